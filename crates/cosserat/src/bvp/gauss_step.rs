//! One step of the Gauss–Legendre Runge–Kutta method with its exact
//! derivative: the segment map of shooting on a collocation mesh.
//!
//! Gauss collocation with m points on a mesh is the m-stage Gauss RK method
//! stepped from node to node (Hairer, Nørsett & Wanner I, Thm. II.7.7), so
//! multiple shooting whose segments are single Gauss steps solves the
//! collocation equations of that mesh — order 2m at the nodes — with the
//! node states as unknowns. The stage equations K_i = f(s + c_i h,
//! y0 + h Σ_l a_il K_l) are solved by Newton; the sensitivity follows by
//! implicit differentiation, (I − h A ⊗ J) dK = (J_i Φ0)_i, Φ1 = Φ0 +
//! h Σ b_i dK_i, with J_i = ∂f/∂y at the stages. The method preserves the
//! quadratic invariants d_i·d_j exactly, so no projection is needed.
//!
//! Cost: the stage equations are solved in flat buffers allocated once per
//! step, with the small dense LU of collocation compiled for the stage
//! sizes m·n (`collocation::lu`: the general nalgebra LU of the 36 × 36
//! spatial stage matrix took 45 % of a collocation continuation run,
//! `perf`, with its allocations another 8 %); one factorization at the
//! converged stages gives the sensitivities of every column of Φ0 and of
//! the parameter (implicit-function theorem: one matrix, many right-hand
//! sides).

use nalgebra::DMatrix;

use super::collocation::lu::{dense_lu, dense_solve, dense_solve_rows};
use super::collocation::Tableau;
use crate::equations::RodEquations;
use crate::model::RodTangent;
use crate::numerics::integrator::IntegrationError;

/// The buffers of one Gauss step, sized once (m stages of dimension n).
struct StageWork {
    n: usize,
    m: usize,
    /// Stage derivatives K_i (m·n).
    k: Vec<f64>,
    /// Stage states Y_i = y0 + h Σ_l a_il K_l (m·n).
    y: Vec<f64>,
    /// Residual, then Newton correction (m·n).
    r: Vec<f64>,
    /// ∂f/∂y at the stages, n × n column-major each.
    jac: Vec<f64>,
    /// The n × n identity, column-major (tangents giving ∂f/∂y).
    ident: Vec<f64>,
    /// f at a stage (n).
    f: Vec<f64>,
    /// The stage matrix I − h (diag J_i)(A ⊗ I), row-major, factored in place.
    w: Vec<f64>,
    piv: Vec<usize>,
}

impl StageWork {
    fn new(n: usize, m: usize) -> Self {
        let mn = m * n;
        let mut ident = vec![0.0; n * n];
        ident.iter_mut().step_by(n + 1).for_each(|v| *v = 1.0);
        StageWork {
            n,
            m,
            k: vec![0.0; mn],
            y: vec![0.0; mn],
            r: vec![0.0; mn],
            jac: vec![0.0; m * n * n],
            ident,
            f: vec![0.0; n],
            w: vec![0.0; mn * mn],
            piv: vec![0; mn],
        }
    }

    /// The stage states y0 + h Σ_l a_il K_l into `self.y`.
    fn stage_states(&mut self, tab: &Tableau, h: f64, y0: &[f64]) {
        let n = self.n;
        for i in 0..self.m {
            let yi = &mut self.y[i * n..(i + 1) * n];
            yi.copy_from_slice(y0);
            for l in 0..self.m {
                let w = h * tab.a(i, l);
                let kl = &self.k[l * n..(l + 1) * n];
                yi.iter_mut().zip(kl).for_each(|(a, b)| *a += w * b);
            }
        }
    }

    /// J_i = ∂f/∂y at the stage states (one `rhs_linearized` call each).
    fn stage_jacobians(&mut self, eq: &dyn RodEquations, tab: &Tableau, s: f64, h: f64) {
        let (n, nn) = (self.n, self.n * self.n);
        for i in 0..self.m {
            eq.rhs_linearized(
                s + tab.c[i] * h,
                &self.y[i * n..(i + 1) * n],
                n,
                &self.ident,
                &mut self.f,
                &mut self.jac[i * nn..(i + 1) * nn],
            );
        }
    }

    /// W = I − h (diag J_i)(A ⊗ I), the Newton matrix of the stage
    /// equations (block (i, l) = δ_il I − h a_il J_i), factored; false if
    /// singular.
    fn factor_stage_matrix(&mut self, tab: &Tableau, h: f64) -> bool {
        let (n, m) = (self.n, self.m);
        let (mn, nn) = (m * n, n * n);
        for i in 0..m {
            let ji = &self.jac[i * nn..(i + 1) * nn];
            for l in 0..m {
                let coef = h * tab.a(i, l);
                for r in 0..n {
                    let row = &mut self.w[(i * n + r) * mn + l * n..(i * n + r) * mn + (l + 1) * n];
                    for (c, v) in row.iter_mut().enumerate() {
                        let id = if i == l && r == c { 1.0 } else { 0.0 };
                        *v = id - coef * ji[c * n + r];
                    }
                }
            }
        }
        dense_lu(&mut self.w, mn, &mut self.piv)
    }

