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
//!
//! Every linear solve uses the structure of the discretization
//! ([`Linearization`]): single shooting's few unknowns by dense LU (the
//! truncated SVD at a singular bordered matrix); multiple shooting and
//! collocation, whose F_x is almost block diagonal, by band LU of F_x or of
//! the banded embedding of the bordered matrix
//! ([`crate::numerics::staircase`]), with its banded least squares at a
//! singular one — O(N) work and memory per step.

use nalgebra::{DMatrix, DVector};

use super::{Family, Point, PointError, Run};
use crate::numerics::dense::DenseLu;
use crate::numerics::newton::{self, Damping, NewtonError, Options, System};
use crate::numerics::staircase::{least_squares, Border, Staircase, StaircaseLu};

/// Solves the dense bordered system by LU, or — where it is singular,
/// exactly at a branch point — by the truncated SVD (the minimum-norm
/// correction). Single shooting only: its systems have a few unknowns.
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

/// The most unknowns solved dense. Below it a dense LU of the bordered
/// matrix costs about one evaluation of F, and small studies keep the
/// results of the dense solver with its truncated SVD bit for bit: the
/// arm's loading path (Sec. 4.4, 125 unknowns) runs its correctors at the
/// noise floor of the integrated residual near λ = 0.976, where round-off
/// in the solve decides whether a step converges (measured: accurate
/// staircase solves, residual 1e-26 against right-hand sides 1e-10, still
/// end that branch at λ = 0.9757 instead of 1).
pub(super) const DENSE_UP_TO: usize = 200;

/// F_x at a point in the shape of the family's discretization: dense for
/// single shooting and small systems, almost block diagonal
/// ([`Staircase`]) for multiple shooting and collocation beyond
/// [`DENSE_UP_TO`] unknowns, so that every step costs O(N) there.
#[derive(Debug, Clone)]
pub(super) enum Linearization {
    /// The small dense F_x of single shooting or of a coarse mesh.
    Dense(DMatrix<f64>),
    /// The block-banded F_x of K > 1 segments or intervals.
    Staircase(Staircase),
}

impl Linearization {
    /// The zero F_x of the family's shape: a staircase above
    /// [`DENSE_UP_TO`] unknowns, dense below.
    fn of(family: &Family) -> Self {
        if let Some(a) = family.staircase().filter(|a| a.size() > DENSE_UP_TO) {
            Linearization::Staircase(a)
        } else {
            let n = family.size();
            Linearization::Dense(DMatrix::zeros(n, n))
        }
    }

    /// F(x, p) into `r` and F_x into self.
    fn evaluate(
        &mut self,
        family: &Family,
        x: &[f64],
        p: f64,
        r: &mut DVector<f64>,
    ) -> Result<(), PointError> {
        match self {
            Linearization::Dense(fx) => family.residual(x, p, r, fx),
            Linearization::Staircase(a) => family.residual_staircase(x, p, r, a),
        }
    }
}

/// The bordered matrix [F_x column; rowᵀ corner] factored in the shape of
/// F_x, and its solves (the corrector's Newton steps and the tangent).
#[derive(Debug, Clone, Default)]
struct BorderedFactors {
    lu: StaircaseLu,
    factored: bool,
    dense: Option<DMatrix<f64>>,
}

impl BorderedFactors {
    /// Prepares the solves with [fx column; rowᵀ corner].
    fn factor(&mut self, fx: &Linearization, column: &[f64], row: &[f64], corner: f64) {
        match fx {
            Linearization::Dense(fx) => {
                let n = fx.nrows();
                let a = self
                    .dense
                    .get_or_insert_with(|| DMatrix::zeros(n + 1, n + 1));
                a.view_mut((0, 0), (n, n)).copy_from(fx);
                for k in 0..n {
                    a[(k, n)] = column[k];
                    a[(n, k)] = row[k];
                }
                a[(n, n)] = corner;
            }
            Linearization::Staircase(a) => {
                let border = Border {
                    column,
                    row,
                    corner,
                };
                self.factored = self.lu.factor(a, Some(&border)).is_ok();
            }
        }
    }

