//! A one-parameter family of rods and its discretized equilibrium equations
//! F(x, p) = 0 (shooting unknowns x, parameter p).
//!
//! F_x is the exact shooting Jacobian (variational equations). F_p is
//! exact too where the lens says how the rod moves with p
//! ([`Lens::tangent`]): the sensitivity equations z' = f_y z + ∂f/∂p,
//! z(0) = ∂y(0)/∂p, integrated with the state, and the explicit
//! p-dependence of the tip residual and of the residuals' units. Elsewhere
//! (a lens without a tangent, a tip support) it is a central difference in
//! p, and [`Family::derivative_method`] says so: F_p steers the predictor,
//! the bordering row and the tangents that locate folds, so its O(h²)
//! error moves located folds, while the points themselves satisfy F = 0
//! to the Newton tolerance either way.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3};

use super::lens::{Lens, Parameter, RodLens};

use crate::bvp::{equations, ShootingSystem};
use crate::equations::RodSample;
use crate::model::{ModelLevel, Rod};
use crate::numerics::integrator::{IntegrationError, Tolerances};
use crate::numerics::staircase::Staircase;

/// The most segments of the multiple shooting that solves the start of a
/// branch ([`Family::method`]): its dense Newton costs O(K³).
const START_SEGMENTS: usize = 32;

/// The integrator's smallest tolerance (the problem files' floor for
/// `solver.integration_tolerance`: below it DOP853's steps underflow in
/// round-off).
const TOLERANCE_FLOOR: f64 = 1e-14;

/// How much tighter the refined shooting family's tolerances are at most
/// ([`Family::refined`]).
const MAX_GAIN: f64 = 100.0;

/// The least refinement gain that still tells the error apart from the
/// refined point's own ([`Family::refined`]).
const MIN_GAIN: f64 = 10.0;

/// A rod whose one number is the parameter: a [`Lens`] gives the rod at
/// p, the family discretizes its equilibrium equations.
#[derive(Debug, Clone)]
pub struct Family {
    /// The rod at the start (its sizes and scales weight the unknowns).
    base: Rod,
    lens: Arc<dyn Lens>,
    level: ModelLevel,
    segments: usize,
    /// Gauss points per interval when the segments are collocation
    /// intervals (one Gauss step each) rather than integrated segments.
    stages: Option<usize>,
    tolerances: Tolerances,
    /// The unknowns' scales, computed once ([`Family::cached_weights`]).
    weights: std::sync::OnceLock<Vec<f64>>,
    /// The exact F_p of the last residual evaluation.
    last_fp: DerivativeCache,
}

/// The exact F_p integrated with the last F and F_x ([`Family::residual`],
/// [`Family::residual_staircase`]) at (x, p), so that
/// [`Family::parameter_derivative`] at the same point — the corrector's
/// bordering column, the tangent at a converged point — costs no
/// integration. A clone starts empty (another family's lens may differ).
#[derive(Debug, Default)]
struct DerivativeCache(std::sync::Mutex<Option<CachedDerivative>>);

#[derive(Debug)]
struct CachedDerivative {
    x: Vec<f64>,
    p: f64,
    fp: DVector<f64>,
}

impl Clone for DerivativeCache {
    fn clone(&self) -> Self {
        DerivativeCache::default()
    }
}

impl DerivativeCache {
    fn lock(&self) -> std::sync::MutexGuard<'_, Option<CachedDerivative>> {
        // A panic while the entry was written leaves at worst a stale
        // entry of another point, which the key comparison rejects.
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// F_p at exactly (x, p), if the last evaluation was there.
    fn get(&self, x: &[f64], p: f64) -> Option<DVector<f64>> {
        let entry = self.lock();
        let e = entry.as_ref()?;
        (e.p.to_bits() == p.to_bits()
            && e.x.len() == x.len()
            && e.x.iter().zip(x).all(|(a, b)| a.to_bits() == b.to_bits()))
        .then(|| e.fp.clone())
    }

