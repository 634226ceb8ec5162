//! The checked problem: everything a problem file asks for, as values of
//! the stages (a rod, a model level, solver settings, and optionally a
//! fixed shape, a continued family, an arm study and a sweep grid).
//! The `input` module builds it from TOML text; the commands and the sweep
//! read it.

use crate::bvp::SolverOptions;
use crate::continuation::{ContinuationOptions, Family};
use crate::model::{ModelChoice, Rod};
use crate::stability::{FixedShape, StabilityOptions};
use crate::study::arm::{ArmProblem, ArmScene, SearchOptions};
use crate::study::sweep::Sweep;

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
    /// The arm optimization, its search, and whether to compute R̂0.
    pub arm: Option<(ArmProblem, SearchOptions, bool)>,
    /// The arm's loads and actuator limit, and the size of its reach map.
    pub arm_scene: Option<(ArmScene, usize)>,
    /// The grid of a `[sweep]` table.
    pub sweep: Option<Sweep>,
}
