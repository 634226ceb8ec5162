//! A one-parameter family of rods and its discretized equilibrium equations
//! F(x, p) = 0 (shooting unknowns x, parameter p).
//!
//! F_x is the exact shooting Jacobian (variational equations). F_p is a
//! central difference in p of the converged-tolerance residual; it only
//! steers the predictor and the bordering row, so its O(tolerance/h) error
//! slows the corrector at worst — the points themselves satisfy F = 0 to
//! the Newton tolerance.

use nalgebra::{DMatrix, DVector, Matrix3};

use crate::bvp::newton::NonlinearSystem;
use crate::bvp::{equations, ShootingSystem};
use crate::equations::RodSample;
use crate::model::{ModelLevel, ProfileKind, Rod};
use crate::numerics::integrator::{IntegrationError, Tolerances};

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
    /// [`Family::towards`]. With κ⁰_base = φ' and
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

/// A rod whose one number is the parameter.
#[derive(Debug, Clone)]
pub struct Family {
    base: Rod,
    /// The target energy of [`Parameter::CurvatureTowards`].
    target: Option<std::sync::Arc<dyn crate::model::StoredEnergy>>,
    parameter: Parameter,
    level: ModelLevel,
    segments: usize,
    /// Gauss points per interval when the segments are collocation
    /// intervals (one Gauss step each) rather than integrated segments.
    stages: Option<usize>,
    tolerances: Tolerances,
    /// The unknowns' scales, computed once ([`Family::cached_weights`]).
    weights: std::sync::OnceLock<Vec<f64>>,
}

/// Why a rod could not be built at a parameter value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FamilyError {
    /// The parameter needs a linear energy with constant profiles.
    #[error(
        "continuation.parameter = {0} needs an energy with that profile as a constant (the \
         linear energy, possibly with energy.shear; a stiffness or curvature parameter replaces \
         a constant, never a varying profile)"
    )]
    NotConstant(Parameter),
    /// A value outside the physical range.
    #[error(
        "continuation.parameter = {parameter} is not physical at {value} (a length or stiffness \
         must be positive): narrow continuation.bounds"
    )]
    NotPhysical {
        /// The continuation parameter.
        parameter: Parameter,
        /// Its value outside the physical range.
        value: f64,
    },
}

impl Family {
    /// The family around `base` (its own value of the parameter is
    /// replaced by p), discretized at `level` by shooting on `segments`.
    pub fn new(
        base: Rod,
        parameter: Parameter,
        level: ModelLevel,
        segments: usize,
        tolerances: Tolerances,
    ) -> Self {
        Family {
            base,
            target: None,
            parameter,
            level,
            segments: segments.max(1),
            stages: None,
            tolerances,
            weights: std::sync::OnceLock::new(),
        }
    }

    /// The family on the collocation discretization: Gauss–Legendre
    /// collocation with `stages` points (1 to 3) on `intervals` equal
    /// intervals, its unknowns the node states (see
    /// [`ShootingSystem::collocation`]).
    pub fn collocation(
        base: Rod,
        parameter: Parameter,
        level: ModelLevel,
        intervals: usize,
        stages: usize,
        tolerances: Tolerances,
    ) -> Self {
        // The problem reader checks solver.stages; another value is a
        // caller's error (it was clamped silently, running another order).
        assert!(
            (1..=3).contains(&stages),
            "collocation with {stages} Gauss points; 1 to 3 are implemented"
        );
        Family {
            stages: Some(stages),
            ..Family::new(base, parameter, level, intervals, tolerances)
        }
    }

