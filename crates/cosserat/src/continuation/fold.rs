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
//! corrector's tolerance.
//!
//! Every solve is in F_x's shape (`bordering.rs`): K = [F_x b; cᵀ 0] is
//! factored once per iterate, v and w are K⁻¹e and K⁻ᵀe, the rows
//! wᵀF_x(x ± εv) are transposed products, and the Newton matrix
//! [F_x F_p; g_x g_p] = K + U Vᵀ differs from K by a column and a row
//! (Woodbury). O(N) per iteration on multiple shooting and collocation.

use nalgebra::DVector;

use super::bordering::{low_rank_solve, null_vectors, BorderedJacobian};
use super::Run;

/// Newton iterations before the augmented system is given up.
const MAX_ITERATIONS: usize = 12;

/// A fold located on the augmented system: the unknowns, the parameter and
/// the Newton iterations it took.
pub(super) type Fold = (Vec<f64>, f64, usize);

/// The augmented system at one iterate: the residual (F, g), the Newton
/// correction, and |∇g| (a scale for g's tolerance).
struct FoldSystem {
    residual: DVector<f64>,
    step: DVector<f64>,
    gradient: f64,
}

/// The unit vector e_k of length n.
pub(super) fn unit(n: usize, k: usize) -> DVector<f64> {
    let mut e = DVector::zeros(n);
    e[k] = 1.0;
    e
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
        let fx0 = self.linearization(x0, p0).map_err(|e| e.to_string())?.1;
        let (c, b) = null_vectors(&fx0).ok_or("F_x: no null vectors by inverse iteration")?;
        let mut z = DVector::from_iterator(n + 1, x0.iter().copied().chain([p0]));
        let start = z.clone();
        let mut here = self.fold_system(&z, &b, &c)?;
        for iteration in 1..=MAX_ITERATIONS {
            z -= &here.step;
            if (&z - &start).norm() > radius {
                return Err(format!(
                    "Newton left the step (|Δz| > {radius:.3e}) at iteration {iteration}"
                ));
            }
            let (p, dp) = (z[n], here.step[n]);
            here = self.fold_system(&z, &b, &c)?;
            let tol_p = self.opts.event_tolerance * p.abs().max(1.0);
            if dp.abs() <= tol_p && self.fold_converged(&here) {
                return Ok((z.rows(0, n).iter().copied().collect(), p, iteration));
            }
        }
        Err(format!(
            "Newton did not converge in {MAX_ITERATIONS} iterations"
        ))
    }

    /// ‖F‖∞ ≤ τ and |g| ≤ τ |∇g|.
    fn fold_converged(&self, at: &FoldSystem) -> bool {
        let n = at.residual.len() - 1;
        let tol = self.opts.tolerance;
        at.residual.rows(0, n).amax() <= tol && at.residual[n].abs() <= tol * at.gradient
    }

    /// The residual (F, g) at z = (x, p) and the Newton correction
    /// [F_x F_p; g_x g_p]⁻¹ (F, g).
    fn fold_system(
        &self,
        z: &DVector<f64>,
        b: &DVector<f64>,
        c: &DVector<f64>,
    ) -> Result<FoldSystem, String> {
        let n = z.len() - 1;
        let (x, p) = (&z.as_slice()[..n], z[n]);
        let fail = |e: super::PointError| e.to_string();
        let (f, fx) = self.linearization(x, p).map_err(fail)?;
        let singular = "the bordered matrix [F_x b; cᵀ 0] is singular";
        let mut k = BorderedJacobian::new(fx, b.clone(), c.clone()).ok_or(singular)?;
        let e = unit(n + 1, n);
        let vg = k.solve(&e).ok_or(singular)?;
        let (v, g) = (vg.rows(0, n).into_owned(), vg[n]);
        let w = k
            .solve_transposed(&e)
            .ok_or(singular)?
            .rows(0, n)
            .into_owned();
        let fp = self.family.parameter_derivative(x, p).map_err(fail)?;
        // g_x = −wᵀ (∂/∂ε F_x(x + εv)), g_p = −wᵀ (∂/∂p F_x) v.
        let eps = 1e-6 * x.iter().fold(1.0f64, |m, v| m.max(v.abs())) / v.amax();
        let shifted =
            |sign: f64| -> Vec<f64> { x.iter().zip(&v).map(|(a, d)| a + sign * eps * d).collect() };
        let up = self
            .transposed_product(&shifted(1.0), p, &w)
            .map_err(fail)?;
        let down = self
            .transposed_product(&shifted(-1.0), p, &w)
            .map_err(fail)?;
        let gx = -(up - down) / (2.0 * eps);
        let h = 1e-6 * p.abs().max(1.0);
        let up = self.product(x, p + h, &v).map_err(fail)?;
        let down = self.product(x, p - h, &v).map_err(fail)?;
        let gp = -w.dot(&(up - down)) / (2.0 * h);
        // [F_x F_p; g_x g_p] = K + (F_p − b; 0) e_nᵀ + e_n (g_x − c; g_p)ᵀ.
        let mut residual = DVector::zeros(n + 1);
        residual.rows_mut(0, n).copy_from(&f);
        residual[n] = g;
        let column = DVector::from_iterator(n + 1, (&fp - b).iter().copied().chain([0.0]));
        let row = DVector::from_iterator(n + 1, (&gx - c).iter().copied().chain([gp]));
        let step = low_rank_solve(|r| k.solve(r), &[column, e.clone()], &[e, row], &residual)
            .ok_or("the augmented Jacobian is singular (not a simple fold)")?;
        let gradient = (gx.norm_squared() + gp * gp).sqrt();
        Ok(FoldSystem {
            residual,
            step,
            gradient,
        })
    }
}
