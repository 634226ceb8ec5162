//! The longest soft robotic arm (Sipos & Várkonyi 2019, Sec. 3–4): the
//! loaded shape that reaches farthest in a direction α before the arm loses
//! stability, with the intrinsic curvature that produces it.
//!
//! The loaded shape is the turning angle φ(s̄) = Σ_{i=1}^{M} c_i s̄^{i−1}
//! (paper (52)); c1 is a rigid rotation fixed by the reach direction
//! (third condition of (46)); the critical load γ_crit = F L²/B2 of the
//! shape held fixed is a generalized eigenvalue of the verified second
//! variation ([`crate::stability::critical_load`], both blocks); the reach
//! is R̂ = √γ_crit |(x̄(1), z̄(1))| in units of √(B2/F) (paper (54)–(55)).
//! The intrinsic curvature follows from (43): κ̄⁰2 = φ' − γ m̄2, with m̄2 the
//! moment of the unit tip load on the shape.
//!
//! The search is deterministic: an Owen-scrambled Sobol' set over the box
//! of c2..cM (the global stage, the private `study/arm/sampling.rs`), then
//! projected BFGS on R̂ with its exact gradient (`gradient`,
//! [`crate::stability::critical_load_gradient`]) from the best few (the
//! polish; Nelder–Mead (argmin) only where R̂ has no gradient).
//!
//! Submodules: `design` (a design's reach), `search` (the sampled search
//! and its polish), `straight` (the intrinsically straight arm R̂0),
//! `resolve` (mesh studies), `fig5` (the reach map), `control_path` and
//! `scene`.

use std::sync::Arc;

use crate::model::{LinearElastic, Profile, Rod};
use crate::stability::{FixedShape, StabilityOptions};

pub mod control_path;
pub mod fig5;
mod polish;
mod resolve;
mod sampling;
pub mod scene;
pub mod spatial;
pub mod taper;
mod taper_arm;

pub use control_path::{
    control_path, control_path_until, loading_path_in, loading_path_until, shape_holding_path,
    shape_holding_path_until,
};
pub use fig5::{ClosestStraight, ReachMap};
pub use resolve::{
    MeshStudy, ReachLimit, Resolution, Verdict, LIMIT_MIN_ELEMENTS, LIMIT_ORDER, MAX_ELEMENTS,
    REACH_TOLERANCE,
};
pub use scene::{ArmScene, ArmWeight};
pub use spatial::{DirectionComparison, PathVerdict, SpatialArm, SpatialDesign, SpatialOptimum};
pub use taper_arm::{loading_verdict, LoadingVerdict, TaperedArm, TaperedOptimum};

mod warm_start;

mod design;
mod gradient;
mod search;
mod straight;

use design::{derivative, polynomial};
pub use gradient::ReachSlope;
pub use straight::{StraightArm, StraightLimit};

/// The arm to design.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmProblem {
    /// B̄1 = B1/B2.
    pub b1: f64,
    /// B̄3 = B3/B2.
    pub b3: f64,
    /// Reach direction (rad) above the horizontal: the tip at elevation α.
    pub alpha: f64,
    /// Bounds of c2..cM (M − 1 pairs).
    pub bounds: Vec<(f64, f64)>,
    /// Discretization of the second variation.
    pub stability: StabilityOptions,
}

/// How hard to search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SearchOptions {
    /// Samples (scrambled Sobol' points) of the global stage.
    pub samples: usize,
    /// Nelder–Mead polishes from the best samples.
    pub starts: usize,
    /// Iterations of each polish.
    pub iterations: u64,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            samples: 400,
            starts: 4,
            iterations: 400,
        }
    }
}

/// One evaluated design.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmDesign {
    /// R̂ = √γ_crit |(x̄(1), z̄(1))| (with an [`ArmScene`]: L̂(λ) |r̄(1)|).
    pub reach: f64,
    /// The design load: γ_crit = F L²/B2 (with an [`ArmScene`]: the load
    /// factor λ, γ_crit or, actuator-limited, the largest λ below it that
    /// the actuators can hold).
    pub gamma: f64,
    /// c1..cM of the loaded shape φ(s̄).
    pub shape_coefficients: Vec<f64>,
}

