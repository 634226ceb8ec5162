//! The `[support]` table: what holds the tip s = L (absent: a free tip).
//!
//! Classical end conditions in this grammar (the base is always clamped):
//!
//! | support | translation | rotation |
//! |---|---|---|
//! | pinned (spherical joint) | `"fixed"` | `"free"` |
//! | clamped | `"fixed"` | `"fixed"` |
//! | sliding pin (roller along `axis`) | `"axial"` | `"free"` |
//! | guided clamp (slides along `axis`) | `"axial"` | `"fixed"` |
//! | Greenhill's end: slides along and spins about `axis` | `"axial"` | `"axial"` |

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::problem::{invalid, ProblemError};
use crate::model::{Clamp, Frame, Freedom, TipSupport};

/// `[support]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SupportSection {
    /// "fixed", "free" or "axial" (free only along `axis`).
    #[serde(default = "fixed")]
    pub translation: String,
    /// "free", "fixed" or "axial" (free only about `axis`).
    #[serde(default = "free")]
    pub rotation: String,
    /// The sliding / spin axis (unit vector), required for "axial".
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::strict::option"
    )]
    pub axis: Option<[f64; 3]>,
    /// The held tip position; default the unloaded straight rod's tip
    /// r(0) + L d3(0).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::strict::option"
    )]
    pub position: Option<[f64; 3]>,
    /// The held tip frame's d1; default the clamp's.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::strict::option"
    )]
    pub d1: Option<[f64; 3]>,
    /// The held tip frame's d3; default the clamp's.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::strict::option"
    )]
    pub d3: Option<[f64; 3]>,
    /// The held tip frame then turned about a fixed axis by an angle that
    /// may run through any number of turns (a rod twisted at its end).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turn: Option<super::TurnSection>,
}

fn fixed() -> String {
    "fixed".into()
}
fn free() -> String {
    "free".into()
}

/// Unit length and orthogonality tolerance.
const TOLERANCE: f64 = 1e-9;

fn finite_vector(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, ProblemError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(Vector3::from(v))
    } else {
        Err(invalid(field, "must contain finite numbers only"))
    }
}

fn unit(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, ProblemError> {
    let v = finite_vector(field, v)?;
    if (v.norm() - 1.0).abs() > TOLERANCE {
        return Err(invalid(
            field,
            format!("must be a unit vector, |{field}| = {}", v.norm()),
        ));
    }
    Ok(v)
}

impl SupportSection {
    /// The tip support of a rod of `length` clamped by `clamp`.
    pub fn build(&self, clamp: &Clamp, length: f64) -> Result<TipSupport, ProblemError> {
        let axis = self.axis.map(|a| unit("support.axis", a)).transpose()?;
        let freedom = |field: &str, name: &str| match name {
            "fixed" => Ok(Freedom::Fixed),
            "free" => Ok(Freedom::Free),
            "axial" => axis
                .map(Freedom::Axial)
                .ok_or_else(|| invalid("support.axis", format!("required by {field} = \"axial\""))),
            other => Err(invalid(
                field,
                format!("unknown `{other}`; expected \"fixed\", \"free\" or \"axial\""),
            )),
        };
        let translation = freedom("support.translation", &self.translation)?;
        let rotation = freedom("support.rotation", &self.rotation)?;
        if translation == Freedom::Free && rotation == Freedom::Free {
            return Err(invalid(
                "support",
                "holds nothing (translation and rotation free); remove [support] for a free tip",
            ));
        }
        let position = match self.position {
            Some(p) => finite_vector("support.position", p)?,
            None => clamp.position + clamp.director(2) * length,
        };
        Ok(TipSupport {
            position,
            frame: self.frame(clamp)?,
            translation,
            rotation,
        })
    }

    /// The held tip frame from `d1`, `d3` (each defaulting to the clamp's).
    fn frame(&self, clamp: &Clamp) -> Result<Frame, ProblemError> {
        let d1 = match self.d1 {
            Some(v) => unit("support.d1", v)?,
            None => clamp.director(0),
        };
        let d3 = match self.d3 {
            Some(v) => unit("support.d3", v)?,
            None => clamp.director(2),
        };
        if d1.dot(&d3).abs() > TOLERANCE {
            return Err(invalid(
                "support.d3",
                format!("must be orthogonal to support.d1, d1·d3 = {}", d1.dot(&d3)),
            ));
        }
        // Unit and orthogonal to 1e-9 above, so within Frame::TOLERANCE; a
        // frame refused all the same is named by its directors.
        let frame =
            Frame::from_directors(d1, d3).map_err(|e| invalid("support.d3", e.to_string()))?;
        match &self.turn {
            Some(turn) => turn.apply("support.turn", &frame),
            None => Ok(frame),
        }
    }
}
