//! The support at the tip s = L: free (a cantilever), or constrained in
//! translation and rotation — pinned, clamped, sliding, or free to spin
//! about an axis — so that columns and twisted rods with both ends held
//! can be posed.
//!
//! A constrained translation makes the tip force a reaction R, an unknown
//! of the BVP carried as a constant state; a constrained rotation replaces
//! the natural condition M(L) = C by a condition on the tip frame. Each
//! freedom is one of
//!
//! * `Fixed`: no motion (3 conditions on the position or on the frame);
//! * `Free`: the natural condition (R = 0, or M(L) = C);
//! * `Axial(a)`: free only along (translation) or about (rotation) the unit
//!   axis a: 2 conditions across a plus the natural condition along a.

use nalgebra::Vector3;

use super::Frame;

/// Freedom of the tip in translation or rotation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Freedom {
    /// Held: position or frame prescribed.
    Fixed,
    /// Unconstrained: the load (tip force or couple) acts alone.
    Free,
    /// Free only along / about this unit axis (global components; a unit
    /// vector to [`Frame::TOLERANCE`], checked by [`super::Rod::new`]).
    Axial(Vector3<f64>),
}

/// The tip support.
#[derive(Debug, Clone, PartialEq)]
pub struct TipSupport {
    /// The prescribed tip position r(L) (used unless translation is free).
    pub position: Vector3<f64>,
    /// The prescribed tip frame (d1 d2 d3)(L), the directors as columns (used unless
    /// rotation is free); a rotation, checked by [`Frame`].
    pub frame: Frame,
    /// Translation freedom of the tip.
    pub translation: Freedom,
    /// Rotation freedom of the tip.
    pub rotation: Freedom,
}

impl TipSupport {
    /// True when the tip force is (partly) a reaction: R is an unknown.
    pub fn holds_position(&self) -> bool {
        self.translation != Freedom::Free
    }

    /// A short description for reports ("pinned", "clamped", ...).
    pub fn name(&self) -> &'static str {
        match (self.translation, self.rotation) {
            (Freedom::Free, Freedom::Free) => "free",
            (Freedom::Fixed, Freedom::Free) => "pinned",
            (Freedom::Fixed, Freedom::Fixed) => "clamped",
            (Freedom::Axial(_), Freedom::Free) => "sliding pin",
            (Freedom::Axial(_), Freedom::Fixed) => "sliding clamp",
            (Freedom::Axial(_), Freedom::Axial(_)) => "sliding clamp free to spin",
            (Freedom::Fixed, Freedom::Axial(_)) => "clamp free to spin",
            (Freedom::Free, _) => "held in rotation only",
        }
    }
}

/// Two unit vectors completing the unit vector a to an orthonormal basis.
pub fn across(a: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let helper = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let b1 = a.cross(&helper).normalize();
    [b1, a.cross(&b1)]
}
