//! The checked problem: everything a problem file asks for, as values of
//! the stages (a rod, a model level, solver settings, and optionally a
//! fixed shape, a continued family, an arm study and a sweep grid).
//! The `input` module builds it from TOML text; the commands and the sweep
//! read it.

use crate::bvp::SolverOptions;
use crate::continuation::{ContinuationOptions, Family};
use crate::model::{ModelChoice, Rod};
use crate::stability::{FixedShape, StabilityOptions};
use crate::study::arm::{ArmProblem, ArmScene, SearchOptions, SpatialArm};
use crate::study::sweep::Sweep;

/// A curve of singular points to follow: the two parameters, the second's
/// value at the start, the options.
#[derive(Debug, Clone)]
pub struct Curve {
    /// Both parameters (the first is the family's).
    pub pair: std::sync::Arc<dyn crate::continuation::Lens2>,
    /// The second parameter at the stored special point.
    pub start: f64,
    /// Bounds and steps.
    pub options: crate::continuation::CurveOptions,
}

/// A problem ready to solve.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The rod.
    pub rod: Rod,
    /// The model level and why.
    pub model: ModelChoice,
    /// The solver settings.
    pub options: SolverOptions,
    /// The effective problem text (with overrides applied), stored with
    /// results.
    pub text: String,
    /// The fixed loaded shape of a fixed-shape scene.
    pub shape: Option<FixedShape>,
    /// The discretization of the second variation.
    pub stability: StabilityOptions,
    /// The continued family and how to continue it.
    pub continuation: Option<(Family, ContinuationOptions)>,
    /// `[continuation.curve]`: both parameters as one lens, the second's
    /// start value, and how to follow a singular point in them.
    pub curve: Option<Curve>,
    /// The arm optimization, its search, and whether to compute R̂0.
    pub arm: Option<(ArmProblem, SearchOptions, bool)>,
    /// The arm's loads and actuator limit, and the size of its reach map.
    pub arm_scene: Option<(ArmScene, usize)>,
    /// `[arm] taper`: the section's design space of a tapered arm.
    pub arm_taper: Option<crate::study::arm::taper::Taper>,
    /// `[arm] spatial = true`: the spatial arm (its planar part is `arm`).
    pub arm_spatial: Option<SpatialArm>,
    /// The grid of a `[sweep]` table.
    pub sweep: Option<Sweep>,
    /// The keys of the later stages of a chained continuation
    /// (`[[continuation.stage]]`, stage 2 on; empty for a single run);
    /// `Problem::stage` reads each stage's problem.
    pub stage_keys: Vec<String>,
}
