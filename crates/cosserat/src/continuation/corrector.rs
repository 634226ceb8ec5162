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

use super::engine::{self, ContinuationProblem, Jacobian, StepFailure};
use super::{Family, Point, PointError, Run};
use crate::numerics::dense::DenseLu;
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
pub(crate) const DENSE_UP_TO: usize = 200;

/// F_x at a point in the shape of the family's discretization: dense for
/// single shooting and small systems, almost block diagonal
/// ([`Staircase`]) for multiple shooting and collocation beyond
/// 200 unknowns (`DENSE_UP_TO`), so that every step costs O(N) there.
#[derive(Debug, Clone)]
pub enum Linearization {
    /// The small dense F_x of single shooting or of a coarse mesh.
    Dense(DMatrix<f64>),
    /// The block-banded F_x of K > 1 segments or intervals.
    Staircase(Staircase),
}

impl Linearization {
    /// The zero F_x of the family's shape: a staircase above
    /// [`DENSE_UP_TO`] unknowns, dense below.
    pub(super) fn of(family: &Family) -> Self {
        if let Some(a) = family.staircase().filter(|a| a.size() > DENSE_UP_TO) {
            Linearization::Staircase(a)
        } else {
            let n = family.size();
            Linearization::Dense(DMatrix::zeros(n, n))
        }
    }