    /// The solution of the factored system for `rhs` (length N + 1) into
    /// `z`; the least-squares solution where the bordered matrix is
    /// singular (an exact branch point), false where none is finite.
    fn solve(
        &mut self,
        fx: &Linearization,
        column: &[f64],
        row: &[f64],
        corner: f64,
        rhs: &[f64],
        z: &mut [f64],
    ) -> bool {
        match fx {
            Linearization::Dense(_) => {
                let Some(a) = self.dense.clone() else {
                    return false;
                };
                match bordered_solve(a, &DVector::from_column_slice(rhs)) {
                    Some(d) => {
                        z.copy_from_slice(d.as_slice());
                        true
                    }
                    None => false,
                }
            }
            Linearization::Staircase(a) => {
                let border = Border {
                    column,
                    row,
                    corner,
                };
                if self.factored {
                    self.lu.solve_bordered(a, &border, rhs, z)
                } else {
                    match least_squares(a, &border, rhs).filter(|y| y.iter().all(|v| v.is_finite()))
                    {
                        Some(y) => {
                            z.copy_from_slice(&y);
                            true
                        }
                        None => false,
                    }
                }
            }
        }
    }
}

/// F(x, p) = 0 in x at a fixed parameter value p, for
/// [`crate::numerics::newton`]: the family's residual and F_x, solved by
/// dense LU (single shooting) or band LU of the staircase.
struct FixedParameter<'a> {
    family: &'a Family,
    p: f64,
    r: DVector<f64>,
    fx: Linearization,
    dense: DenseLu,
    banded: StaircaseLu,
}

impl<'a> FixedParameter<'a> {
    fn new(family: &'a Family, p: f64, n: usize) -> Self {
        FixedParameter {
            family,
            p,
            r: DVector::zeros(n),
            fx: Linearization::of(family),
            dense: DenseLu::default(),
            banded: StaircaseLu::default(),
        }
    }
}

impl System for FixedParameter<'_> {
    type Error = PointError;

    fn size(&self) -> usize {
        self.r.len()
    }

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), PointError> {
        self.fx.evaluate(self.family, x, self.p, &mut self.r)?;
        r.copy_from_slice(self.r.as_slice());
        Ok(())
    }

    fn linearize(&mut self, _x: &[f64]) -> bool {
        match &self.fx {
            Linearization::Dense(fx) => {
                self.dense.factor(fx);
                true
            }
            Linearization::Staircase(a) => self.banded.factor(a, None).is_ok(),
        }
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        match &self.fx {
            Linearization::Dense(_) => self.dense.newton_step(f, delta),
            Linearization::Staircase(_) => {
                delta.iter_mut().zip(f).for_each(|(d, v)| *d = -v);
                self.banded.solve(delta)
            }
        }
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
/// taken once at the predictor (a chord in the parameter column), when
/// the first Newton step linearizes there: an exact F_p then comes with
/// that evaluation's integration ([`Family::parameter_derivative`]). The
/// constraint row is linear, so one step satisfies it to round-off; it is
/// measured against an absolute 1e-13 (its residual scale is 1e-13/τ).
struct PseudoArclength<'a> {
    family: &'a Family,
    pred: &'a [f64],
    tangent: &'a [f64],
    /// F_p at the predictor, from the first linearization.
    fp: Option<DVector<f64>>,
    /// Why F_p could not be had (the corrector's error).
    failure: Option<PointError>,
    tolerance: f64,
    r: DVector<f64>,
    /// F_x at the last evaluated point (the corrected one on success).
    fx: Linearization,
    bordered: BorderedFactors,
    rhs: Vec<f64>,
}

