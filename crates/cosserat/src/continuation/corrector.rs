//! One predictor–corrector step of pseudo-arclength continuation (Keller
//! 1977): from a point z₀ = (x₀, p₀) with unit tangent τ₀ = (ẋ₀, ṗ₀), the
//! predictor z_pred = z₀ + Δs τ₀, then Newton ([`crate::numerics::newton`])
//! on the bordered system
//!
//!   F(x, p) = 0,   ⟨x − x₀, ẋ₀⟩ + (p − p₀)ṗ₀ − Δs = 0,
//!
//! whose Jacobian [F_x F_p; τ₀ᵀ] stays regular at a fold, where F_x alone
//! is singular. The new tangent is the null vector of [F_x F_p] oriented
//! along τ₀. Newton at a fixed p starts branches and lands them on bounds.

use nalgebra::{DMatrix, DVector};

use super::{Family, Point, PointError, Run};
use crate::numerics::newton::{self, Damping, NewtonError, Options, System};

/// Solves the bordered system by LU, or — where it is singular, exactly at
/// a branch point — by the truncated SVD (the minimum-norm correction).
fn bordered_solve(a: DMatrix<f64>, rhs: &DVector<f64>) -> Option<DVector<f64>> {
    let finite = |v: &DVector<f64>| v.iter().all(|x| x.is_finite());
    if let Some(x) = a.clone().lu().solve(rhs).filter(finite) {
        let scale = a.amax().max(f64::MIN_POSITIVE);
        if x.amax() * scale < 1e12 * rhs.amax().max(f64::MIN_POSITIVE) {
            return Some(x);
        }
    }
    let svd = a.svd(true, true);
    let tol = 1e-12 * svd.singular_values.max();
    svd.solve(rhs, tol).ok().filter(finite)
}

/// F(x, p) = 0 in x at a fixed parameter value p, for
/// [`crate::numerics::newton`]: the family's residual and F_x, solved by
/// dense LU.
struct FixedParameter<'a> {
    family: &'a Family,
    p: f64,
    r: DVector<f64>,
    fx: DMatrix<f64>,
    lu: crate::numerics::dense::DenseLu,
}

impl<'a> FixedParameter<'a> {
    fn new(family: &'a Family, p: f64, n: usize) -> Self {
        FixedParameter {
            family,
            p,
            r: DVector::zeros(n),
            fx: DMatrix::zeros(n, n),
            lu: crate::numerics::dense::DenseLu::default(),
        }
    }
}

impl System for FixedParameter<'_> {
    type Error = PointError;

    fn size(&self) -> usize {
        self.r.len()
    }

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), PointError> {
        self.family.residual(x, self.p, &mut self.r, &mut self.fx)?;
        r.copy_from_slice(self.r.as_slice());
        Ok(())
    }

    fn linearize(&mut self, _x: &[f64]) -> bool {
        self.lu.factor(&self.fx);
        true
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        self.lu.newton_step(f, delta)
    }
}

/// The bordered system of a pseudo-arclength corrector in z = (x, p),
///
///   F(x, p) = 0,   ⟨z − z_pred, τ⟩ = 0,
///
/// with z_pred = z₀ + Δs τ the predictor along the unit tangent τ at z₀,
/// so that the second row is Keller's (1977) arclength constraint
/// ⟨x − x₀, ẋ₀⟩ + (p − p₀)ṗ₀ − Δs = 0. Its Jacobian is the bordered matrix
/// [F_x F_p; τᵀ], regular at folds where F_x alone is singular, with F_p
/// taken once at the predictor (a chord in the parameter column). The
/// constraint row is linear, so one step satisfies it to round-off; it is
/// measured against an absolute 1e-13 (its residual scale is 1e-13/τ).
struct PseudoArclength<'a> {
    family: &'a Family,
    pred: &'a [f64],
    tangent: &'a [f64],
    fp: DVector<f64>,
    tolerance: f64,
    r: DVector<f64>,
    /// F_x at the last evaluated point (the corrected one on success).
    fx: DMatrix<f64>,
    bordered: DMatrix<f64>,
}

impl<'a> PseudoArclength<'a> {
    fn new(
        family: &'a Family,
        pred: &'a [f64],
        tangent: &'a [f64],
        fp: DVector<f64>,
        tolerance: f64,
    ) -> Self {
        let n = pred.len() - 1;
        PseudoArclength {
            family,
            pred,
            tangent,
            fp,
            tolerance,
            r: DVector::zeros(n),
            fx: DMatrix::zeros(n, n),
            bordered: DMatrix::zeros(n + 1, n + 1),
        }
    }
}

impl System for PseudoArclength<'_> {
    type Error = PointError;

    fn size(&self) -> usize {
        self.pred.len()
    }

    fn residual(&mut self, z: &[f64], r: &mut [f64]) -> Result<(), PointError> {
        let n = self.r.len();
        self.family
            .residual(&z[..n], z[n], &mut self.r, &mut self.fx)?;
        let arc: f64 = self
            .tangent
            .iter()
            .zip(z.iter().zip(self.pred))
            .map(|(t, (a, b))| t * (a - b))
            .sum();
        r[..n].copy_from_slice(self.r.as_slice());
        r[n] = arc;
        Ok(())
    }

    fn linearize(&mut self, _z: &[f64]) -> bool {
        let n = self.r.len();
        let a = &mut self.bordered;
        a.view_mut((0, 0), (n, n)).copy_from(&self.fx);
        a.view_mut((0, n), (n, 1)).copy_from(&self.fp);
        for (k, v) in self.tangent.iter().enumerate() {
            a[(n, k)] = *v;
        }
        true
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        let rhs = -DVector::from_column_slice(f);
        match bordered_solve(self.bordered.clone(), &rhs) {
            Some(d) => {
                delta.copy_from_slice(d.as_slice());
                true
            }
            None => false,
        }
    }

    fn residual_scales(&self) -> Vec<f64> {
        let mut scales = vec![1.0; self.size()];
        scales[self.r.len()] = ARC_TOLERANCE / self.tolerance;
        scales
    }
}