    /// The residual K_i − f(s_i, Y_i) into `self.r` (stage states current);
    /// false if it is not finite.
    fn residual(&mut self, eq: &dyn RodEquations, tab: &Tableau, s: f64, h: f64) -> bool {
        let n = self.n;
        for i in 0..self.m {
            eq.rhs(s + tab.c[i] * h, &self.y[i * n..(i + 1) * n], &mut self.f);
            let (ri, ki) = (&mut self.r[i * n..(i + 1) * n], &self.k[i * n..(i + 1) * n]);
            for ((r, k), f) in ri.iter_mut().zip(ki).zip(&self.f) {
                *r = k - f;
            }
        }
        self.r.iter().all(|v| v.is_finite())
    }
}

/// y(s + h) and Φ(s + h) = ∂y(s + h)/∂(unknowns) from y0 and Φ0 (n × cols,
/// cols may be 0) by one Gauss step.
///
/// With `forcing`, the last column of Φ is the parameter sensitivity
/// z = ∂y/∂p at fixed σ = s/L: its stage equations gain the explicit
/// ∂f/∂p ([`RodEquations::rhs_parameter`]), (I − h A ⊗ J) dK =
/// (J_i z0 + ∂f/∂p(s_i, Y_i))_i. A Gauss step on s = Lσ with h = L/K is
/// the same step on σ with 1/K, so this is the exact p-derivative of the
/// discrete step, a length rate included.
pub(crate) fn gauss_step(
    eq: &dyn RodEquations,
    tab: &Tableau,
    s: f64,
    h: f64,
    y0: &[f64],
    phi0: &DMatrix<f64>,
    forcing: Option<&RodTangent>,
) -> Result<(Vec<f64>, DMatrix<f64>), IntegrationError> {
    let (m, n) = (tab.m, eq.dim());
    let mut ws = StageWork::new(n, m);
    solve_stages(eq, tab, s, h, y0, &mut ws)?;
    let mut y1 = y0.to_vec();
    for i in 0..m {
        let w = h * tab.b[i];
        let ki = &ws.k[i * n..(i + 1) * n];
        y1.iter_mut().zip(ki).for_each(|(a, b)| *a += w * b);
    }
    let cols = phi0.ncols();
    if cols == 0 {
        return Ok((y1, DMatrix::zeros(n, 0)));
    }
    Ok((y1, sensitivity(eq, tab, s, h, phi0, forcing, &mut ws)?))
}

/// The stage derivatives K of the step into `ws.k` (and their stage
/// states into `ws.y`), by Newton from
/// K_i = f(s + c_i h, y0 + c_i h f(s, y0)).
///
/// Simplified Newton: the stage matrix of the first iterate is factored
/// once and kept while the corrections contract at least twofold (its
/// error is O(h) in the stages, so the rate is O(h²)); it is refreshed
/// only where they do not. The fixed point is the same as Newton's.
fn solve_stages(
    eq: &dyn RodEquations,
    tab: &Tableau,
    s: f64,
    h: f64,
    y0: &[f64],
    ws: &mut StageWork,
) -> Result<(), IntegrationError> {
    let (m, n) = (tab.m, eq.dim());
    let mn = m * n;
    // K_i from the explicit Euler stage state y0 + c_i h f(s, y0): O(h²)
    // from the solution where f(s, y0) alone is O(h), one Newton
    // iteration fewer.
    eq.rhs(s, y0, &mut ws.f);
    for i in 0..m {
        let ch = tab.c[i] * h;
        let yi = &mut ws.y[i * n..(i + 1) * n];
        yi.iter_mut()
            .zip(y0)
            .zip(&ws.f)
            .for_each(|((y, a), f)| *y = a + ch * f);
    }
    for i in 0..m {
        let r = i * n..(i + 1) * n;
        eq.rhs(s + tab.c[i] * h, &ws.y[r.clone()], &mut ws.k[r]);
    }
    let scale = y0.iter().map(|v| v.abs()).fold(1.0, f64::max);
    let mut factored = false;
    let mut previous = f64::INFINITY;
    for _ in 0..30 {
        ws.stage_states(tab, h, y0);
        if !ws.residual(eq, tab, s, h) {
            return Err(IntegrationError::NotFinite { s });
        }
        if !factored {
            ws.stage_jacobians(eq, tab, s, h);
            if !ws.factor_stage_matrix(tab, h) {
                return Err(IntegrationError::StepSizeUnderflow { s });
            }
        }
        dense_solve(&ws.w, mn, &ws.piv, &mut ws.r);
        let mut size = 0.0f64;
        for (k, d) in ws.k.iter_mut().zip(&ws.r) {
            *k -= d;
            size = size.max(d.abs());
        }
        let size = h * size;
        if !size.is_finite() {
            return Err(IntegrationError::NotFinite { s });
        }
        if size <= 1e-15 * scale {
            ws.stage_states(tab, h, y0);
            return Ok(());
        }
        factored = size <= 0.5 * previous;
        previous = size;
    }
    Err(IntegrationError::StepSizeUnderflow { s })
}

