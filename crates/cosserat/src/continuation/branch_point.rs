//! Simple branch points located by Newton on a minimally augmented system
//! (Govaerts, *Numerical Methods for Bifurcations of Dynamical
//! Equilibria*, SIAM 2000, Sec. 4.3; the bordered form of Moore's system,
//! Moore 1980, as BifurcationKit.jl's `newton_bp`), after the singularity
//! of F_x is bracketed on det F_x and narrowed by regula falsi.
//!
//! At a simple branch point (x*, p*) F_x has a one-dimensional kernel φ
//! and cokernel ψ, and F_p lies in the range of F_x (ψᵀF_p = 0): the null
//! space of [F_x F_p] is a plane, and the bordered pseudo-arclength
//! corrector is singular there. A root of det F_x sampled along the
//! branch is therefore found only to the scatter of the corrected points
//! (ill-determined along the crossing branch) — the full bistable strip's
//! asymmetric branch point stalled at ±4e-10. Newton in z = (x, p, μ) on
//! the n + 2 equations
//!
//!   F(x, p) + μ b = 0,   g(x, p) = 0,   h(x, p) = wᵀF_p(x, p) = 0,
//!
//!   [F_x b; cᵀ 0] [v; g] = [0; 1],   [F_xᵀ c; bᵀ 0] [w; g] = [0; 1],
//!
//! with b, c the approximate left and right null vectors of F_x at the
//! bracketed point (fixed), converges quadratically to the branch point
//! itself: g = 0 makes F_x singular with w its left null vector, h = 0
//! puts F_p in its range, and the unfolding μ (zero at the solution)
//! supplies the direction the singular F_x lacks. The Jacobian
//!
//!   [F_x F_p b; g_x g_p 0; h_x h_p 0]
//!
//! is regular at a nondegenerate simple branch point: a null vector has
//! μ-part 0 (multiply the first row by wᵀ, wᵀb = 1), so its (x, p)-part
//! lies in the null plane of [F_x F_p], where the rows of g and h form
//! the Hessian of the algebraic bifurcation equation, regular exactly
//! when the two branches cross transversally (for a pitchfork its
//! diagonal entry ψᵀF_xx[φ, φ] vanishes and the off-diagonal one does
//! not).
//!
//! Gradients (differentiate the bordered systems, multiply by wᵀ):
//!
//!   g_z = −wᵀ F_xz v,
//!   h_z = wᵀ F_xz v₀ + wᵀ F_pz,   [F_x b; cᵀ 0] [v₀; s] = [−F_p; 0],
//!
//! (h_z in this form is exact where h = 0, which is all Newton's rate
//! needs), the second derivatives by central differences of the exact
//! F_x and F_p along v, v₀ and p. They steer Newton only: the equations it
//! solves — and so the located point — are exact to the corrector's
//! tolerance. Dense, once per branch point, up to
//! [`super::fold::FOLD_DENSE_UP_TO`] unknowns, as for folds.

use nalgebra::{DMatrix, DVector};

use super::fold::{bordered, null_vectors, FOLD_DENSE_UP_TO};
use super::Run;

/// Newton iterations before the augmented system is given up.
const MAX_ITERATIONS: usize = 12;

/// A branch point located on the augmented system: the unknowns, the
/// parameter and the Newton iterations it took.
pub(super) type Located = (Vec<f64>, f64, usize);

/// The pieces of the augmented system at one iterate.
struct Augmented {
    residual: DVector<f64>,
    jacobian: DMatrix<f64>,
}

