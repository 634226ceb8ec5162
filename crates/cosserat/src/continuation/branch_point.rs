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
//! tolerance. Every solve is in F_x's shape (`bordering.rs`): in the
//! unknowns' order (x, μ, p) the Newton matrix differs from
//! diag(K, 1), K = [F_x b; cᵀ 0], by the column F_p and the rows of g and
//! h — a rank-three Woodbury correction of K's factors, O(N) per
//! iteration on multiple shooting and collocation.

use nalgebra::DVector;

use super::bordering::{low_rank_solve, null_vectors, BorderedJacobian};
use super::fold::unit;
use super::Run;

/// Newton iterations before the augmented system is given up.
const MAX_ITERATIONS: usize = 12;

/// A branch point located on the augmented system: the unknowns, the
/// parameter and the Newton iterations it took.
pub(super) type Located = (Vec<f64>, f64, usize);

/// The augmented system at one iterate z = (x, p, μ): the residual
/// (F + μb, g, h), the Newton correction (in the same order) and the
/// norms of ∇g and ∇h (scales for their tolerances).
struct Augmented {
    residual: DVector<f64>,
    step: DVector<f64>,
    gradients: (f64, f64),
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
        let fx0 = self.linearization(x0, p0).map_err(|e| e.to_string())?.1;
        let (c, b) = null_vectors(&fx0).ok_or("F_x: no null vectors by inverse iteration")?;
        let mut z = DVector::from_iterator(n + 2, x0.iter().copied().chain([p0, 0.0]));
        let start = z.rows(0, n + 1).into_owned();
        let mut here = self.branch_system(&z, &b, &c)?;
        for iteration in 1..=MAX_ITERATIONS {
            z -= &here.step;
            if (z.rows(0, n + 1) - &start).norm() > radius {
                return Err(format!(
                    "Newton left the step (|Δz| > {radius:.3e}) at iteration {iteration}"
                ));
            }
            let (p, dp) = (z[n], here.step[n]);
            here = self.branch_system(&z, &b, &c)?;
            let tol_p = self.opts.event_tolerance * p.abs().max(1.0);
            if dp.abs() <= tol_p && self.branch_converged(&here, z[n + 1] * b.amax()) {
                return Ok((z.rows(0, n).iter().copied().collect(), p, iteration));
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
            && r[n].abs() <= tol * at.gradients.0
            && r[n + 1].abs() <= tol * at.gradients.1
    }

    /// The residual (F + μb, g, h) at z = (x, p, μ) and the Newton
    /// correction.
    fn branch_system(
        &self,
        z: &DVector<f64>,
        b: &DVector<f64>,
        c: &DVector<f64>,
    ) -> Result<Augmented, String> {
        let n = z.len() - 2;
        let (x, p, mu) = (&z.as_slice()[..n], z[n], z[n + 1]);
        let fail = |e: super::PointError| e.to_string();
        let (f, fx) = self.linearization(x, p).map_err(fail)?;
        let fp = self.family.parameter_derivative(x, p).map_err(fail)?;
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
        let minus_fp = DVector::from_iterator(n + 1, fp.iter().map(|v| -v).chain([0.0]));
        let v0 = k.solve(&minus_fp).ok_or(singular)?.rows(0, n).into_owned();
        // wᵀ F_xx[d, ·] by a central difference of wᵀF_x along d (zero
        // along a zero direction: v₀ = 0 where F_p = 0, e.g. a straight
        // column in its load).
        let along = |d: &DVector<f64>| -> Result<DVector<f64>, String> {
            if d.amax() == 0.0 {
                return Ok(DVector::zeros(n));
            }
            let eps = 1e-6 * x.iter().fold(1.0f64, |m, v| m.max(v.abs())) / d.amax();
            let shifted = |sign: f64| -> Vec<f64> {
                x.iter()
                    .zip(d.iter())
                    .map(|(a, e)| a + sign * eps * e)
                    .collect()
            };
            let up = self
                .transposed_product(&shifted(1.0), p, &w)
                .map_err(fail)?;
            let down = self
                .transposed_product(&shifted(-1.0), p, &w)
                .map_err(fail)?;
            Ok((up - down) / (2.0 * eps))
        };
        let h = 1e-6 * p.abs().max(1.0);
        let (plus, minus) = (
            self.linearization(x, p + h).map_err(fail)?.1,
            self.linearization(x, p - h).map_err(fail)?.1,
        );
        // wᵀ F_xp (a row), F_xp v, F_xp v₀ and F_pp.
        let wt_fxp = (plus.mul_transposed(&w) - minus.mul_transposed(&w)) / (2.0 * h);
        let fxp = |d: &DVector<f64>| (plus.mul(d) - minus.mul(d)) / (2.0 * h);
        let fpp = (self.family.parameter_derivative(x, p + h).map_err(fail)?
            - self.family.parameter_derivative(x, p - h).map_err(fail)?)
            / (2.0 * h);
        let gx = -along(&v)?;
        let gp = -w.dot(&fxp(&v));
        let hx = along(&v0)? + wt_fxp;
        let hp = w.dot(&fxp(&v0)) + w.dot(&fpp);
        // In the order (x, μ, p): the Newton matrix is diag(K, 1) plus the
        // column F_p (rows of F), the row (g_x − c, 0, g_p) in K's border
        // row and the row (h_x, 0, h_p − 1) in the identity's.
        let m = n + 2;
        let mut residual = DVector::zeros(m);
        residual.rows_mut(0, n).copy_from(&(f + b * mu));
        residual[n] = g;
        residual[n + 1] = w.dot(&fp);
        let column = DVector::from_iterator(m, fp.iter().copied().chain([0.0, 0.0]));
        let g_row = DVector::from_iterator(m, (&gx - c).iter().copied().chain([0.0, gp]));
        let h_row = DVector::from_iterator(m, hx.iter().copied().chain([0.0, hp - 1.0]));
        let solve_k = |r: &DVector<f64>| -> Option<DVector<f64>> {
            let mut y = k.solve(&r.rows(0, n + 1).into_owned())?;
            y = y.push(r[n + 1]);
            Some(y)
        };
        let (en, ep) = (unit(m, n), unit(m, n + 1));
        let step = low_rank_solve(
            solve_k,
            &[column, en, ep.clone()],
            &[ep, g_row, h_row],
            &residual,
        )
        .ok_or("the augmented Jacobian is singular (not a simple branch point)")?;
        // Back to the order (x, p, μ).
        let mut step = step;
        step.swap_rows(n, n + 1);
        let gradients = (
            (gx.norm_squared() + gp * gp).sqrt(),
            (hx.norm_squared() + hp * hp).sqrt(),
        );
        Ok(Augmented {
            residual,
            step,
            gradients,
        })
    }
}

/// The x-part of [F_x column; rowᵀ 0] [y; s] = [rhs; 0]: the solution of
/// F_x y = rhs in the complement of the (near) kernel of F_x, whatever
/// its (near) singularity.
pub(super) fn bordered_solve(k: &mut BorderedJacobian, rhs: &DVector<f64>) -> Option<DVector<f64>> {
    let n = rhs.len();
    let full = DVector::from_iterator(n + 1, rhs.iter().copied().chain([0.0]));
    Some(k.solve(&full)?.rows(0, n).into_owned())
}
