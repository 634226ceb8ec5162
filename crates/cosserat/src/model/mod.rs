//! What a rod is: its stored energy, its clamp, the dead loads on it, and the
//! least model level (planar, Kirchhoff or Cosserat) that the scene needs.
//!
//! This stage knows nothing of how equilibria are computed.

mod autodiff;
mod catalog;
mod energy;
pub mod energy_check;
mod error;
mod formula;
mod frame;
mod level;
mod loads;
mod profile;
mod profile_edits;
mod rod;
mod shear;
mod strain;
mod strain_autodiff;
mod support;
mod tangent;

pub use autodiff::{lift, AutoDiff, Density};
pub use catalog::{EnergyBuilder, EnergyCatalog, EnergySpec, EnergySpecError};
pub use energy::{LinearElastic, QuarticStiffening, StoredEnergy};
pub use error::ModelError;
pub use formula::{
    Formula, FormulaEnergy, FormulaError, Variable as FormulaVariable,
    FUNCTIONS as FORMULA_FUNCTIONS,
};
pub use frame::Frame;
pub use level::{ModelChoice, ModelLevel};
pub use loads::{DeadLoads, PointLoad};
pub use profile::{Extremes, Knots, Pieces, Profile, Sampler, SplineKnots};
pub use profile_edits::{intrinsic_profiles, ProfileEdits, ProfileKind};
pub use rod::{Clamp, ResidualScales, Rod};
pub use shear::Shearable;
pub use strain::{assemble_blocks, shear_strain, stack, StrainEnergy, StrainError, StrainJet};
pub use strain_autodiff::{StrainAutoDiff, StrainDensity};
pub use support::{across, Freedom, TipSupport};
pub use tangent::{EnergyRate, RodTangent};