/// The optimum with what a user keeps of it.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmOptimum {
    /// The design.
    pub design: ArmDesign,
    /// b1..bM: the least-squares Taylor fit of κ̄⁰2(s̄) (paper (59)).
    pub curvature_coefficients: Vec<f64>,
    /// The loaded shape in scaled coordinates (x̂, ŷ, ẑ) = √γ (x̄, ȳ, z̄).
    pub loaded_shape: Vec<[f64; 3]>,
    /// The unloaded (intrinsic) shape, same scaling and clamp.
    pub unloaded_shape: Vec<[f64; 3]>,
    /// κ̄⁰2 at the shape points.
    pub intrinsic_curvature: Vec<f64>,
    /// Designs evaluated.
    pub evaluations: usize,
    /// The critical load factor of the loaded shape (≥ `design.gamma`; equal
    /// unless the actuators limit the load).
    pub critical_load: f64,
    /// The loads and limits the design was made for.
    pub scene: ArmScene,
    /// Its discretization check ([`ArmProblem::resolve`]): R̂ on finer
    /// meshes, the error estimate, and whether it was searched for again on
    /// a finer mesh. None
    /// where no check was made (a sample, the best so far of an
    /// interrupted search).
    pub resolution: Option<Resolution>,
    /// The mesh-converged optimum R*(N → ∞) with its error bound, from the
    /// optimum polished again on meshes of order-2 elements
    /// ([`ArmProblem::resolve`]); None where no check was made or the
    /// values have no gradient to polish with (an actuator limit).
    pub limit: Option<ReachLimit>,
    /// The discretization the design was optimized on (the search's, or
    /// the finer one [`ArmProblem::resolve`] searched again on).
    pub mesh: StabilityOptions,
}

/// How far a search has come: what `cosserat optimize --resume` keeps of an
/// interrupted run to go on where it stopped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SearchProgress {
    /// Samples evaluated: the global stage goes on from the next one.
    pub samples_done: usize,
    /// The best samples so far as (R̂, c2..cM), best first, at most
    /// `starts` of them: the starting points of the polishes.
    pub leaders: Vec<(f64, Vec<f64>)>,
    /// Polishes finished (an interrupted polish is redone).
    pub polishes_done: usize,
    /// The best design so far.
    pub best: Option<ArmDesign>,
    /// Designs evaluated so far.
    pub evaluations: usize,
}

/// The rod of a design at its design load: the intrinsic curvature κ̄⁰2 of
/// (43) as a natural cubic spline through `points` nodes (exact at the
/// nodes), the clamp turned by c1 (the design's tangent at s = 0), the
/// scene's loads scaled by the design load; refused as in [`Rod::new`]
/// (a non-finite design load or weight).
pub fn designed_rod(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
) -> Result<Rod, crate::model::ModelError> {
    let rod0 = problem.rod_in(scene)?;
    let shape = FixedShape {
        turning_angle: Profile::Polynomial(design.shape_coefficients.clone()),
    };
    let s: Vec<f64> = (0..points)
        .map(|i| i as f64 / (points - 1) as f64)
        .collect();
    let c = &design.shape_coefficients;
    let dphi = derivative(c);
    let kappa0: Vec<f64> = shape
        .samples(&rod0, &s)
        .expect("a design's shape was integrated when its critical load was found")
        .iter()
        .map(|p| polynomial(&dphi, p.s) - design.gamma * p.moment[1])
        .collect();
    let rod = rod0.clone();
    let energy = Arc::new(LinearElastic::new(
        [problem.b1, 1.0, problem.b3].map(Profile::Constant),
        [
            Profile::Constant(0.0),
            Profile::spline(s, kappa0)?,
            Profile::Constant(0.0),
        ],
    )?);
    let mut clamp = rod.clamp().clone();
    clamp.frame = clamp.turned_frame(c[0])?;
    let loads = rod.loads().scaled(design.gamma);
    rod.with_energy(energy).with_clamp(clamp)?.with_loads(loads)
}