    /// Keeps F_p at (x, p), reusing the entry's buffers.
    fn put(&self, x: &[f64], p: f64, fp: &DVector<f64>) {
        let mut entry = self.lock();
        match entry.as_mut() {
            Some(e) if e.x.len() == x.len() && e.fp.len() == fp.len() => {
                e.x.copy_from_slice(x);
                e.p = p;
                e.fp.copy_from(fp);
            }
            _ => {
                *entry = Some(CachedDerivative {
                    x: x.to_vec(),
                    p,
                    fp: fp.clone(),
                });
            }
        }
    }
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
    NotConstant(String),
    /// A value outside the physical range.
    #[error(
        "continuation.parameter = {parameter} is not physical at {value} (a length or stiffness \
         must be positive): narrow continuation.bounds"
    )]
    NotPhysical {
        /// The continuation parameter's key.
        parameter: String,
        /// Its value outside the physical range.
        value: f64,
    },
    /// The problem with the parameter set to the value is refused by the
    /// problem's own checks (a generic lens rereads the problem).
    #[error("continuation.parameter = {parameter} at {value}: {reason}")]
    Refused {
        /// The continuation parameter's key.
        parameter: String,
        /// The value.
        value: f64,
        /// The problem's error at that value.
        reason: String,
    },
    /// The rod at the value needs a richer model than the family's.
    #[error(
        "continuation.parameter = {parameter} at {value} takes the rod out of the planar \
         model the branch started on ({why}); set solver.model = \"kirchhoff\""
    )]
    NeedsModel {
        /// The continuation parameter's key.
        parameter: String,
        /// The value.
        value: f64,
        /// What the planar model cannot represent.
        why: String,
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
        let lens = Arc::new(RodLens::new(base.clone(), parameter));
        Family::of_lens(lens, base, level, segments, tolerances)
    }

    /// The family of any [`Lens`] (e.g. a problem-file key read by the
    /// input stage), `base` its rod at the start, discretized at `level` by
    /// shooting on `segments`.
    pub fn of_lens(
        lens: Arc<dyn Lens>,
        base: Rod,
        level: ModelLevel,
        segments: usize,
        tolerances: Tolerances,
    ) -> Self {
        Family {
            base,
            lens,
            level,
            segments: segments.max(1),
            stages: None,
            tolerances,
            weights: std::sync::OnceLock::new(),
            last_fp: DerivativeCache::default(),
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
        Family::new(base, parameter, level, intervals, tolerances).collocated(stages)
    }

    /// The same family with its segments as collocation intervals of
    /// `stages` Gauss points (1 to 3).
    #[must_use]
    pub fn collocated(self, stages: usize) -> Self {
        // The problem reader checks solver.stages; another value is a
        // caller's error (it was clamped silently, running another order).
        assert!(
            (1..=3).contains(&stages),
            "collocation with {stages} Gauss points; 1 to 3 are implemented"
        );
        Family {
            stages: Some(stages),
            // Another discretization: no F_p of the old one is reused.
            last_fp: DerivativeCache::default(),
            ..self
        }
    }

    /// The same family on a finer discretization, and how many times
    /// smaller its error is expected to be (the gain): collocation on
    /// twice the intervals (the nodes' error falls by 2^{2m} at order 2m),
    /// shooting with its integration tolerances divided by up to 100, down
    /// to the integrator's floor 1e-14 (DOP853's global error follows its
    /// tolerance). Located special points are located again on it, and
    /// the difference, scaled by gain/(gain − 1), is their discretization
    /// error (`events.rs`). Err says why there is none: a tolerance within
    /// a factor 10 of the floor.
    pub fn refined(&self) -> Result<(Family, f64), String> {
        let mut fine = self.clone();
        let gain = if let Some(m) = self.stages {
            fine.segments = 2 * self.segments;
            // The node states' weights carry 1/√K.
            fine.weights = std::sync::OnceLock::new();
            f64::from(1u32 << (2 * m))
        } else {
            let coarse = self.tolerances.rtol.min(self.tolerances.atol);
            let gain = (coarse / TOLERANCE_FLOOR).min(MAX_GAIN);
            if gain < MIN_GAIN {
                return Err(format!(
                    "the integration tolerance {coarse:.1e} is within a factor \
                     {MIN_GAIN} of the integrator's floor {TOLERANCE_FLOOR:.0e}"
                ));
            }
            fine.tolerances.rtol = self.tolerances.rtol / gain;
            fine.tolerances.atol = self.tolerances.atol / gain;
            gain
        };
        fine.last_fp = DerivativeCache::default();
        Ok((fine, gain))
    }

    /// The segments (shooting) or intervals (collocation) of the mesh.
    pub fn intervals(&self) -> usize {
        self.segments
    }

    /// Gauss points per interval where the family is collocation.
    pub fn stages(&self) -> Option<usize> {
        self.stages
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
        target: Arc<dyn crate::model::StoredEnergy>,
        level: ModelLevel,
        segments: usize,
        tolerances: Tolerances,
    ) -> Self {
        let lens = Arc::new(RodLens::towards(base.clone(), target));
        Family::of_lens(lens, base, level, segments, tolerances)
    }

    /// The BVP method that solves the start of a branch: shooting for a
    /// single-shooting family, otherwise multiple shooting on at most
    /// 32 equal segments (`START_SEGMENTS`) (its dense Newton costs O(K³), so
    /// a fine family is started from a coarse solve):
    /// [`Family::start_unknowns`] carries its solution onto the family's
    /// nodes, and Newton at the start value (O(K), banded) then moves it
    /// onto the family's equations (collocation or finer shooting).
    pub fn method(&self) -> crate::bvp::Method {
        match self.segments.min(START_SEGMENTS) {
            1 => crate::bvp::Method::Shooting,
            segments => crate::bvp::Method::MultipleShooting { segments },
        }
    }

    /// The family's (scaled) unknowns at p from the raw unknowns of a
    /// solve by [`Family::method`]: the same vector when the segments
    /// agree, otherwise the node states integrated from the coarse
    /// solution ([`ShootingSystem::refined_unknowns`]), O(K).
    pub fn start_unknowns(&self, raw: &[f64], p: f64) -> Result<Vec<f64>, PointError> {
        let coarse = self.segments.min(START_SEGMENTS);
        if coarse == self.segments {
            return Ok(self.scaled(raw));
        }
        let rod = self.rod_at(p)?;
        let eq = equations(&rod, self.level);
        let mut sys = ShootingSystem::new(eq.as_ref(), coarse, self.tolerances);
        Ok(self.scaled(&sys.refined_unknowns(raw, self.segments)?))
    }

    /// The family's unknowns at p from the raw shooting unknowns of a
    /// stored solve: those of [`Family::method`] (carried onto the
    /// family's nodes by [`Family::start_unknowns`]) or of the family's own
    /// segments; another count (another level, method or mesh) is refused
    /// naming both.
    pub fn solved_unknowns(&self, raw: &[f64], p: f64) -> Result<Vec<f64>, String> {
        let eq = equations(&self.base, self.level);
        let coarse = eq.unknowns() + eq.dim() * (self.segments.min(START_SEGMENTS) - 1);
        if raw.len() == self.size() {
            Ok(self.scaled(raw))
        } else if raw.len() == coarse {
            self.start_unknowns(raw, p).map_err(|e| e.to_string())
        } else {
            Err(format!(
                "the solve has {} unknowns; this continuation starts from {coarse} ({} model, {} \
                 segments) or {} (its own discretization): solve with the same model and \
                 solver.method",
                raw.len(),
                self.level.name(),
                self.segments.min(START_SEGMENTS),
                self.size()
            ))
        }
    }

    /// This family's unknowns from the unknowns `x` of another family
    /// `from` (a stored diagram's) at its parameter value `p`: unscaled
    /// by `from`'s weights (its base rod's state scales, which move with
    /// the loads, length and stiffness the stored problem had), then, on
    /// another mesh, carried onto this family's nodes by integrating the
    /// stored solution of `from`'s rod at `p`
    /// ([`ShootingSystem::refined_unknowns`]), and scaled by this
    /// family's weights. Reusing the scaled vector as it is would start
    /// Newton from another shape wherever the two base rods' scales
    /// differ. Refused, naming both, when the states differ in size
    /// (another model level or tip support) or `x` is not of `from`.
    pub fn carried(&self, from: &Family, x: &[f64], p: f64) -> Result<Vec<f64>, CarryError> {
        if x.len() != from.size() {
            return Err(CarryError::Size {
                found: x.len(),
                expected: from.size(),
            });
        }
        let (dim_from, dim) = (
            equations(&from.base, from.level).dim(),
            equations(&self.base, self.level).dim(),
        );
        if from.level != self.level || dim_from != dim {
            return Err(CarryError::Layout {
                from: format!("{} model, {dim_from} states", from.level.name()),
                to: format!("{} model, {dim} states", self.level.name()),
            });
        }
        let raw = from.unscaled(x);
        if from.segments == self.segments {
            return Ok(self.scaled(&raw));
        }
        let rod = from.rod_at(p).map_err(PointError::from)?;
        let eq = equations(&rod, from.level);
        let mut sys = ShootingSystem::new(eq.as_ref(), from.segments, from.tolerances);
        let fine = sys
            .refined_unknowns(&raw, self.segments)
            .map_err(PointError::from)?;
        Ok(self.scaled(&fine))
    }

    /// A direction of travel (x, p) of `from` as one of this family: the
    /// x part rescaled as [`Family::carried`] does on the same mesh; on
    /// another mesh only the sense in p is kept (x part zero).
    pub fn carried_direction(&self, from: &Family, t: &[f64]) -> Option<Vec<f64>> {
        let (tp, tx) = t.split_last()?;
        let mut d = if from.segments == self.segments && tx.len() == self.size() {
            let mut d = self.scaled(&from.unscaled(tx));
            d.push(*tp);
            d
        } else {
            let mut d = vec![0.0; self.size()];
            d.push(tp.signum());
            d
        };
        let norm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
        for v in &mut d {
            *v /= norm;
        }
        Some(d)
    }

    /// The length of the base rod (the problem's `rod.length`).
    pub fn base_length(&self) -> f64 {
        self.base.length()
    }

    /// Where the base rod's internal force jumps (its interior point
    /// loads, [`crate::model::DeadLoads::jumps`]).
    pub fn base_jumps(&self) -> Vec<f64> {
        self.base.loads().jumps()
    }

    /// The model level.
    pub fn level(&self) -> ModelLevel {
        self.level
    }

    /// The same discretization of another lens (a slice of a
    /// two-parameter family at a fixed second parameter).
    #[must_use]
    pub fn with_lens(&self, lens: Arc<dyn Lens>) -> Family {
        Family {
            lens,
            ..self.clone()
        }
    }

    /// The parameter's key (`loads.tip_force[2]`, `support.turn.angle`).
    pub fn key(&self) -> String {
        self.lens.key()
    }

    /// The rod at p: the lens's rod, refused where it needs a richer
    /// model than the family's level (a planar family whose parameter turns
    /// a load or an end out of the plane would otherwise drop the
    /// out-of-plane part without a word).
    pub fn rod_at(&self, p: f64) -> Result<Rod, FamilyError> {
        let rod = self.lens.rod_at(p)?;
        if self.level == ModelLevel::Planar {
            if let Err(why) = crate::model::ModelChoice::forced(&rod, ModelLevel::Planar) {
                return Err(FamilyError::NeedsModel {
                    parameter: self.lens.key(),
                    value: p,
                    why,
                });
            }
        }
        Ok(rod)
    }

    /// The typical magnitudes of the shooting unknowns: 1 for the free
    /// values at the clamp, the state scales (lengths L, curvatures 1/L,
    /// reactions M_s/L, see [`crate::equations::RodEquations::state_scales`])
    /// for the interior node states of multiple shooting. The family's
    /// unknowns x are the shooting unknowns divided by these, so that the
    /// arclength of continuation is not dominated by node positions of long
    /// rods.
    ///
    /// On the collocation mesh the node states are further divided by
    /// √K (K intervals), so that their part of the arclength is the
    /// root-mean-square of the node states — a discrete L² norm of the
    /// solution, as AUTO's integral norm — and a step moves the parameter
    /// as far on 32 intervals as on 8 or on shooting's few unknowns (with
    /// the Euclidean norm of all node states, 33 nodes moved p three times
    /// less per step than shooting: docs/performance.md). Multiple
    /// shooting keeps the plain scales: the arm's loading path on 32
    /// segments runs its correctors at the noise floor near λ = 0.976
    /// and keeps its points as they were.
    fn weights(&self) -> Vec<f64> {
        let eq = equations(&self.base, self.level);
        let mut w = vec![1.0; eq.unknowns()];
        let per_node = match self.stages {
            Some(_) => (self.segments as f64).sqrt(),
            None => 1.0,
        };
        let scales: Vec<f64> = eq.state_scales().iter().map(|s| s * per_node).collect();
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
        let mut a = sys.staircase();
        self.evaluate_with_derivative(&mut sys, x, p, r, &mut a)?;
        a.write_dense(jac);
        for (mut column, w) in jac.column_iter_mut().zip(self.cached_weights()) {
            column *= *w;
        }
        Ok(())
    }

    /// F and F_x (raw unknowns' columns) into `r`, `a`; with the exact F_p
    /// from the same integration kept for [`Family::parameter_derivative`]
    /// where the lens gives a tangent the equations differentiate.
    fn evaluate_with_derivative(
        &self,
        sys: &mut ShootingSystem,
        x: &[f64],
        p: f64,
        r: &mut DVector<f64>,
        a: &mut Staircase,
    ) -> Result<(), PointError> {
        let raw = self.unscaled(x);
        match self.lens.tangent(p).filter(|t| sys.differentiates(t)) {
            Some(t) => {
                let mut fp = DVector::zeros(x.len());
                sys.evaluate_staircase_forced(&raw, r, a, Some((&t, &mut fp)))?;
                self.last_fp.put(x, p, &fp);
            }
            None => sys.evaluate_staircase(&raw, r, a)?,
        }
        Ok(())
    }

    /// The zero F_x in the almost block diagonal shape of multiple
    /// shooting and collocation (K > 1 segments or intervals), for
    /// [`Family::residual_staircase`]; None for single shooting, whose
    /// F_x is small and dense ([`Family::residual`]).
    pub fn staircase(&self) -> Option<Staircase> {
        if self.segments == 1 {
            return None;
        }
        let eq = equations(&self.base, self.level);
        Some(self.system(eq.as_ref()).staircase())
    }

    /// F(x, p) and F_x as [`Family::residual`], with F_x in the shape of
    /// [`Family::staircase`]: O(K) memory and work, what every
    /// continuation step on a fine mesh uses.
    pub fn residual_staircase(
        &self,
        x: &[f64],
        p: f64,
        r: &mut DVector<f64>,
        jac: &mut Staircase,
    ) -> Result<(), PointError> {
        let rod = self.rod_at(p)?;
        let eq = equations(&rod, self.level);
        let mut sys = self.system(eq.as_ref());
        self.evaluate_with_derivative(&mut sys, x, p, r, jac)?;
        jac.scale_columns(self.cached_weights());
        Ok(())
    }

    /// F_p = ∂F/∂p at (x, p): exact by the sensitivity equations
    /// ([`ShootingSystem::parameter_derivative`]; free when F and F_x were
    /// just evaluated at (x, p), whose integration carried it) where the
    /// lens gives its
    /// [`crate::model::RodTangent`] and the equations differentiate it,
    /// otherwise by [`Family::central_difference`]; which one is
    /// [`Family::derivative_method`].
    pub fn parameter_derivative(&self, x: &[f64], p: f64) -> Result<DVector<f64>, PointError> {
        if let Some(fp) = self.last_fp.get(x, p) {
            return Ok(fp);
        }
        if let Some(t) = self.lens.tangent(p) {
            let rod = self.rod_at(p)?;
            let eq = equations(&rod, self.level);
            if eq.differentiates(&t) {
                let mut fp = DVector::zeros(x.len());
                self.system(eq.as_ref())
                    .parameter_derivative(&self.unscaled(x), &t, &mut fp)?;
                return Ok(fp);
            }
        }
        self.central_difference(x, p)
    }

    /// How [`Family::parameter_derivative`] computes F_p at p: exact where
    /// the lens knows how the rod moves and the equations differentiate
    /// that motion, by central differences elsewhere (a lens without a
    /// tangent, a key the tangent does not cover, a tip support).
    pub fn derivative_method(&self, p: f64) -> Result<DerivativeMethod, FamilyError> {
        let Some(t) = self.lens.tangent(p) else {
            return Ok(DerivativeMethod::CentralDifference);
        };
        let rod = self.rod_at(p)?;
        Ok(if equations(&rod, self.level).differentiates(&t) {
            DerivativeMethod::Exact
        } else {
            DerivativeMethod::CentralDifference
        })
    }

    /// F_p by a central difference with h = 1e-4 max(1, |p|): two extra
    /// integrations and an O(h²) ≈ 1e-8 relative truncation error, which
    /// shifts tangents and hence located folds by as much. The fallback
    /// of [`Family::parameter_derivative`].
    pub fn central_difference(&self, x: &[f64], p: f64) -> Result<DVector<f64>, PointError> {
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
        let samples = sys.sample_interpolated(&self.unscaled(x), points)?.0;
        // One sample per point, or the callers' pairing of samples with
        // points (quadrature and shape points) would go silently wrong.
        if samples.len() != points.len() {
            return Err(PointError::Sampling {
                p,
                asked: points.len(),
                served: samples.len(),
            });
        }
        Ok(samples)
    }

    /// The tip sample (position, directors) at (x, p).
    pub fn tip(&self, x: &[f64], p: f64) -> Result<RodSample, PointError> {
        let l = self.rod_at(p)?.length();
        Ok(self.samples(x, p, &[l])?.remove(0))
    }
}

