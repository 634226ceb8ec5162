//! The continuation engine: pseudo-arclength continuation (Keller 1977)
//! of any one-parameter family F(u, p) = 0, knowing nothing of rods.
//!
//! In the spirit of BifurcationKit.jl's split of problem, algorithm and
//! options: a problem is a [`ContinuationProblem`] — its dimension, the
//! residual F with F_u in the problem's own structure (a [`Jacobian`]:
//! dense, banded, almost block diagonal), ∂F/∂p, and optionally a
//! stability monitor (the Morse index at a point). The algorithm is one
//! predictor–corrector step (`corrector`: Newton on the bordered system
//! [F_u F_p; τᵀ], the tangent as the null vector of [F_u F_p], Newton at a
//! fixed p) and the branch loop with step control, bounds, folds and the
//! problem's own test functions (`trace`). The options are [`TraceOptions`].
//!
//! The rod's [`super::Family`] is one implementation
//! (`continuation/corrector.rs`); its driver adds what only rods have —
//! eigenvalue tracking of the second variation, branch points and
//! switching, slices, landing on a tip angle — on top of this engine's
//! steps. Nothing here imports the model, the equations or the solvers.

mod corrector;
mod trace;

pub use corrector::{
    correct, correct_from, curved_start, newton_at_fixed_p, step, step_after, tangent,
    tangent_from, Corrected, Stepped,
};
pub use trace::{
    trace, StepControl, Trace, TraceEnd, TraceOptions, TracePoint, TracedEvent, TracedFold,
};

use nalgebra::DVector;

use crate::numerics::staircase::Border;

/// F_u of a problem in its own storage, and the linear solves the engine
/// needs with it: F_u δ = −f (Newton at a fixed p) and the bordered
/// system [F_u b; cᵀ d] z = r (the corrector and the tangent). An
/// implementation picks its algebra — dense LU, band LU of a staircase —
/// so that a step costs what the structure allows (O(N) for a band).
pub trait Jacobian {
    /// The factorizations, reused across the solves of one Newton run.
    type Factors: Default;

    /// Factors F_u alone; false where it is singular.
    fn factor(&self, factors: &mut Self::Factors) -> bool;

    /// δ with F_u δ = −f from the last [`Jacobian::factor`]; false where
    /// there is no finite solution.
    fn newton_step(&self, factors: &mut Self::Factors, f: &[f64], delta: &mut [f64]) -> bool;

    /// Factors the bordered matrix [F_u column; rowᵀ corner].
    fn factor_bordered(&self, factors: &mut Self::Factors, border: &Border);

    /// z with [F_u column; rowᵀ corner] z = rhs (length N + 1) from the
    /// last [`Jacobian::factor_bordered`] with the same border: the
    /// least-squares solution where the bordered matrix is singular (at an
    /// exact branch point), false where none is finite.
    fn solve_bordered(
        &self,
        factors: &mut Self::Factors,
        border: &Border,
        rhs: &[f64],
        z: &mut [f64],
    ) -> bool;
}

/// A one-parameter family F(u, p) = 0 to continue: the engine's only view
/// of a problem.
pub trait ContinuationProblem {
    /// Why F (or F_p) cannot be evaluated at a point.
    type Error;
    /// F_u in the problem's structure.
    type Jacobian: Jacobian;

    /// The number of unknowns N (and of equations).
    fn size(&self) -> usize;

    /// A Jacobian of the problem's structure to evaluate into.
    fn jacobian(&self) -> Self::Jacobian;

    /// F(u, p) into `r` and F_u into `fu`.
    fn evaluate(
        &self,
        u: &[f64],
        p: f64,
        r: &mut DVector<f64>,
        fu: &mut Self::Jacobian,
    ) -> Result<(), Self::Error>;

    /// ∂F/∂p at (u, p).
    fn parameter_derivative(&self, u: &[f64], p: f64) -> Result<DVector<f64>, Self::Error>;

    /// The optional stability monitor: the Morse index at a point of the
    /// branch (the number of unstable directions), None when the problem
    /// has none or cannot decide it there.
    fn morse_index(&self, _u: &[f64], _p: f64) -> Option<usize> {
        None
    }

    /// Optional test functions of events: each one whose sign changes
    /// between two points of a branch marks an event there, located where
    /// it vanishes (by [`trace`]). None by default.
    fn test_functions(&self, _u: &[f64], _p: f64) -> Vec<f64> {
        vec![]
    }
}

/// Why a step of the engine failed.
#[derive(Debug, Clone, PartialEq)]
pub enum StepFailure<E> {
    /// The problem could not be evaluated.
    Problem(E),
    /// Newton at the fixed parameter value did not converge.
    NoConvergence(f64),
    /// [F_u F_p] bordered by the previous tangent is singular there.
    SingularTangent(f64),
}

impl<E: std::fmt::Display> std::fmt::Display for StepFailure<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepFailure::Problem(e) => e.fmt(f),
            StepFailure::NoConvergence(p) => write!(f, "Newton did not converge at p = {p}"),
            StepFailure::SingularTangent(p) => {
                write!(
                    f,
                    "no tangent at p = {p}: the bordered Jacobian is singular"
                )
            }
        }
    }
}
