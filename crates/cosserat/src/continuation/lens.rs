//! Parameters as lenses: a continued number is whatever gives the rod at
//! p (BifurcationKit's lenses on a problem's parameters, in spirit), not a
//! closed list in the engine.
//!
//! [`Lens`] is the whole contract: a key naming the number and the rod at
//! p. [`RodLens`] is the library's own set of parameters on a base rod
//! ([`Parameter`]: load components and scalings, length, constant
//! stiffness and intrinsic curvature, the clamp angle, the arm's control
//! paths), fast because it edits the rod in place. The input stage adds a
//! lens for any numeric problem-file key (`--set` grammar), which rereads
//! the problem with the key set, so that every key the reader accepts —
//! boundary data, end turns, an energy's parameters — can be continued.

use std::sync::Arc;

use super::family::FamilyError;
use crate::model::{ProfileKind, Rod, StoredEnergy};

/// A number of a rod problem that continuation varies.
pub trait Lens: std::fmt::Debug + Send + Sync {
    /// The number's key, as a problem file names it (`loads.tip_force[2]`,
    /// `support.turn.angle`).
    fn key(&self) -> String;
    /// The rod with the number set to p (everything else as given); the
    /// same p gives the same rod. A value the problem refuses is an error
    /// naming the key, never a clamped rod.
    fn rod_at(&self, p: f64) -> Result<Rod, FamilyError>;
}

/// Which number of the rod the parameter sets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Parameter {
    /// All loads multiplied by p.
    LoadScale,
    /// All loads and the intrinsic curvature κ⁰(s) multiplied by p
    /// together: the control path of a designed arm, on which the
    /// actuators raise κ⁰ as the load is applied (paper Sec. 5).
    ControlScale,
    /// All loads multiplied by p and the intrinsic curvature moved from
    /// the base rod's (p = 0) to a target's (p = 1),
    /// κ⁰ = (1 − p) κ⁰_base + p κ⁰_target; build with
    /// [`super::Family::towards`]. With κ⁰_base = φ' and
    /// κ⁰_target from (43) the designed shape is an equilibrium all along
    /// (the shape-holding control of a designed arm).
    CurvatureTowards,
    /// Component i of the tip force.
    TipForce(usize),
    /// Component i of the tip couple.
    TipCouple(usize),
    /// Component i of the distributed force.
    DistributedForce(usize),
    /// The rod length.
    Length,
    /// The constant stiffness B_i (i = 0, 1, 2).
    Stiffness(usize),
    /// The constant intrinsic curvature κ⁰_i.
    IntrinsicCurvature(usize),
    /// The clamp turned by p (rad) about d2(0), d3 towards d1.
    ClampAngle,
}

impl std::fmt::Display for Parameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Parameter::LoadScale => f.write_str("load_scale"),
            Parameter::ControlScale => f.write_str("control_scale"),
            Parameter::CurvatureTowards => f.write_str("the shape-holding control"),
            Parameter::TipForce(i) => write!(f, "loads.tip_force[{i}]"),
            Parameter::TipCouple(i) => write!(f, "loads.tip_couple[{i}]"),
            Parameter::DistributedForce(i) => write!(f, "loads.distributed_force[{i}]"),
            Parameter::Length => f.write_str("rod.length"),
            Parameter::Stiffness(i) => write!(f, "energy.stiffness[{i}]"),
            Parameter::IntrinsicCurvature(i) => write!(f, "energy.intrinsic_curvature[{i}]"),
            Parameter::ClampAngle => f.write_str("clamp.angle"),
        }
    }
}

impl Parameter {
    /// Whether the parameter is a number a problem file writes (a load
    /// component, the length, a stiffness…), not one of the library's
    /// scalings of several numbers at once (`load_scale`, `control_scale`,
    /// the shape-holding control).
    pub fn is_file_key(self) -> bool {
        !matches!(
            self,
            Parameter::LoadScale | Parameter::ControlScale | Parameter::CurvatureTowards
        )
    }

    /// The parameter named by a problem-file key: `load_scale`,
    /// `loads.tip_force[i]`, `loads.tip_couple[i]`,
    /// `loads.distributed_force[i]`, `control_scale`, `rod.length`, `energy.stiffness[i]`,
    /// `energy.intrinsic_curvature[i]`, `clamp.angle`.
    pub fn from_key(key: &str) -> Option<Parameter> {
        let indexed = |prefix: &str| -> Option<usize> {
            let rest = key
                .strip_prefix(prefix)?
                .strip_prefix('[')?
                .strip_suffix(']')?;
            rest.parse().ok().filter(|i| *i < 3)
        };
        Some(match key {
            "load_scale" => Parameter::LoadScale,
            "control_scale" => Parameter::ControlScale,
            "rod.length" => Parameter::Length,
            "clamp.angle" => Parameter::ClampAngle,
            _ => {
                if let Some(i) = indexed("loads.tip_force") {
                    Parameter::TipForce(i)
                } else if let Some(i) = indexed("loads.tip_couple") {
                    Parameter::TipCouple(i)
                } else if let Some(i) = indexed("loads.distributed_force") {
                    Parameter::DistributedForce(i)
                } else if let Some(i) = indexed("energy.stiffness") {
                    Parameter::Stiffness(i)
                } else if let Some(i) = indexed("energy.intrinsic_curvature") {
                    Parameter::IntrinsicCurvature(i)
                } else {
                    return None;
                }
            }
        })
    }
}