/// Continues the designed rod in `parameter` from nearly 0 to 1 (the
/// design) with the Hessian tracked on the design's own discretization, so
/// that λ = 1 is its γ_crit.
pub(crate) fn continue_to_design(
    problem: &ArmProblem,
    rod: &Rod,
    parameter: crate::continuation::Parameter,
    stop: &dyn Fn() -> bool,
) -> Result<crate::continuation::Diagram, crate::continuation::ContinuationError> {
    continue_refining(
        problem,
        |segments| {
            crate::continuation::Family::new(
                rod.clone(),
                parameter,
                crate::model::ModelLevel::Planar,
                segments,
                crate::numerics::integrator::Tolerances::default(),
            )
        },
        stop,
    )
}

/// The shooting segments of a design's path, tried in turn while its
/// branch stops short because the corrector cannot converge.
pub const PATH_SEGMENTS: [usize; 3] = [32, 64, 128];

/// [`continue_family`] on the family `on(segments)` for each of
/// [`PATH_SEGMENTS`] while the branch ends with its step below the
/// smallest (`BranchEnd::StepTooSmall`: no fold, no loss of stability —
/// the corrector has met its residual's noise floor, which on 32 segments
/// lies above its tolerance for a strongly coiled arm: the Sec. 4.4
/// optimum's loading path stopped at λ = 0.974). The first diagram that
/// ends otherwise is returned; if every one stops short, the last (whose
/// branch says so).
fn continue_refining(
    problem: &ArmProblem,
    on: impl Fn(usize) -> crate::continuation::Family,
    stop: &dyn Fn() -> bool,
) -> Result<crate::continuation::Diagram, crate::continuation::ContinuationError> {
    use crate::continuation::BranchEnd;
    let mut last = None;
    for segments in PATH_SEGMENTS {
        let d = continue_family(problem, &on(segments), stop)?;
        let short = d
            .branches
            .first()
            .is_some_and(|b| matches!(b.stop_reason, BranchEnd::StepTooSmall(_)));
        if !short || stop() {
            return Ok(d);
        }
        last = Some(d);
    }
    Ok(last.expect("at least one segment count"))
}

/// Continues `family` from p = 10⁻³ to 1 with the design's own mesh,
/// stopping at the next point once `stop()` turns true (the diagram's
/// `stop_reason` is then "interrupted").
pub(crate) fn continue_family(
    problem: &ArmProblem,
    family: &crate::continuation::Family,
    stop: &dyn Fn() -> bool,
) -> Result<crate::continuation::Diagram, crate::continuation::ContinuationError> {
    use crate::continuation::{continuation, ContinuationOptions};
    let opts = ContinuationOptions {
        start: 1e-3,
        bounds: (0.0, 1.0),
        step: 0.02,
        max_step: 0.05,
        switch_depth: 0,
        max_points: 4000,
        // Two eigenvalues: the lowest and the next, to see the crossing.
        stability: problem
            .stability
            .with_eigenvalues(2)
            .expect("two eigenvalues on a valid mesh"),
        ..Default::default()
    };
    continuation(family, &opts, &mut |_, _| !stop())
}

/// The loading path of a designed arm (paper Sec. 5 warns that loading need
/// not reach the design): the rod with the design's intrinsic curvature
/// and clamp angle ([`designed_rod`]), continued in the load factor λ from
/// nearly unloaded to λ = 1 (the design load γ_crit) with the Hessian
/// tracked.
pub fn loading_path(
    problem: &ArmProblem,
    design: &ArmDesign,
    points: usize,
) -> Result<crate::continuation::Diagram, crate::continuation::ContinuationError> {
    loading_path_until(problem, &ArmScene::default(), design, points, &|| false)
}