impl<'a> PseudoArclength<'a> {
    fn new(family: &'a Family, pred: &'a [f64], tangent: &'a [f64], tolerance: f64) -> Self {
        let n = pred.len() - 1;
        PseudoArclength {
            family,
            pred,
            tangent,
            fp: None,
            failure: None,
            tolerance,
            r: DVector::zeros(n),
            fx: Linearization::of(family),
            bordered: BorderedFactors::default(),
            rhs: vec![0.0; n + 1],
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
        self.fx.evaluate(self.family, &z[..n], z[n], &mut self.r)?;
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

    fn linearize(&mut self, z: &[f64]) -> bool {
        let n = self.r.len();
        if self.fp.is_none() {
            match self.family.parameter_derivative(&z[..n], z[n]) {
                Ok(fp) => self.fp = Some(fp),
                Err(e) => {
                    self.failure = Some(e);
                    return false;
                }
            }
        }
        let Some(fp) = &self.fp else {
            return false;
        };
        let (row, corner) = self.tangent.split_at(n);
        self.bordered
            .factor(&self.fx, fp.as_slice(), row, corner[0]);
        true
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        let n = self.r.len();
        let Some(fp) = &self.fp else {
            return false;
        };
        self.rhs.iter_mut().zip(f).for_each(|(r, v)| *r = -v);
        let (row, corner) = self.tangent.split_at(n);
        self.bordered
            .solve(&self.fx, fp.as_slice(), row, corner[0], &self.rhs, delta)
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
pub(super) type Corrected = (Vec<f64>, usize, Linearization);

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
        let mut fx = Linearization::of(self.family);
        fx.evaluate(self.family, x, p, &mut DVector::zeros(x.len()))?;
        self.tangent_from(&fx, x, p, previous)
    }

    /// The tangent with F_x already known at (x, p): the solution of
    /// [F_x F_p; previousᵀ] t = (0, 1), normalized.
    pub(super) fn tangent_from(
        &self,
        fx: &Linearization,
        x: &[f64],
        p: f64,
        previous: &[f64],
    ) -> Result<Vec<f64>, PointError> {
        let n = x.len();
        let fp = self.family.parameter_derivative(x, p)?;
        let (row, corner) = previous.split_at(n);
        let mut rhs = vec![0.0; n + 1];
        rhs[n] = 1.0;
        let mut factors = BorderedFactors::default();
        factors.factor(fx, fp.as_slice(), row, corner[0]);
        let mut t = DVector::zeros(n + 1);
        let solved = factors.solve(fx, fp.as_slice(), row, corner[0], &rhs, t.as_mut_slice());
        if !solved || !t.iter().all(|v| v.is_finite()) || t.norm() == 0.0 {
            return Err(PointError::SingularTangent(p));
        }
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
        let mut system = PseudoArclength::new(self.family, pred, tangent, self.opts.tolerance);
        let opts = Options {
            tolerance: self.opts.tolerance,
            max_iterations: 9,
            damping: Damping::Full,
        };
        let mut z = pred.to_vec();
        let outcome = newton::solve(&mut system, &mut z, &opts);
        if let Some(e) = system.failure {
            return Err(e);
        }
        Ok(match outcome {
            Ok(report) => Some((z, report.iterations, system.fx)),
            // Not evaluable at the predictor: the error F_p there gave
            // before Newton started, as when it was taken first.
            Err(NewtonError::BadStart(e)) => return Err(e),
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
        // A branch of symmetric copies keeps a null vector of F_x: step in
        // the slice through the last point (`slice.rs`).
        let kernel = if self.sliced {
            self.symmetric_kernel(&from.unknowns, from.parameter)
        } else {
            None
        };
        if let Some(kernel) = kernel {
            let Some((z, iterations)) = self.correct_sliced(&from.unknowns, &pred, &t, &kernel)?
            else {
                return Ok(None);
            };
            let n = z.len() - 1;
            let tangent = self.sliced_tangent(&z[..n], z[n], &kernel, &t)?;
            let stored: Vec<f64> = tangent.iter().map(|v| v * sign).collect();
            return Ok(Some((z[..n].to_vec(), z[n], stored, iterations)));
        }
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