/// A [`Parameter`] of a base rod.
#[derive(Debug, Clone)]
pub struct RodLens {
    base: Rod,
    /// The target energy of [`Parameter::CurvatureTowards`].
    target: Option<Arc<dyn StoredEnergy>>,
    parameter: Parameter,
}

impl RodLens {
    /// `parameter` of `base` (its own value replaced by p).
    pub fn new(base: Rod, parameter: Parameter) -> Self {
        RodLens {
            base,
            target: None,
            parameter,
        }
    }

    /// [`Parameter::CurvatureTowards`]: the loads of `base` scaled by p,
    /// κ⁰ moved from `base`'s to `target`'s.
    pub fn towards(base: Rod, target: Arc<dyn StoredEnergy>) -> Self {
        RodLens {
            base,
            target: Some(target),
            parameter: Parameter::CurvatureTowards,
        }
    }

    /// The parameter.
    pub fn parameter(&self) -> Parameter {
        self.parameter
    }

    /// The base energy with one constant profile set to p, everything else
    /// (the other profiles, the shear and extension part of a Cosserat rod)
    /// kept ([`crate::model::StoredEnergy::with_constant`]).
    fn linear_with(&self, p: f64) -> Result<Arc<dyn StoredEnergy>, FamilyError> {
        let (kind, i) = match self.parameter {
            Parameter::Stiffness(i) => {
                if p <= 0.0 {
                    return Err(FamilyError::NotPhysical {
                        parameter: self.key(),
                        value: p,
                    });
                }
                (ProfileKind::Stiffness, i)
            }
            Parameter::IntrinsicCurvature(i) => (ProfileKind::IntrinsicCurvature, i),
            _ => unreachable!("only profile parameters"),
        };
        self.base
            .energy()
            .with_constant(kind, i, p)
            .ok_or(FamilyError::NotConstant(self.key()))
    }
}

impl Lens for RodLens {
    fn key(&self) -> String {
        self.parameter.to_string()
    }

    fn rod_at(&self, p: f64) -> Result<Rod, FamilyError> {
        let mut rod = self.base.clone();
        let bad = || FamilyError::NotPhysical {
            parameter: self.key(),
            value: p,
        };
        if !p.is_finite() {
            return Err(bad());
        }
        match self.parameter {
            Parameter::LoadScale => {
                rod = rod
                    .with_loads(self.base.loads().scaled(p))
                    .map_err(|_| bad())?;
            }
            Parameter::ControlScale => {
                rod = rod
                    .with_loads(self.base.loads().scaled(p))
                    .map_err(|_| bad())?;
                rod = rod.with_energy(
                    self.base
                        .energy()
                        .with_intrinsic_scaled(p)
                        .ok_or(FamilyError::NotConstant(self.key()))?,
                );
            }
            Parameter::CurvatureTowards => {
                rod = rod
                    .with_loads(self.base.loads().scaled(p))
                    .map_err(|_| bad())?;
                rod = rod.with_energy(
                    self.target
                        .as_ref()
                        .and_then(|t| self.base.energy().with_intrinsic_towards(t.as_ref(), p))
                        .ok_or(FamilyError::NotConstant(self.key()))?,
                );
            }
            Parameter::TipForce(_) | Parameter::TipCouple(_) | Parameter::DistributedForce(_) => {
                let mut loads = self.base.loads().clone();
                match self.parameter {
                    Parameter::TipForce(i) => loads.tip_force[i] = p,
                    Parameter::TipCouple(i) => loads.tip_couple[i] = p,
                    Parameter::DistributedForce(i) => loads.distributed_force[i] = p,
                    _ => unreachable!("only load components"),
                }
                rod = rod.with_loads(loads).map_err(|_| bad())?;
            }
            Parameter::Length => {
                if p <= 0.0 {
                    return Err(bad());
                }
                rod = rod.with_length(p).map_err(|_| bad())?;
            }
            Parameter::ClampAngle => {
                // About d2 by +p: d3 turns towards d1 (R d3 = d3 cos p + d1 sin p).
                let mut clamp = self.base.clamp().clone();
                clamp.frame = clamp.turned_frame(p).map_err(|_| bad())?;
                rod = rod.with_clamp(clamp).map_err(|_| bad())?;
            }
            Parameter::Stiffness(_) | Parameter::IntrinsicCurvature(_) => {
                rod = rod.with_energy(self.linear_with(p)?);
            }
        }
        Ok(rod)
    }
}
