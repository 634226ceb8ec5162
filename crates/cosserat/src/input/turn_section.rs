//! `turn = { axis = [a1, a2, a3], angle = θ }` in `[clamp]` and `[support]`:
//! an end frame turned by θ (rad) about a fixed direction.
//!
//! The angle is a real number, not a frame: a turn of 2π gives the same
//! end frame as no turn, but a continuation in `clamp.turn.angle` or
//! `support.turn.angle` follows the rod through any number of turns (a
//! rod twisted at its end through 2π and beyond), which directors d1, d3
//! alone cannot express.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::problem::{invalid, ProblemError};
use crate::model::Frame;

/// The largest |θ| accepted (rad): beyond it sin θ and cos θ keep fewer
/// than 10 significant digits (θ ulp ≈ 1e-10 at 1e6), so the end frame is
/// no longer the one asked for.
pub const MAX_TURN_ANGLE: f64 = 1e6;

/// `turn`: the frame turned by `angle` about `axis`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TurnSection {
    /// The fixed direction turned about (normalized; must not be zero).
    #[serde(deserialize_with = "super::strict::array")]
    pub axis: [f64; 3],
    /// The angle (rad), right-handed about `axis`, any number of turns.
    #[serde(default)]
    pub angle: f64,
}

impl TurnSection {
    /// `frame` turned by R(axis, angle); `field` names the table
    /// (`clamp.turn` or `support.turn`) in errors.
    pub fn apply(&self, field: &str, frame: &Frame) -> Result<Frame, ProblemError> {
        let axis = Vector3::from(self.axis);
        if !axis.iter().all(|v| v.is_finite()) || axis.norm() == 0.0 {
            return Err(invalid(
                format!("{field}.axis"),
                format!("must be a finite non-zero vector, got {:?}", self.axis),
            ));
        }
        if !(self.angle.is_finite() && self.angle.abs() <= MAX_TURN_ANGLE) {
            return Err(invalid(
                format!("{field}.angle"),
                format!(
                    "{} is not a finite angle within ±{MAX_TURN_ANGLE:e} rad (beyond it the \
                     turned frame keeps fewer than 10 digits)",
                    self.angle
                ),
            ));
        }
        frame
            .rotated(axis, self.angle)
            .map_err(|e| invalid(format!("{field}.angle"), e.to_string()))
    }
}
