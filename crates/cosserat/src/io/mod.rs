//! Problem files in, results out: TOML problem files (serde), and — with
//! the `hdf5` feature — HDF5 results (the HDF5 C library through
//! hdf5-metno). Without the feature the library is pure Rust.

#[cfg(feature = "hdf5")]
mod arm_output;
mod arm_section;
mod continuation_section;
#[cfg(feature = "hdf5")]
mod diagram;
#[cfg(feature = "hdf5")]
mod hdf5_output;
pub mod memory;
mod problem;
pub mod seal;
mod strict;
mod support_section;
#[cfg(feature = "hdf5")]
mod sweep_output;
mod sweep_section;
pub mod target;

#[cfg(feature = "hdf5")]
pub use arm_output::{read_search, write_arm, write_arm_study, ArmStudy, SavedSearch};
pub use arm_section::ArmSection;
pub use continuation_section::{ContinuationSection, MEASURES};
#[cfg(feature = "hdf5")]
pub use diagram::{read_saved, write_diagram};
#[cfg(feature = "hdf5")]
pub use hdf5_output::{
    check_target, write_equilibrium, write_stability, OutputError, StabilityResult,
};
pub use problem::{Problem, ProblemError, ProblemFile, ProfileSpec};
pub use support_section::SupportSection;
#[cfg(feature = "hdf5")]
pub use sweep_output::{read_sweep, write_sweep, SweepHeader};
pub use sweep_section::{grid_index, AxisSpec, Sweep, SweepAxis, SweepSection, MAX_POINTS};