impl Run<'_> {
    /// The simple branch point near the bracketed point (x₀, p₀), by
    /// Newton on the minimally augmented system; `radius` bounds how far
    /// (in (x, p)) Newton may go from it. Converged when ‖F‖∞ and |μ|‖b‖∞
    /// are within the corrector's tolerance, |g| and |h| within it times
    /// their gradients' norms (distances in z), and the last correction of
    /// p within the event tolerance relative to max(|p|, 1). Err says why
    /// not.
    pub(super) fn refine_branch_point(
        &self,
        x0: &[f64],
        p0: f64,
        radius: f64,
    ) -> Result<Located, String> {
        let n = x0.len();
        if n > FOLD_DENSE_UP_TO {
            return Err(format!(
                "{n} unknowns: the augmented system is solved dense up to {FOLD_DENSE_UP_TO}"
            ));
        }
        let fx0 = self.dense_jacobian(x0, p0).map_err(|e| e.to_string())?.1;
        let (c, b) = null_vectors(&fx0).ok_or("F_x: no null vectors by inverse iteration")?;
        let mut z = DVector::from_iterator(n + 2, x0.iter().copied().chain([p0, 0.0]));
        let start = z.rows(0, n + 1).into_owned();
        for iteration in 1..=MAX_ITERATIONS {
            let here = self.branch_system(&z, &b, &c)?;
            let dz = here
                .jacobian
                .lu()
                .solve(&here.residual)
                .filter(|d| d.iter().all(|v| v.is_finite()))
                .ok_or("the augmented Jacobian is singular (not a simple branch point)")?;
            z -= &dz;
            if (z.rows(0, n + 1) - &start).norm() > radius {
                return Err(format!(
                    "Newton left the step (|Δz| > {radius:.3e}) at iteration {iteration}"
                ));
            }
            let p = z[n];
            let tol_p = self.opts.event_tolerance * p.abs().max(1.0);
            if dz[n].abs() <= tol_p {
                let at = self.branch_system(&z, &b, &c)?;
                if self.branch_converged(&at, z[n + 1] * b.amax()) {
                    return Ok((z.rows(0, n).iter().copied().collect(), p, iteration));
                }
            }
        }
        Err(format!(
            "Newton did not converge in {MAX_ITERATIONS} iterations"
        ))
    }

    /// ‖F + μb‖∞ ≤ τ, |μ|‖b‖∞ ≤ τ, |g| ≤ τ |∇g| and |h| ≤ τ |∇h|.
    fn branch_converged(&self, at: &Augmented, unfolding: f64) -> bool {
        let n = at.residual.len() - 2;
        let tol = self.opts.tolerance;
        let r = &at.residual;
        r.rows(0, n).amax() <= tol
            && unfolding.abs() <= tol
            && r[n].abs() <= tol * at.jacobian.row(n).norm()
            && r[n + 1].abs() <= tol * at.jacobian.row(n + 1).norm()
    }

    /// The residual (F + μb, g, h) at z = (x, p, μ) and its Jacobian.
    fn branch_system(
        &self,
        z: &DVector<f64>,
        b: &DVector<f64>,
        c: &DVector<f64>,
    ) -> Result<Augmented, String> {
        let n = z.len() - 2;
        let (x, p, mu) = (z.as_slice()[..n].to_vec(), z[n], z[n + 1]);
        let fail = |e: super::PointError| e.to_string();
        let (f, fx) = self.dense_jacobian(&x, p).map_err(fail)?;
        let fp = self.family.parameter_derivative(&x, p).map_err(fail)?;
        let singular = "the bordered matrix [F_x b; cᵀ 0] is singular";
        let (g, v) = bordered(&fx, b, c).ok_or(singular)?;
        let (_, w) = bordered(&fx.transpose(), c, b).ok_or(singular)?;
        let v0 = bordered_solve(&fx, b, c, &(-&fp)).ok_or(singular)?;
        // Directional differences of F_x along v and v₀, and of F_x, F_p in p.
        let along = |d: &DVector<f64>| -> Result<DMatrix<f64>, String> {
            if d.amax() == 0.0 {
                // F_x does not move along a zero direction (v₀ = 0 where
                // F_p = 0, e.g. a straight column in its load).
                return Ok(DMatrix::zeros(n, n));
            }
            let eps = 1e-6 * x.iter().fold(1.0f64, |m, v| m.max(v.abs())) / d.amax();
            let shifted = |sign: f64| -> Vec<f64> {
                x.iter()
                    .zip(d.iter())
                    .map(|(a, e)| a + sign * eps * e)
                    .collect()
            };
            let up = self.dense_jacobian(&shifted(1.0), p).map_err(fail)?.1;
            let down = self.dense_jacobian(&shifted(-1.0), p).map_err(fail)?.1;
            Ok((up - down) / (2.0 * eps))
        };
        let fxx_v = along(&v)?;
        let fxx_v0 = along(&v0)?;
        let h = 1e-6 * p.abs().max(1.0);
        let fxp = (self.dense_jacobian(&x, p + h).map_err(fail)?.1
            - self.dense_jacobian(&x, p - h).map_err(fail)?.1)
            / (2.0 * h);
        let fpp = (self.family.parameter_derivative(&x, p + h).map_err(fail)?
            - self.family.parameter_derivative(&x, p - h).map_err(fail)?)
            / (2.0 * h);
        let wt = w.transpose();
        let gx = -(&wt * &fxx_v);
        let gp = -w.dot(&(&fxp * &v));
        let hx = &wt * &fxx_v0 + &wt * &fxp;
        let hp = w.dot(&(&fxp * &v0)) + w.dot(&fpp);
        let mut jacobian = DMatrix::zeros(n + 2, n + 2);
        jacobian.view_mut((0, 0), (n, n)).copy_from(&fx);
        jacobian.view_mut((0, n), (n, 1)).copy_from(&fp);
        jacobian.view_mut((0, n + 1), (n, 1)).copy_from(b);
        jacobian.view_mut((n, 0), (1, n)).copy_from(&gx);
        jacobian[(n, n)] = gp;
        jacobian.view_mut((n + 1, 0), (1, n)).copy_from(&hx);
        jacobian[(n + 1, n)] = hp;
        let mut residual = DVector::zeros(n + 2);
        residual.rows_mut(0, n).copy_from(&(f + b * mu));
        residual[n] = g;
        residual[n + 1] = w.dot(&fp);
        Ok(Augmented { residual, jacobian })
    }
}

/// The x-part of [A column; rowᵀ 0] [y; s] = [rhs; 0]: the solution of
/// A y = rhs in the complement of the (near) kernel of A, whatever A's
/// (near) singularity.
pub(super) fn bordered_solve(
    matrix: &DMatrix<f64>,
    column: &DVector<f64>,
    row: &DVector<f64>,
    rhs: &DVector<f64>,
) -> Option<DVector<f64>> {
    let n = matrix.nrows();
    let mut m = DMatrix::zeros(n + 1, n + 1);
    m.view_mut((0, 0), (n, n)).copy_from(matrix);
    m.view_mut((0, n), (n, 1)).copy_from(column);
    m.view_mut((n, 0), (1, n)).copy_from(&row.transpose());
    let mut full = DVector::zeros(n + 1);
    full.rows_mut(0, n).copy_from(rhs);
    m.lu()
        .solve(&full)
        .filter(|s| s.iter().all(|v| v.is_finite()))
        .map(|s| s.rows(0, n).into_owned())
}
