//! Why a model value was refused: the checked constructors of the model
//! ([`super::Rod::new`], [`super::Frame::new`], [`super::LinearElastic::new`],
//! [`super::Shearable::new`], [`super::Profile::table`], ...) return these
//! instead of building a rod that would fail later, far from its cause, or
//! give numbers that mean nothing.

/// A model value that cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The rod length is not a positive finite number.
    #[error("the rod length must be positive and finite, got {0}")]
    Length(f64),
    /// A vector of the model (a load, a position, an axis) has a non-finite
    /// component; `what` names it ("tip force", "clamp position", ...).
    #[error("the {what} must be finite, got {value:?}")]
    NotFinite {
        /// Which vector.
        what: &'static str,
        /// Its components.
        value: [f64; 3],
    },
    /// An axis of a support is not a unit vector (to [`super::Frame::TOLERANCE`]).
    #[error("the support axis must be a unit vector, got |a| = {norm}")]
    Axis {
        /// |a|.
        norm: f64,
    },
    /// A director frame is not a rotation: its columns are not orthonormal
    /// to [`super::Frame::TOLERANCE`], or it is left-handed.
    #[error(
        "the director frame is not a rotation: max |QᵀQ − I| = {defect:e} (tolerance {:e}), \
         det Q = {determinant}",
        super::Frame::TOLERANCE
    )]
    Frame {
        /// max_ij |(QᵀQ − I)_ij| (NaN for a non-finite matrix).
        defect: f64,
        /// det Q (+1 for a rotation).
        determinant: f64,
    },
    /// A turning angle (rad) is not finite.
    #[error("a turning angle must be finite, got {0}")]
    Angle(f64),
    /// A stiffness is not positive and finite: the `index`th (from 0) of
    /// the kind `what` ("bending/torsional stiffness B", "shear/extension
    /// stiffness S").
    #[error("the {what}{} must be positive and finite, got {value}", .index + 1)]
    Stiffness {
        /// Which kind of stiffness.
        what: &'static str,
        /// Which component, from 0.
        index: usize,
        /// The refused value (NaN for a profile holding a non-finite
        /// number).
        value: f64,
    },
    /// An intrinsic curvature profile κ⁰_i (`index` i from 0) holds a
    /// non-finite number.
    #[error("the intrinsic curvature κ⁰{} must hold finite numbers only", .index + 1)]
    IntrinsicCurvature {
        /// Which component, from 0.
        index: usize,
    },
    /// A coefficient of an energy is out of its range (the quartic
    /// coefficient C ≥ 0, finite).
    #[error("the {what} must be {range}, got {value}")]
    Coefficient {
        /// Which coefficient.
        what: &'static str,
        /// Its admissible range, in words.
        range: &'static str,
        /// The refused value.
        value: f64,
    },
    /// A point load (`index` k from 0, in the order given) is not at an
    /// interior point 0 < s < L, or its force or couple is not finite.
    #[error(
        "point load {index} must act at an interior point 0 < s < {length} with a finite force \
         and couple, got s = {s}, force {force:?}, couple {couple:?}"
    )]
    PointLoad {
        /// Which point load, from 0.
        index: usize,
        /// Its point of application.
        s: f64,
        /// Its force.
        force: [f64; 3],
        /// Its couple.
        couple: [f64; 3],
        /// The rod length.
        length: f64,
    },
    /// A profile of s cannot be built: what is wrong with it.
    #[error("invalid profile: {0}")]
    Profile(String),
}
