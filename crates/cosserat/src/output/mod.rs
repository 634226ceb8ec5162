//! Results out: HDF5 files of equilibria, stability, bifurcation diagrams,
//! arm studies and sweeps (feature `hdf5`: pure Rust through hdf5-pure,
//! behind the one module `store`), written atomically to outputs claimed by `target` and
//! sealed with a checksum (`seal`) that is verified before a file is read
//! back. Writers read results; they never build or compute them. No stage
//! imports this module.

#[cfg(feature = "hdf5")]
mod arm_output;
#[cfg(feature = "hdf5")]
mod curve;
#[cfg(feature = "hdf5")]
mod diagram;
#[cfg(feature = "hdf5")]
mod hdf5_output;
#[cfg(feature = "hdf5")]
pub mod schema;
pub mod seal;
#[cfg(feature = "hdf5")]
mod spatial_arm_output;
#[cfg(feature = "hdf5")]
pub mod store;
#[cfg(feature = "hdf5")]
mod sweep_output;
pub mod target;
pub mod vtk;
pub mod xdmf;

#[cfg(feature = "hdf5")]
pub use arm_output::{read_search, write_arm, write_arm_study, ArmStudy, SavedSearch};
#[cfg(feature = "hdf5")]
pub use arm_output::{write_tapered_arm, TaperedStudy};
#[cfg(feature = "hdf5")]
pub use curve::write_curve;
#[cfg(feature = "hdf5")]
pub use diagram::{read_saved, read_stable, write_diagram, write_stages};
#[cfg(feature = "hdf5")]
pub use hdf5_output::{
    check_target, read_solved, write_equilibrium, write_stability, OutputError, SolvedUnknowns,
    StabilityResult,
};
#[cfg(feature = "hdf5")]
pub use spatial_arm_output::{write_spatial_arm, SpatialStudy};
#[cfg(feature = "hdf5")]
pub use store::{StoreError, StoreResult};
#[cfg(feature = "hdf5")]
pub use sweep_output::{read_sweep, write_sweep, SweepHeader};