/// The absolute tolerance on the arclength constraint of the corrector.
const ARC_TOLERANCE: f64 = 1e-13;

/// A converged corrector: (x, p), its iterations and F_x there.
pub(super) type Corrected = (Vec<f64>, usize, DMatrix<f64>);

/// A corrected step: unknowns, parameter, tangent, corrector iterations.
pub(super) type Stepped = (Vec<f64>, f64, Vec<f64>, usize);

impl Run<'_> {
    /// Newton in x at fixed p (the start point of a branch, or a step
    /// pulled back onto a bound): plain Newton steps ([`Damping::Full`]),
    /// at most 29 of them (30 tests, as the loop this replaced), from a
    /// guess already close.
    pub(super) fn newton_at_fixed_p(
        &self,
        mut x: Vec<f64>,
        p: f64,
    ) -> Result<Vec<f64>, PointError> {
        let mut system = FixedParameter::new(self.family, p, x.len());
        let opts = Options {
            tolerance: self.opts.tolerance,
            max_iterations: 29,
            damping: Damping::Full,
        };
        match newton::solve(&mut system, &mut x, &opts) {
            Ok(_) => Ok(x),
            Err(NewtonError::BadStart(e) | NewtonError::Evaluation { error: e, .. }) => Err(e),
            Err(_) => Err(PointError::NoConvergence(p)),
        }
    }

    /// The unit tangent at (x, p): the null vector of [F_x F_p], oriented
    /// along `previous`.
    pub(super) fn tangent(
        &self,
        x: &[f64],
        p: f64,
        previous: &[f64],
    ) -> Result<Vec<f64>, PointError> {
        let n = x.len();
        let (mut r, mut fx) = (DVector::zeros(n), DMatrix::zeros(n, n));
        self.family.residual(x, p, &mut r, &mut fx)?;
        self.tangent_from(&fx, x, p, previous)
    }

    /// The tangent with F_x already known at (x, p).
    pub(super) fn tangent_from(
        &self,
        fx: &DMatrix<f64>,
        x: &[f64],
        p: f64,
        previous: &[f64],
    ) -> Result<Vec<f64>, PointError> {
        let n = x.len();
        let fp = self.family.parameter_derivative(x, p)?;
        let mut a = DMatrix::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n)).copy_from(fx);
        a.view_mut((0, n), (n, 1)).copy_from(&fp);
        for (k, v) in previous.iter().enumerate() {
            a[(n, k)] = *v;
        }
        let mut rhs = DVector::zeros(n + 1);
        rhs[n] = 1.0;
        let t = bordered_solve(a, &rhs)
            .filter(|t| t.iter().all(|v| v.is_finite()) && t.norm() > 0.0)
            .ok_or(PointError::SingularTangent(p))?;
        let t = t.normalize();
        Ok(t.as_slice().to_vec())
    }

    /// Newton on the bordered system F(x, p) = 0, τᵀ(z − z_pred) = 0 from
    /// the predictor z_pred ([`PseudoArclength`]): plain Newton steps, at
    /// most 9 (10 tests). No damping on purpose: a corrector that does not
    /// converge fast means the step was too long, and the caller halves
    /// the arclength step instead (`walk`), which keeps the points evenly
    /// spaced along the branch.
    pub(super) fn correct(
        &self,
        pred: &[f64],
        tangent: &[f64],
    ) -> Result<Option<Corrected>, PointError> {
        let n = pred.len() - 1;
        let fp = self.family.parameter_derivative(&pred[..n], pred[n])?;
        let mut system = PseudoArclength::new(self.family, pred, tangent, fp, self.opts.tolerance);
        let opts = Options {
            tolerance: self.opts.tolerance,
            max_iterations: 9,
            damping: Damping::Full,
        };
        let mut z = pred.to_vec();
        Ok(match newton::solve(&mut system, &mut z, &opts) {
            Ok(report) => Some((z, report.iterations, system.fx)),
            Err(_) => None,
        })
    }

    /// Corrector from `from` along its tangent (times `sign`) by `ds`.
    pub(super) fn step(
        &self,
        from: &Point,
        sign: f64,
        ds: f64,
    ) -> Result<Option<Stepped>, PointError> {
        let t: Vec<f64> = from.tangent.iter().map(|v| v * sign).collect();
        let mut z = from.unknowns.clone();
        z.push(from.parameter);
        let pred: Vec<f64> = z.iter().zip(&t).map(|(a, b)| a + ds * b).collect();
        let Some((z, iterations, fx)) = self.correct(&pred, &t)? else {
            return Ok(None);
        };
        let n = z.len() - 1;
        let tangent = self.tangent_from(&fx, &z[..n], z[n], &t)?;
        // Keep the stored tangent oriented along the travel direction.
        let stored: Vec<f64> = tangent.iter().map(|v| v * sign).collect();
        Ok(Some((z[..n].to_vec(), z[n], stored, iterations)))
    }
}
