//! What a continuation run produces: points on branches, the special points
//! between them, the diagram that holds both, and what a monitor hears.

use nalgebra::Vector3;

use super::{BranchEnd, PointError, RunState};
use crate::equations::RodSample;
use crate::stability::Block;

/// One equilibrium on a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The parameter value.
    pub parameter: f64,
    /// The discrete unknowns x.
    pub unknowns: Vec<f64>,
    /// The unit tangent (x, p) of the branch.
    pub tangent: Vec<f64>,
    /// The tip.
    pub tip: RodSample,
    /// The angle (rad) between the tip tangent and the clamp tangent.
    pub tip_angle: f64,
    /// Tracked eigenvalues, block after block.
    pub eigenvalues: Vec<f64>,
    /// Morse index.
    pub morse_index: usize,
    /// The Morse index of each block (in the order of the eigenvalues'
    /// blocks), counted exactly — by the warm pairs' certificate or
    /// Sylvester's inertia —, not read from the tracked eigenvalues: a
    /// block may have more negative eigenvalues than it tracks (the
    /// twisted rod's second pair crosses zero while three are tracked).
    pub block_morse: Vec<usize>,
    /// Stable (Morse index 0).
    pub stable: bool,
    /// The L² norm of the curvature, √∫|κ|².
    pub norm: f64,
    /// The rod at equally spaced points (`continuation.shape_points`):
    /// position, directors, curvature, moment and force — for pictures
    /// and for ParaView (`cosserat export`).
    pub shape: Vec<RodSample>,
    /// The values of the run's measures
    /// ([`super::ContinuationOptions::measures`]), in their order.
    pub measures: Vec<f64>,
}

/// Kinds of special points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpecialKind {
    /// The parameter turns back.
    Fold,
    /// Another branch crosses.
    BranchPoint,
}

impl SpecialKind {
    /// The name in output files.
    pub fn name(self) -> &'static str {
        match self {
            SpecialKind::Fold => "fold",
            SpecialKind::BranchPoint => "branch_point",
        }
    }
}

/// How a special point was located.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// Newton on Govaerts' minimally augmented system (F, g) = 0
    /// converged (folds; docs/methods.md): exact to the corrector's
    /// tolerance.
    Augmented,
    /// The root of the test function bracketed in the arclength (Illinois
    /// regula falsi): a multiple branch point (on an entry of Govaerts'
    /// bordered G), and a fold or simple branch point whose augmented
    /// Newton failed — the diagram's warnings say why.
    Bracketed,
    /// A mode the model's BVP does not see (out of the plane of a planar
    /// model): the crossing of the finite-element eigenvalue located on
    /// the tracked mesh and on two and four times its elements, and
    /// extrapolated at the elements' order (Richardson); its estimated
    /// error is [`SpecialPoint::parameter_error`].
    Extrapolated,
    /// The root of the test function interpolated from its samples on both
    /// sides where the corrector fails closer to it (the bracket could not
    /// be closed; `interpolated_root.rs`): its estimated error is the
    /// difference from the interpolant of one degree less.
    Interpolated,
}

impl Location {
    /// The name in output files.
    pub fn name(self) -> &'static str {
        match self {
            Location::Augmented => "augmented",
            Location::Bracketed => "bracketed",
            Location::Extrapolated => "extrapolated",
            Location::Interpolated => "interpolated",
        }
    }
}