/// How a family computes F_p ([`Family::derivative_method`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DerivativeMethod {
    /// By the sensitivity equations: exact up to the integration
    /// tolerance (shooting) or to rounding (collocation).
    Exact,
    /// By a central difference in p (h = 1e-4 max(1, |p|)): an O(h²)
    /// truncation error.
    CentralDifference,
}

impl std::fmt::Display for DerivativeMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            DerivativeMethod::Exact => "exact (sensitivity equations)",
            DerivativeMethod::CentralDifference => "central difference in p",
        })
    }
}

/// Why unknowns of one family cannot start another ([`Family::carried`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CarryError {
    /// The unknowns are not of the family they are said to be of.
    #[error(
        "the stored point has {found} unknowns, its own problem's discretization {expected}: \
         the file's problem does not describe its points"
    )]
    Size {
        /// Unknowns found.
        found: usize,
        /// Unknowns of the stored family.
        expected: usize,
    },
    /// Another state layout: no node state carries over.
    #[error(
        "the stored point is of the {from}, this continuation of the {to}; set solver.model \
         (and the support) as the stored problem had them"
    )]
    Layout {
        /// The stored family's model and state size.
        from: String,
        /// This family's.
        to: String,
    },
    /// The stored solution could not be integrated onto the new nodes.
    #[error("carrying the stored point onto this mesh: {0}")]
    Point(#[from] PointError),
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
    /// The tracked second variation's mesh does not resolve the shape: the
    /// material frame turns more than
    /// [`crate::stability::MAX_TURN_PER_ELEMENT`] across an element, where
    /// eigenvalues of two such meshes agree and are both wrong.
    #[error(
        "at p = {p} the material frame turns {turn:.2} rad across one element of the tracked \
         second variation: its eigenvalues decide nothing there; set continuation.elements to \
         at least {elements}"
    )]
    Unresolved {
        /// The parameter value.
        p: f64,
        /// The largest turn per element (rad).
        turn: f64,
        /// Elements that would resolve it.
        elements: f64,
    },
    /// The discretization served fewer samples than asked (a point
    /// outside the rod): never paired off silently.
    #[error("at p = {p}: {asked} sample points asked, {served} served (a point outside [0, L])")]
    Sampling {
        /// The parameter value.
        p: f64,
        /// Points asked for.
        asked: usize,
        /// Samples served.
        served: usize,
    },
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
