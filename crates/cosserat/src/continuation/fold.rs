//! Fold location by Govaerts' minimally augmented system (Govaerts,
//! *Numerical Methods for Bifurcations of Dynamical Equilibria*, SIAM
//! 2000, Sec. 3.2; BifurcationKit.jl's `newtonFold`): after the fold is
//! bracketed on the sign of the tangent's parameter component τ_p and the
//! bracket narrowed by regula falsi, Newton in z = (x, p) on the n + 1
//! equations
//!
//!   F(x, p) = 0,   g(x, p) = 0,   [F_x b; cᵀ 0] [v; g] = [0; 1],
//!
//! with b, c the left and right null vectors of F_x at the bracketed point
//! by inverse iteration (fixed during the iteration). g vanishes
//! exactly where F_x is singular and is a regular equation at a simple
//! fold, so Newton converges quadratically to the fold itself — not to a
//! root of a test function sampled along the arclength. The gradient of g
//! is the adjoint formula
//!
//!   g_z = −wᵀ F_xz v,   [F_xᵀ c; bᵀ 0] [w; g] = [0; 1],
//!
//! (differentiate the bordered system and multiply by wᵀ), with the second
//! derivatives by central differences of the exact F_x: one directional
//! difference along v gives the whole row g_x (F_xx is symmetric in its
//! two arguments), one in p gives g_p. These steer Newton only; the
//! equations it solves, and so the located fold, are exact to the
//! corrector's tolerance. Dense, once per fold: used up to
//! [`FOLD_DENSE_UP_TO`] unknowns (multiple shooting and collocation
//! included); beyond, the bracketed root is kept and the record says so.

use nalgebra::{DMatrix, DVector};

use super::Run;

/// The most unknowns of a fold located on the augmented system: each
/// Newton iteration evaluates the dense F_x five times (at the point and
/// for the two difference quotients) and factors three (n + 1)² matrices
/// (the bordered system, its transpose, the Newton step), once per fold;
/// measured 0.25 s per fold at 381 unknowns (collocation, 64 intervals).
pub(crate) const FOLD_DENSE_UP_TO: usize = 1000;

/// Newton iterations before the augmented system is given up.
const MAX_ITERATIONS: usize = 12;

/// A fold located on the augmented system: the unknowns, the parameter and
/// the Newton iterations it took.
pub(super) type Fold = (Vec<f64>, f64, usize);

/// The bordered system's g and its vector (v or w) for `matrix` = F_x or
/// F_xᵀ with the borders (`column`, `row`): [A column; rowᵀ 0] [v; g] =
/// [0; 1]. None where the bordered matrix is singular (also the
/// singularity test of a curve of folds, [`super::codim2`]).
pub(super) fn bordered(
    matrix: &DMatrix<f64>,
    column: &DVector<f64>,
    row: &DVector<f64>,
) -> Option<(f64, DVector<f64>)> {
    let n = matrix.nrows();
    let mut m = DMatrix::zeros(n + 1, n + 1);
    m.view_mut((0, 0), (n, n)).copy_from(matrix);
    m.view_mut((0, n), (n, 1)).copy_from(column);
    m.view_mut((n, 0), (1, n)).copy_from(&row.transpose());
    let mut rhs = DVector::zeros(n + 1);
    rhs[n] = 1.0;
    let sol = m
        .lu()
        .solve(&rhs)
        .filter(|s| s.iter().all(|v| v.is_finite()))?;
    Some((sol[n], sol.rows(0, n).into_owned()))
}

/// Approximate right and left null vectors of a nearly singular F_x, by
/// two steps of inverse iteration on F_x and F_xᵀ from a fixed start
/// (one LU each; an SVD costs seconds at a thousand unknowns): the borders
/// need only complement the kernel and the range, and at a bracketed fold
/// F_x's smallest singular value is far below the next, so one step
/// already isolates the null vectors.
pub(super) fn null_vectors(fx: &DMatrix<f64>) -> Option<(DVector<f64>, DVector<f64>)> {
    let n = fx.nrows();
    let start = DVector::from_fn(n, |i, _| 1.0 + (0.618_033_988_75 * i as f64).fract());
    let (lu, lu_t) = (fx.clone().lu(), fx.transpose().lu());
    let (mut right, mut left) = (start.clone(), start);
    for _ in 0..2 {
        right = lu.solve(&right)?.normalize();
        left = lu_t.solve(&left)?.normalize();
    }
    let finite = |v: &DVector<f64>| v.iter().all(|x| x.is_finite());
    (finite(&right) && finite(&left)).then_some((right, left))
}