/// Φ1 = Φ0 + h Σ_i b_i dK_i with (I − h (diag J_i)(A ⊗ I)) dK = (J_i Φ0)_i
/// (plus ∂f/∂p in the last column with `forcing`), J_i at the converged
/// stages: one factorization, a solve per column.
fn sensitivity(
    eq: &dyn RodEquations,
    tab: &Tableau,
    s: f64,
    h: f64,
    phi0: &DMatrix<f64>,
    forcing: Option<&RodTangent>,
    ws: &mut StageWork,
) -> Result<DMatrix<f64>, IntegrationError> {
    let (m, n, cols) = (tab.m, eq.dim(), phi0.ncols());
    let (mn, nn) = (m * n, n * n);
    ws.stage_jacobians(eq, tab, s, h);
    if !ws.factor_stage_matrix(tab, h) {
        return Err(IntegrationError::StepSizeUnderflow { s });
    }
    // ∂f/∂p at every stage, once: K_i = f(s_i, Y_i) to the stage Newton's 1e-15.
    let mut fp = vec![0.0; if forcing.is_some() { mn } else { 0 }];
    if let Some(t) = forcing {
        for i in 0..m {
            let r = i * n..(i + 1) * n;
            eq.rhs_parameter(
                s + tab.c[i] * h,
                &ws.y[r.clone()],
                &ws.k[r.clone()],
                t,
                &mut fp[r],
            );
        }
    }
    // The right-hand sides J_i Φ0 (+ ∂f/∂p), mn × cols row-major.
    let mut dk = vec![0.0; mn * cols];
    for i in 0..m {
        let ji = &ws.jac[i * nn..(i + 1) * nn];
        for (c, p0) in phi0.row_iter().enumerate() {
            let col = &ji[c * n..(c + 1) * n];
            for (r, &j) in col.iter().enumerate() {
                if j != 0.0 {
                    let row = &mut dk[(i * n + r) * cols..(i * n + r + 1) * cols];
                    row.iter_mut().zip(p0.iter()).for_each(|(d, p)| *d += j * p);
                }
            }
        }
    }
    if forcing.is_some() {
        for (row, f) in dk.chunks_exact_mut(cols).zip(&fp) {
            row[cols - 1] += f;
        }
    }
    dense_solve_rows(&ws.w, mn, &ws.piv, &mut dk, cols);
    if !dk.iter().all(|v| v.is_finite()) {
        return Err(IntegrationError::NotFinite { s });
    }
    let mut phi1 = phi0.clone();
    for i in 0..m {
        let w = h * tab.b[i];
        for r in 0..n {
            let row = &dk[(i * n + r) * cols..(i * n + r + 1) * cols];
            for (q, d) in row.iter().enumerate() {
                phi1[(r, q)] += w * d;
            }
        }
    }
    Ok(phi1)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::Vector3;

    use super::*;
    use crate::equations::KirchhoffEquations;
    use crate::model::{Clamp, DeadLoads, LinearElastic, Rod};

    /// Φ of one Gauss step against central differences of the step in y0,
    /// on the spatial equations of a loaded, intrinsically curved rod.
    #[test]
    fn sensitivity_matches_central_differences() {
        let rod = Rod::new(
            1.0,
            Arc::new(LinearElastic::uniform([2.0, 1.0, 1.5], [0.3, -0.4, 0.7]).unwrap()),
            Clamp::paper(),
            DeadLoads {
                tip_force: Vector3::new(1.5, 0.4, -0.3),
                ..Default::default()
            },
            None,
        )
        .unwrap();
        let eq = KirchhoffEquations::new(rod);
        let tab = Tableau::gauss(3).unwrap();
        let mut y0 = vec![0.0; 12];
        eq.initial_state(&[0.2, -0.5, 0.1], &mut y0);
        let (h, s) = (0.125, 0.25);
        let (_, phi) = gauss_step(&eq, &tab, s, h, &y0, &DMatrix::identity(12, 12), None).unwrap();
        let none = DMatrix::zeros(12, 0);
        for j in 0..12 {
            let (mut a, mut b) = (y0.clone(), y0.clone());
            a[j] += 1e-6;
            b[j] -= 1e-6;
            let ya = gauss_step(&eq, &tab, s, h, &a, &none, None).unwrap().0;
            let yb = gauss_step(&eq, &tab, s, h, &b, &none, None).unwrap().0;
            for i in 0..12 {
                let fd = (ya[i] - yb[i]) / 2e-6;
                assert!(
                    (fd - phi[(i, j)]).abs() < 1e-7,
                    "({i}, {j}): {fd} vs {}",
                    phi[(i, j)]
                );
            }
        }
    }
}
