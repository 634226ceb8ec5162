//! Pseudo-arclength continuation of equilibria (Keller 1977) with tracking
//! of the Hessian eigenvalues, detection and location of folds and branch
//! points, and branch switching — a bifurcation diagram in one call.
//!
//! The discretization is shooting on the family F(x, p) = 0 of
//! [`Family`]; each point carries the lowest eigenvalues of the second
//! variation per block (tracked by eigenvector overlap, not by sorted
//! position), its Morse index and a stable flag. Events between two points:
//! a **fold** where the parameter component of the tangent changes sign; a
//! **branch point** where the Morse index of a block changes without a
//! fold. Folds are bracketed where τ_p changes sign and located on
//! Govaerts' minimally augmented system (`fold`); simple branch points
//! bracketed where det F_x = 0 when the model can represent the
//! bifurcating mode and located on a minimally augmented system
//! (`branch_point`; exact to the integration tolerance), else where the
//! tracked eigenvalue vanishes on three meshes, extrapolated (with the
//! estimated error). Branch switching follows the
//! null vector of [F_x F_p] orthogonal to the branch tangent, both ways.
//!
//! The modules: `options` holds the settings ([`ContinuationOptions`]),
//! `diagram` what a run produces ([`Diagram`], [`Branch`], [`Point`],
//! [`SpecialPoint`]), `corrector` one predictor–corrector step (Newton on
//! the bordered pseudo-arclength system, the tangent), `driver` the loop
//! that follows branches and switches at branch points, `events` the
//! location of folds and branch points, `resume` a run continued from a
//! saved diagram, `restart` a run started from given unknowns, `stage` the
//! chained stages of one run joined into one diagram.

mod bordered_root;
mod bordering;
mod branch_point;
mod codim2;
mod corrector;
mod diagram;
mod discretization;
mod driver;
pub mod engine;
mod events;
mod family;
mod fold;
mod interpolated_root;
mod kernel;
mod landing;
mod lens;
mod measure;
mod mesh_check;
mod options;
mod restart;
mod resume;
mod slice;
mod stage;
mod status;
mod tracking;

pub use codim2::{follow_singular, CurveOptions, CurvePoint, Lens2, ParameterOn, SingularCurve};
/// The size limits of the dense algebra (the memory estimate's).
pub(crate) use corrector::DENSE_UP_TO;
pub use corrector::{Linearization, RodFactors};
pub use diagram::{
    Branch, ContinuationError, Diagram, Location, Point, Progress, SpecialKind, SpecialPoint,
};
pub use driver::continuation;
pub use family::{tip_angle, CarryError, DerivativeMethod, Family, FamilyError, PointError};
pub use lens::{Lens, Parameter, RodLens};
pub use measure::{Measure, Quantity};
pub use options::{ContinuationOptions, StopAt};
pub use restart::{continuation_from, switch_from, StartPoint};
pub use resume::{resume, SavedBranch, SavedDiagram, SavedSpecial};
pub use stage::{stage_of, Stage};
pub use status::{BranchEnd, RunState};
pub use tracking::{Modes, Spectrum, Tracker};

use driver::{drain, Pending, Run};
