//! What a rod is: its stored energy, its clamp, the dead loads on it, and the
//! least model level (planar, Kirchhoff or Cosserat) that the scene needs.
//!
//! This stage knows nothing of how equilibria are computed.

mod catalog;
mod energy;
mod error;
mod frame;
mod level;
mod loads;
mod profile;
mod rod;
mod shear;
mod support;
mod tangent;

pub use catalog::{EnergyBuilder, EnergyCatalog, EnergySpec, EnergySpecError};
pub use energy::{LinearElastic, ProfileKind, QuarticStiffening, StoredEnergy};
pub use error::ModelError;
pub use frame::Frame;
pub use level::{ModelChoice, ModelLevel};
pub use loads::DeadLoads;
pub use profile::{Extremes, Knots, Profile, SplineKnots};
pub use rod::{Clamp, ResidualScales, Rod};
pub use shear::Shearable;
pub use support::{across, Freedom, TipSupport};
pub use tangent::{EnergyRate, RodTangent};