    /// F(x, p) into `r` and F_x into self.
    pub(super) fn evaluate(
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

    /// F_x d.
    pub(super) fn mul(&self, d: &DVector<f64>) -> DVector<f64> {
        match self {
            Linearization::Dense(fx) => fx * d,
            Linearization::Staircase(a) => {
                let mut y = DVector::zeros(d.len());
                a.mul(d.as_slice(), y.as_mut_slice());
                y
            }
        }
    }

    /// F_xᵀ w.
    pub(super) fn mul_transposed(&self, w: &DVector<f64>) -> DVector<f64> {
        match self {
            Linearization::Dense(fx) => fx.tr_mul(w),
            Linearization::Staircase(a) => {
                let mut y = DVector::zeros(w.len());
                a.mul_transposed(w.as_slice(), y.as_mut_slice());
                y
            }
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

/// The factorizations of the rod's F_x: plain (Newton at a fixed p) and
/// bordered (the corrector and the tangent).
#[derive(Debug, Default)]
pub struct RodFactors {
    dense: DenseLu,
    banded: StaircaseLu,
    bordered: BorderedFactors,
}

impl Jacobian for Linearization {
    type Factors = RodFactors;

    fn factor(&self, factors: &mut RodFactors) -> bool {
        match self {
            Linearization::Dense(fx) => {
                factors.dense.factor(fx);
                true
            }
            Linearization::Staircase(a) => factors.banded.factor(a, None).is_ok(),
        }
    }

    fn newton_step(&self, factors: &mut RodFactors, f: &[f64], delta: &mut [f64]) -> bool {
        match self {
            Linearization::Dense(_) => factors.dense.newton_step(f, delta),
            Linearization::Staircase(_) => {
                delta.iter_mut().zip(f).for_each(|(d, v)| *d = -v);
                factors.banded.solve(delta)
            }
        }
    }

    fn factor_bordered(&self, factors: &mut RodFactors, border: &Border) {
        factors
            .bordered
            .factor(self, border.column, border.row, border.corner);
    }

    fn solve_bordered(
        &self,
        factors: &mut RodFactors,
        border: &Border,
        rhs: &[f64],
        z: &mut [f64],
    ) -> bool {
        factors
            .bordered
            .solve(self, border.column, border.row, border.corner, rhs, z)
    }
}

/// The rod as the engine sees it: F(x, p) of the family's discretization
/// (shooting, multiple shooting, fixed-mesh collocation) with its exact
/// F_x in the shape of [`Linearization`] and F_p from
/// [`Family::parameter_derivative`].
impl ContinuationProblem for Family {
    type Error = PointError;
    type Jacobian = Linearization;

    fn size(&self) -> usize {
        Family::size(self)
    }

    fn jacobian(&self) -> Linearization {
        Linearization::of(self)
    }

    fn evaluate(
        &self,
        x: &[f64],
        p: f64,
        r: &mut DVector<f64>,
        fx: &mut Linearization,
    ) -> Result<(), PointError> {
        fx.evaluate(self, x, p, r)
    }

    fn parameter_derivative(&self, x: &[f64], p: f64) -> Result<DVector<f64>, PointError> {
        Family::parameter_derivative(self, x, p)
    }
}

impl From<StepFailure<PointError>> for PointError {
    fn from(failure: StepFailure<PointError>) -> Self {
        match failure {
            StepFailure::Problem(e) => e,
            StepFailure::NoConvergence(p) => PointError::NoConvergence(p),
            StepFailure::SingularTangent(p) => PointError::SingularTangent(p),
        }
    }
}

/// A converged corrector: (x, p), its iterations and F_x there.
pub(super) type Corrected = engine::Corrected<Linearization>;

/// A corrected step: unknowns, parameter, tangent, corrector iterations.
pub(super) type Stepped = engine::Stepped;

impl Run<'_> {
    /// Newton in x at fixed p (the start point of a branch, or a step
    /// pulled back onto a bound): the engine's
    /// [`engine::newton_at_fixed_p`], at most 29 plain Newton steps from a
    /// guess already close.
    pub(super) fn newton_at_fixed_p(&self, x: Vec<f64>, p: f64) -> Result<Vec<f64>, PointError> {
        Ok(engine::newton_at_fixed_p(
            self.family,
            x,
            p,
            self.opts.tolerance,
        )?)
    }

    /// The unit tangent at (x, p): the null vector of [F_x F_p], oriented
    /// along `previous`.
    pub(super) fn tangent(
        &self,
        x: &[f64],
        p: f64,
        previous: &[f64],
    ) -> Result<Vec<f64>, PointError> {
        Ok(engine::tangent(self.family, x, p, previous)?)
    }

    /// Newton on the bordered pseudo-arclength system from the predictor
    /// (the engine's [`engine::correct`]); None where it does not converge
    /// (the caller halves the step).
    pub(super) fn correct(
        &self,
        pred: &[f64],
        tangent: &[f64],
    ) -> Result<Option<Corrected>, PointError> {
        engine::correct(self.family, pred, tangent, self.opts.tolerance)
    }

    /// Corrector from `from` along its tangent (times `sign`) by `ds`.
    pub(super) fn step(
        &self,
        from: &Point,
        sign: f64,
        ds: f64,
    ) -> Result<Option<Stepped>, PointError> {
        self.step_after(None, from, sign, ds)
    }

    /// [`Run::step`], Newton started from the parabola through `before`
    /// (the branch's point before `from`) where there is one
    /// ([`engine::step_after`]): the same plane, so the same point to the
    /// Newton tolerance. Should that corrector fail, the step from the
    /// tangent predictor decides, so that a step fails only where it did
    /// without the parabola.
    pub(super) fn step_after(
        &self,
        before: Option<&Point>,
        from: &Point,
        sign: f64,
        ds: f64,
    ) -> Result<Option<Stepped>, PointError> {
        if before.is_some() {
            if let Ok(Some(stepped)) = self.step_from(before, from, sign, ds) {
                return Ok(Some(stepped));
            }
        }
        self.step_from(None, from, sign, ds)
    }

    /// The step of [`Run::step_after`] from one start.
    fn step_from(
        &self,
        before: Option<&Point>,
        from: &Point,
        sign: f64,
        ds: f64,
    ) -> Result<Option<Stepped>, PointError> {
        let t: Vec<f64> = from.tangent.iter().map(|v| v * sign).collect();
        // A branch of symmetric copies keeps a null vector of F_x: step in
        // the slice through the last point (`slice.rs`).
        let kernel = if self.sliced {
            self.symmetric_kernel(&from.unknowns, from.parameter)
        } else {
            None
        };
        if let Some(kernel) = kernel {
            let pred: Vec<f64> = from
                .unknowns
                .iter()
                .chain([&from.parameter])
                .zip(&t)
                .map(|(a, b)| a + ds * b)
                .collect();
            let Some((z, iterations)) = self.correct_sliced(&from.unknowns, &pred, &t, &kernel)?
            else {
                return Ok(None);
            };
            let n = z.len() - 1;
            let tangent = self.sliced_tangent(&z[..n], z[n], &kernel, &t)?;
            let stored: Vec<f64> = tangent.iter().map(|v| v * sign).collect();
            return Ok(Some((z[..n].to_vec(), z[n], stored, iterations)));
        }
        let before: Option<Vec<f64>> =
            before.map(|b| b.unknowns.iter().copied().chain([b.parameter]).collect());
        let Some((x, p, tangent, iterations)) = engine::step_after(
            self.family,
            before.as_deref(),
            &from.unknowns,
            from.parameter,
            &t,
            ds,
            self.opts.tolerance,
        )?
        else {
            return Ok(None);
        };
        // Keep the stored tangent oriented along the travel direction.
        let stored: Vec<f64> = tangent.iter().map(|v| v * sign).collect();
        Ok(Some((x, p, stored, iterations)))
    }
}