/// A located fold or branch point.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecialPoint {
    /// Fold or branch point.
    pub kind: SpecialKind,
    /// The branch it lies on.
    pub branch: usize,
    /// The index of the branch point just before it.
    pub index: usize,
    /// The located point.
    pub point: Point,
    /// The block whose eigenvalue vanishes.
    pub block: Block,
    /// The Hessian null mode as nodal rotations.
    pub null_mode: Vec<Vector3<f64>>,
    /// The bifurcating mode breaks a symmetry of the branch (out of the
    /// plane of a planar branch, or bending of a straight one).
    pub symmetry_breaking: bool,
    /// The new branches started here.
    pub children: Vec<usize>,
    /// The located singularity: |det F_x| relative to its scale on the
    /// neighbouring points, and the eigenvalue of the block there.
    pub singularity: (f64, f64),
    /// How many eigenvalues of the second variation cross zero here: the
    /// change of the block's Morse index across the point (1 for a simple
    /// fold or branch point; 2 where a pair crosses together, as for the
    /// bending modes of an isotropic rod, B1 = B2, whose kernel is a
    /// plane).
    pub multiplicity: usize,
    /// How it was located.
    pub location: Location,
    /// The estimated error of `point.parameter`: on the augmented system
    /// ([`Location::Augmented`]) the discretization's — the same point
    /// located on the family refined (twice the collocation intervals, or
    /// integration tolerances up to 100× tighter), the difference scaled
    /// by Richardson's G/(G − 1) (`continuation/discretization.rs`); for
    /// [`Location::Extrapolated`] the difference of the extrapolations
    /// from two pairs of element meshes plus the BVP discretization's part
    /// (the crossing located again on the refined family); for
    /// [`Location::Interpolated`] the interpolants' difference plus the
    /// event tolerance (plus the discretization's where it is known); for
    /// [`Location::Bracketed`] the bracket's spread where it could not be
    /// closed, and where it closed on a multiple branch point, or on a
    /// fold of a branch of symmetric copies, the discretization's (the
    /// root of the same test located again on the refined family,
    /// `continuation/bordered_root.rs`, `discretization.rs`,
    /// Richardson-scaled alike). None where it is not estimated: a refined
    /// location that failed, a fold kept at its closed bracket because its
    /// augmented Newton failed, and a simple branch point on a branch of
    /// symmetric copies (the diagram's warnings say which and why).
    pub parameter_error: Option<f64>,
}

/// A followed branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Its points in order.
    pub points: Vec<Point>,
    /// The special point it was switched from.
    pub parent: Option<usize>,
    /// Why it ended ([`BranchEnd::InProgress`] while it is followed).
    pub stop_reason: BranchEnd,
    /// The direction of travel: +1 along the stored tangents, −1 against
    /// them (the backward half of a `both_directions` start).
    pub direction: f64,
    /// The arclength step the next point would be tried with: with the
    /// points and the direction, all a resumed run needs to go on exactly
    /// as an uninterrupted one.
    pub next_step: f64,
}

/// A bifurcation diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagram {
    /// The branches.
    pub branches: Vec<Branch>,
    /// Folds and branch points.
    pub special_points: Vec<SpecialPoint>,
    /// Column names of the eigenvalues: `"in_plane[0]"`, ...
    pub eigenvalue_names: Vec<String>,
    /// The names of the per-point measures ([`Point::measures`]).
    pub measure_names: Vec<String>,
    /// Finite-element nodes of the null modes.
    pub nodes: Vec<f64>,
    /// Why the whole run ended: "in progress" while it runs (what a
    /// checkpoint records), then "completed" or "interrupted".
    pub stop_reason: RunState,
    /// What the run noticed but could not settle: events detected (a Morse
    /// index that changed) that could not be located.
    pub warnings: Vec<String>,
}

/// Why continuation could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContinuationError {
    /// No equilibrium at the start value.
    #[error("no equilibrium at the start value p = {p}: {message}")]
    Start {
        /// The start value of the parameter.
        p: f64,
        /// Why no equilibrium was found there.
        message: String,
    },
    /// A point could not be evaluated.
    #[error(transparent)]
    Point(#[from] PointError),
}

/// What a monitor hears after every point; returning false stops the run
/// (an interrupt), keeping what was computed.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    /// Points so far, all branches.
    pub points: usize,
    /// The branch being followed.
    pub branch: usize,
    /// The current parameter.
    pub parameter: f64,
}