impl Run<'_> {
    /// The fold near the bracketed point (x₀, p₀), by Newton on the
    /// minimally augmented system; `radius` bounds how far (in z) Newton
    /// may go from it (the step's arclength: farther is another point).
    /// Converged when ‖F‖∞ is within the corrector's tolerance, |g| within
    /// it times |∇g| (a distance in z), and the last correction of p within
    /// the event tolerance relative to max(|p|, 1). Err says why not.
    pub(super) fn refine_fold(&self, x0: &[f64], p0: f64, radius: f64) -> Result<Fold, String> {
        let n = x0.len();
        if n > FOLD_DENSE_UP_TO {
            return Err(format!(
                "{n} unknowns: the augmented system is solved dense up to {FOLD_DENSE_UP_TO}"
            ));
        }
        let fx0 = self.dense_jacobian(x0, p0).map_err(|e| e.to_string())?.1;
        let (c, b) = null_vectors(&fx0).ok_or("F_x: no null vectors by inverse iteration")?;
        let mut z = DVector::from_iterator(n + 1, x0.iter().copied().chain([p0]));
        let start = z.clone();
        for iteration in 1..=MAX_ITERATIONS {
            let (residual, jacobian) = self.augmented(&z, &b, &c)?;
            let dz = jacobian
                .lu()
                .solve(&residual)
                .filter(|d| d.iter().all(|v| v.is_finite()))
                .ok_or("the augmented Jacobian is singular (not a simple fold)")?;
            z -= &dz;
            if (&z - &start).norm() > radius {
                return Err(format!(
                    "Newton left the step (|Δz| > {radius:.3e}) at iteration {iteration}"
                ));
            }
            let p = z[n];
            let tol_p = self.opts.event_tolerance * p.abs().max(1.0);
            if dz[n].abs() <= tol_p {
                let (r, j) = self.augmented(&z, &b, &c)?;
                if self.fold_converged(&r, &j) {
                    return Ok((z.rows(0, n).iter().copied().collect(), p, iteration));
                }
            }
        }
        Err(format!(
            "Newton did not converge in {MAX_ITERATIONS} iterations"
        ))
    }

    /// ‖F‖∞ ≤ τ and |g| ≤ τ |∇g|.
    fn fold_converged(&self, r: &DVector<f64>, j: &DMatrix<f64>) -> bool {
        let n = r.len() - 1;
        let tol = self.opts.tolerance;
        r.rows(0, n).amax() <= tol && r[n].abs() <= tol * j.row(n).norm()
    }

    /// The residual (F, g) at z = (x, p) and its Jacobian [F_x F_p; g_x g_p].
    fn augmented(
        &self,
        z: &DVector<f64>,
        b: &DVector<f64>,
        c: &DVector<f64>,
    ) -> Result<(DVector<f64>, DMatrix<f64>), String> {
        let n = z.len() - 1;
        let (x, p) = (z.as_slice()[..n].to_vec(), z[n]);
        let fail = |e: super::PointError| e.to_string();
        let (f, fx) = self.dense_jacobian(&x, p).map_err(fail)?;
        let singular = "the bordered matrix [F_x b; cᵀ 0] is singular";
        let (g, v) = bordered(&fx, b, c).ok_or(singular)?;
        let (_, w) = bordered(&fx.transpose(), c, b).ok_or(singular)?;
        let fp = self.family.parameter_derivative(&x, p).map_err(fail)?;
        // g_x = −wᵀ (∂/∂ε F_x(x + εv)), g_p = −wᵀ (∂/∂p F_x) v.
        let eps = 1e-6 * x.iter().fold(1.0f64, |m, v| m.max(v.abs())) / v.amax();
        let shifted =
            |sign: f64| -> Vec<f64> { x.iter().zip(&v).map(|(a, d)| a + sign * eps * d).collect() };
        let up = self.dense_jacobian(&shifted(1.0), p).map_err(fail)?.1;
        let down = self.dense_jacobian(&shifted(-1.0), p).map_err(fail)?.1;
        let gx = -(w.transpose() * (up - down)) / (2.0 * eps);
        let h = 1e-6 * p.abs().max(1.0);
        let up = self.dense_jacobian(&x, p + h).map_err(fail)?.1;
        let down = self.dense_jacobian(&x, p - h).map_err(fail)?.1;
        let gp = -w.dot(&((up - down) * &v)) / (2.0 * h);
        let mut jacobian = DMatrix::zeros(n + 1, n + 1);
        jacobian.view_mut((0, 0), (n, n)).copy_from(&fx);
        jacobian.view_mut((0, n), (n, 1)).copy_from(&fp);
        jacobian.view_mut((n, 0), (1, n)).copy_from(&gx);
        jacobian[(n, n)] = gp;
        let mut residual = DVector::zeros(n + 1);
        residual.rows_mut(0, n).copy_from(&f);
        residual[n] = g;
        Ok((residual, jacobian))
    }
}
