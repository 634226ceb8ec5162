//! The settings of a continuation run.

use crate::bvp::SolverOptions;
use crate::stability::StabilityOptions;

/// Continuation settings (BifurcationKit's ContinuationPar, in spirit).
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationOptions {
    /// The parameter value to start from.
    pub start: f64,
    /// Stop when the parameter leaves [min, max].
    pub bounds: (f64, f64),
    /// Initial arclength step Δs of the constraint
    /// ⟨x − x₀, ẋ₀⟩ + (p − p₀)ṗ₀ − Δs = 0, in the scaled unknowns.
    pub step: f64,
    /// Smallest step before giving up: a corrector that fails halves Δs,
    /// and the branch ends ([`super::BranchEnd::StepTooSmall`]) below this.
    pub min_step: f64,
    /// Largest step: a corrector that converges in at most 3 Newton
    /// iterations lengthens Δs by 1.5, up to this.
    pub max_step: f64,
    /// Points per branch at most.
    pub max_points: usize,
    /// Follow the start branch in both directions.
    pub both_directions: bool,
    /// Depth of recursive branch switching (0: none).
    pub switch_depth: usize,
    /// Stop a branch when the tip tangent turns more than this (rad) from
    /// the clamp tangent.
    pub tip_angle_limit: Option<f64>,
    /// Discretization of the second variation and eigenvalues per block.
    pub stability: StabilityOptions,
    /// Newton tolerance τ of the corrector and of Newton at fixed p: the
    /// [`crate::numerics::newton::Convergence`] test, scaled residual ≤ τ and
    /// relative correction ≤ √τ.
    pub tolerance: f64,
    /// Relative tolerance on the parameter when locating events.
    pub event_tolerance: f64,
    /// How the start equilibrium is solved: the problem's `[solver]`
    /// (strategy, initial curvature, Newton and integration settings),
    /// with the family's own discretization as its method. None: the
    /// default solver with the automatic load strategy.
    pub start_solver: Option<SolverOptions>,
    /// The measures computed at every point ([`super::Measure`]).
    pub measures: Vec<super::Measure>,
    /// Stop values: a branch ends where one of these measures reaches its
    /// value, its last step shortened onto it (`landing.rs`).
    pub stops: Vec<StopAt>,
    /// Equally spaced points of the shape stored with every point (the
    /// clamp and the tip included).
    pub shape_points: usize,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        ContinuationOptions {
            start: 0.0,
            bounds: (f64::NEG_INFINITY, f64::INFINITY),
            step: 0.05,
            min_step: 1e-7,
            max_step: 0.2,
            max_points: 400,
            both_directions: false,
            switch_depth: 1,
            tip_angle_limit: None,
            stability: StabilityOptions::default(),
            tolerance: 1e-11,
            event_tolerance: 1e-11,
            start_solver: None,
            measures: vec![],
            stops: vec![],
            shape_points: 21,
        }
    }
}

/// A stop value of a branch (`continuation.stop_at`): the branch ends where
/// the measure `measures[measure]` reaches `value`, the step that passes it
/// shortened so that the measure lands on it to
/// [`StopAt::tolerance`]. The index must name one of the run's measures
/// (checked when the run starts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopAt {
    /// The index of the measure in [`ContinuationOptions::measures`].
    pub measure: usize,
    /// The value it stops at.
    pub value: f64,
}

impl StopAt {
    /// How close the landed measure comes to the value: 1e-10 max(1, |value|).
    pub fn tolerance(&self) -> f64 {
        1e-10 * self.value.abs().max(1.0)
    }

    /// The measure minus the value at a point with the run's `measures`
    /// values, or None where the point has no such measure.
    pub fn gap(&self, measures: &[f64]) -> Option<f64> {
        measures.get(self.measure).map(|m| m - self.value)
    }
}