    /// The discrete system at a rod's equations.
    fn system<'e>(&self, eq: &'e dyn crate::equations::RodEquations) -> ShootingSystem<'e> {
        match self.stages {
            Some(m) => ShootingSystem::collocation(eq, self.segments, m, self.tolerances)
                .expect("stages checked in Family::collocation"),
            None => ShootingSystem::new(eq, self.segments, self.tolerances),
        }
    }

    /// The family [`Parameter::CurvatureTowards`]: the loads of `base`
    /// scaled by p, κ⁰ moved from `base`'s to `target`'s.
    pub fn towards(
        base: Rod,
        target: std::sync::Arc<dyn crate::model::StoredEnergy>,
        level: ModelLevel,
        segments: usize,
        tolerances: Tolerances,
    ) -> Self {
        Family {
            target: Some(target),
            ..Family::new(
                base,
                Parameter::CurvatureTowards,
                level,
                segments,
                tolerances,
            )
        }
    }

    /// The BVP method of the family's discretization, or, for collocation,
    /// the multiple shooting on the same nodes whose solution starts the
    /// branch (Newton then moves it onto the collocation equations).
    pub fn method(&self) -> crate::bvp::Method {
        match self.segments {
            1 => crate::bvp::Method::Shooting,
            segments => crate::bvp::Method::MultipleShooting { segments },
        }
    }

    /// The length of the base rod (the problem's `rod.length`).
    pub fn base_length(&self) -> f64 {
        self.base.length()
    }

    /// The model level.
    pub fn level(&self) -> ModelLevel {
        self.level
    }

    /// The parameter.
    pub fn parameter(&self) -> Parameter {
        self.parameter
    }

    /// The rod at p.
    pub fn rod_at(&self, p: f64) -> Result<Rod, FamilyError> {
        let mut rod = self.base.clone();
        let bad = || FamilyError::NotPhysical {
            parameter: self.parameter,
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
                        .ok_or(FamilyError::NotConstant(self.parameter))?,
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
                        .ok_or(FamilyError::NotConstant(self.parameter))?,
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

    /// The base energy with one constant profile set to p, everything else
    /// (the other profiles, the shear and extension part of a Cosserat rod)
    /// kept ([`crate::model::StoredEnergy::with_constant`]).
    fn linear_with(
        &self,
        p: f64,
    ) -> Result<std::sync::Arc<dyn crate::model::StoredEnergy>, FamilyError> {
        let (kind, i) = match self.parameter {
            Parameter::Stiffness(i) => {
                if p <= 0.0 {
                    return Err(FamilyError::NotPhysical {
                        parameter: self.parameter,
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
            .ok_or(FamilyError::NotConstant(self.parameter))
    }

    /// The typical magnitudes of the shooting unknowns: 1 for the free
    /// values at the clamp, the state scales (lengths L, curvatures 1/L,
    /// reactions M_s/L, see [`crate::equations::RodEquations::state_scales`])
    /// for the interior node states of multiple shooting. The family's
    /// unknowns x are the shooting unknowns divided by these, so that the
    /// arclength of continuation is not dominated by node positions of long
    /// rods.
    fn weights(&self) -> Vec<f64> {
        let eq = equations(&self.base, self.level);
        let mut w = vec![1.0; eq.unknowns()];
        let scales = eq.state_scales();
        for _ in 1..self.segments {
            w.extend_from_slice(&scales);
        }
        w
    }

    /// The family's unknowns of raw shooting unknowns.
    pub fn scaled(&self, raw: &[f64]) -> Vec<f64> {
        raw.iter()
            .zip(self.cached_weights())
            .map(|(v, w)| v / w)
            .collect()
    }

    /// The raw shooting unknowns of the family's unknowns.
    pub fn unscaled(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(self.cached_weights())
            .map(|(v, w)| v * w)
            .collect()
    }

    /// F(x, p) and F_x (with respect to the family's scaled unknowns), the
    /// residual scaled as in [`ShootingSystem`].
    pub fn residual(
        &self,
        x: &[f64],
        p: f64,
        r: &mut DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), PointError> {
        let rod = self.rod_at(p)?;
        let eq = equations(&rod, self.level);
        let mut sys = self.system(eq.as_ref());
        sys.evaluate(&self.unscaled(x), r, jac)?;
        for (mut column, w) in jac.column_iter_mut().zip(self.cached_weights()) {
            column *= *w;
        }
        Ok(())
    }

    /// F_p by a central difference with h = 1e-4 max(1, |p|).
    pub fn parameter_derivative(&self, x: &[f64], p: f64) -> Result<DVector<f64>, PointError> {
        let n = x.len();
        let h = 1e-4 * p.abs().max(1.0);
        let (mut a, mut b) = (DVector::zeros(n), DVector::zeros(n));
        self.residual_only(x, p + h, &mut a)?;
        self.residual_only(x, p - h, &mut b)?;
        Ok((a - b) / (2.0 * h))
    }

    /// F(x, p) without its Jacobian.
    pub fn residual_only(&self, x: &[f64], p: f64, r: &mut DVector<f64>) -> Result<(), PointError> {
        let rod = self.rod_at(p)?;
        let eq = equations(&rod, self.level);
        let mut sys = self.system(eq.as_ref());
        sys.residual(&self.unscaled(x), r)?;
        Ok(())
    }

    /// Number of discrete unknowns.
    pub fn size(&self) -> usize {
        let eq = equations(&self.base, self.level);
        eq.unknowns() + eq.dim() * (self.segments - 1)
    }

    /// A starting vector of unknowns at p: the straight-rod balance guess,
    /// integrated across the segments.
    pub fn initial_unknowns(&self, p: f64) -> Result<Vec<f64>, PointError> {
        let rod = self.rod_at(p)?;
        let eq = equations(&rod, self.level);
        let u = eq.initial_guess();
        let mut sys = self.system(eq.as_ref());
        Ok(self.scaled(&sys.initial_unknowns(&u)))
    }

    /// The solution at sorted points.
    pub fn samples(&self, x: &[f64], p: f64, points: &[f64]) -> Result<Vec<RodSample>, PointError> {
        let rod = self.rod_at(p)?;
        let eq = equations(&rod, self.level);
        let mut sys = self.system(eq.as_ref());
        Ok(sys.sample_interpolated(&self.unscaled(x), points)?.0)
    }

    /// The tip sample (position, directors) at (x, p).
    pub fn tip(&self, x: &[f64], p: f64) -> Result<RodSample, PointError> {
        let l = self.rod_at(p)?.length();
        Ok(self.samples(x, p, &[l])?.remove(0))
    }
}

/// Why a point of the family could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PointError {
    /// The rod is not defined at this parameter value.
    #[error(transparent)]
    Family(#[from] FamilyError),
    /// The integration failed.
    #[error(transparent)]
    Integration(#[from] IntegrationError),
    /// The eigensolver failed.
    #[error("eigenvalues: {0}")]
    Eigen(String),
    /// Newton at fixed parameter did not converge.
    #[error("Newton did not converge at p = {0}")]
    NoConvergence(f64),
    /// [F_x F_p] bordered by the previous tangent is singular: no tangent
    /// (the branch is degenerate there).
    #[error("no tangent at p = {0}: the bordered Jacobian is singular")]
    SingularTangent(f64),
}

/// The angle (rad) between the tip tangent and the clamp tangent.
pub fn tip_angle(clamp: &Matrix3<f64>, tip: &RodSample) -> f64 {
    let t0 = clamp.column(2);
    tip.directors[2].dot(&t0).clamp(-1.0, 1.0).acos()
}

/// What the residual evaluation computes once per family instead of at
/// every call.
impl Family {
    /// [`Family::weights`], computed on first use: they depend on the base
    /// rod, the level and the segments only, none of which changes after
    /// construction, and each computation builds the equations and their
    /// state scales (65 evaluations of the energy for the intrinsic
    /// moment) — twice per residual with its Jacobian before.
    fn cached_weights(&self) -> &[f64] {
        self.weights.get_or_init(|| self.weights())
    }
}
