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
use nalgebra::Vector3;

use crate::model::{Profile, ProfileKind, Rod, RodTangent, StoredEnergy};

/// A number of a rod problem that continuation varies.
pub trait Lens: std::fmt::Debug + Send + Sync {
    /// The number's key, as a problem file names it (`loads.tip_force[2]`,
    /// `support.turn.angle`).
    fn key(&self) -> String;
    /// The rod with the number set to p (everything else as given); the
    /// same p gives the same rod. A value the problem refuses is an error
    /// naming the key, never a clamped rod.
    fn rod_at(&self, p: f64) -> Result<Rod, FamilyError>;
    /// How the rod moves with p at p ([`RodTangent`]), from which the
    /// family's ∂F/∂p is computed exactly; None where the lens does not
    /// know (the family then differentiates by central differences and
    /// says so, [`super::family::DerivativeMethod`]).
    fn tangent(&self, _p: f64) -> Option<RodTangent> {
        None
    }
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
    /// kept ([`crate::model::ProfileEdits::with_constant`]).
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
            .profile_edits()
            .and_then(|e| e.with_constant(kind, i, p))
            .ok_or(FamilyError::NotConstant(self.key()))
    }
}

/// The constant intrinsic curvature of an energy (None when it has no κ⁰
/// profiles or one of them varies along the rod).
fn constant_intrinsic(e: &dyn StoredEnergy) -> Option<Vector3<f64>> {
    let profiles = crate::model::intrinsic_profiles(e)?;
    let mut k = Vector3::zeros();
    for (i, profile) in profiles.iter().enumerate() {
        match profile {
            Profile::Constant(v) => k[i] = *v,
            _ => return None,
        }
    }
    Some(k)
}

impl RodLens {
    /// d(rod)/dp of [`RodLens::rod_at`]: p enters linearly (loads, a
    /// profile, the length) or as the clamp's turn about its fixed d2, so
    /// the rates are constants of the base rod; None where κ⁰ is not a
    /// constant (a varying profile's rate is a function of s, which
    /// [`RodTangent`] does not carry) or the length moves an energy with
    /// explicit s-dependence ([`RodTangent::fits`] decides at the rod).
    fn rates(&self) -> Option<RodTangent> {
        let unit = |i: usize| Vector3::ith(i, 1.0);
        let zero = RodTangent::zero();
        let loads = self.base.loads();
        let energy = self.base.energy();
        let tangent = match self.parameter {
            Parameter::LoadScale => zero.with_loads(loads.clone()),
            Parameter::ControlScale => {
                let k0 = constant_intrinsic(energy.as_ref())?;
                zero.with_loads(loads.clone())
                    .and_then(|t| t.with_intrinsic_curvature(k0))
            }
            Parameter::CurvatureTowards => {
                let from = constant_intrinsic(energy.as_ref())?;
                let to = constant_intrinsic(self.target.as_ref()?.as_ref())?;
                zero.with_loads(loads.clone())
                    .and_then(|t| t.with_intrinsic_curvature(to - from))
            }
            Parameter::TipForce(i) => zero.with_loads(crate::model::DeadLoads {
                tip_force: unit(i),
                ..Default::default()
            }),
            Parameter::TipCouple(i) => zero.with_loads(crate::model::DeadLoads {
                tip_couple: unit(i),
                ..Default::default()
            }),
            Parameter::DistributedForce(i) => zero.with_loads(crate::model::DeadLoads {
                distributed_force: unit(i),
                ..Default::default()
            }),
            Parameter::Length => zero.with_length(1.0),
            Parameter::Stiffness(i) => zero.with_stiffness(unit(i)),
            Parameter::IntrinsicCurvature(i) => zero.with_intrinsic_curvature(unit(i)),
            Parameter::ClampAngle => zero.with_clamp_spin(self.base.clamp().director(1)),
        };
        tangent.ok()
    }
}

impl Lens for RodLens {
    fn key(&self) -> String {
        self.parameter.to_string()
    }

    fn tangent(&self, _p: f64) -> Option<RodTangent> {
        self.rates()
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
                        .profile_edits()
                        .and_then(|e| e.with_intrinsic_scaled(p))
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
                        .and_then(|t| {
                            let edits = self.base.energy().profile_edits()?;
                            edits.with_intrinsic_towards(t.as_ref(), p)
                        })
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
