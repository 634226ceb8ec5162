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
//! Cost: the stage equations are solved in flat buffers sized once per
//! [`GaussStepper`], with the small dense LU of collocation compiled for
//! the block sizes (`collocation::lu`: the general nalgebra LU of the
//! 36 × 36 spatial stage matrix took 45 % of a collocation continuation
//! run, `perf`, with its allocations another 8 %). The simplified Newton
//! iteration of the stages uses one Jacobian for all stages, so that A's
//! real block form splits its matrix into an n × n and a 2n × 2n block
//! (Hairer & Wanner II, §IV.8), and stops when the correction it predicts
//! is below round-off. The sensitivities need the exact matrix at the
//! converged stages: in the stage increments X = (A ⊗ I) dK it is
//! B = A⁻¹ ⊗ I − h diag(J_i), whose off-diagonal blocks are multiples of
//! I, eliminated by blocks (half the (mn)³ work); one factorization gives
//! the sensitivities of every column of Φ0 and of the parameter
//! (implicit-function theorem: one matrix, many right-hand sides).

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
    /// ∂f/∂y at the step's start, n × n column-major: the one Jacobian of
    /// the simplified Newton matrix I − h A ⊗ J̄.
    jbar: Vec<f64>,
    /// I − hγJ̄ of A's real eigenvalue γ, row-major, factored in place.
    real_block: Vec<f64>,
    real_piv: Vec<usize>,
    /// [[I − hαJ̄, −hβJ̄], [hβJ̄, I − hαJ̄]] of A's pair α ± iβ, 2n × 2n
    /// row-major, factored in place.
    pair_block: Vec<f64>,
    pair_piv: Vec<usize>,
    /// The transformed correction (T⁻¹ ⊗ I) r (m·n).
    z: Vec<f64>,
    /// ∂f/∂p at the stages (m·n, empty without forcing).
    fp: Vec<f64>,
    /// The sensitivities' right-hand sides, then dK (m·n × cols, row-major).
    dk: Vec<f64>,
    /// Φ0, then Φ1, by rows (n × cols).
    rows: Vec<f64>,
    /// The nonzeros (row, column, value) of Φ0.
    nonzeros: Vec<(usize, usize, f64)>,
    /// The exact stage matrix in Z-form, eliminated by blocks.
    zform: ZForm,
}

/// B = A⁻¹ ⊗ I − h diag(J_i), the Newton matrix of the stage equations in
/// the stage increments X_i = Σ_l a_il K_l (W = B (A ⊗ I)), by block
/// elimination of its first block row: B_00 = ā_00 I − h J_0 factored and
/// inverted (C), the Schur complement S_lk = B_lk − ā_l0 ā_0k C of the
/// other (m − 1)n rows factored with partial pivoting. The off-diagonal
/// blocks ā_il I are multiples of I, so this is ≈ half the work of the
/// (mn)² LU, and its solves with many columns cost ≈ 2/3.
struct ZForm {
    /// B_00, n × n row-major, factored in place.
    b0: Vec<f64>,
    piv0: Vec<usize>,
    /// C = B_00⁻¹, n × n row-major.
    c0: Vec<f64>,
    /// S, (m − 1)n square, row-major, factored in place.
    schur: Vec<f64>,
    piv_s: Vec<usize>,
    /// n × cols scratch: C R_0, then Σ_k ā_0k X_k.
    t: Vec<f64>,
    u: Vec<f64>,
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
            jbar: vec![0.0; n * n],
            real_block: vec![0.0; n * n],
            real_piv: vec![0; n],
            pair_block: vec![0.0; 4 * n * n],
            pair_piv: vec![0; 2 * n],
            z: vec![0.0; mn],
            fp: Vec::new(),
            dk: Vec::new(),
            rows: Vec::new(),
            nonzeros: Vec::new(),
            zform: ZForm {
                b0: vec![0.0; n * n],
                piv0: vec![0; n],
                c0: vec![0.0; n * n],
                schur: vec![0.0; (mn - n) * (mn - n)],
                piv_s: vec![0; mn - n],
                t: Vec::new(),
                u: Vec::new(),
            },
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

    /// [`ZForm`] at the stage Jacobians `self.jac`; false (nothing to use)
    /// where the block elimination is not known to be stable, i.e. unless
    /// ‖h J_0‖_∞ ≤ ā_00 / 2 (then ‖C‖ ≤ 2/ā_00 by the Neumann series, and
    /// the eliminated entries stay of the size of B's), or if a block is
    /// singular.
    fn factor_z_form(&mut self, tab: &Tableau, h: f64) -> bool {
        let (n, m) = (self.n, self.m);
        let (nn, q) = (n * n, (m - 1) * n);
        let j0 = &self.jac[..nn];
        let a00 = tab.a_inv(0, 0);
        let row_sum = (0..n)
            .map(|r| (0..n).map(|c| j0[c * n + r].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        if !(a00 > 0.0 && h * row_sum <= 0.5 * a00) {
            return false;
        }
        let z = &mut self.zform;
        for r in 0..n {
            for c in 0..n {
                let id = if r == c { a00 } else { 0.0 };
                z.b0[r * n + c] = id - h * j0[c * n + r];
            }
        }
        if !dense_lu(&mut z.b0, n, &mut z.piv0) {
            return false;
        }
        z.c0.fill(0.0);
        z.c0.iter_mut().step_by(n + 1).for_each(|v| *v = 1.0);
        dense_solve_rows(&z.b0, n, &z.piv0, &mut z.c0, n);
        for l in 1..m {
            let jl = &self.jac[l * nn..(l + 1) * nn];
            for k in 1..m {
                let (all, coupling) = (tab.a_inv(l, k), tab.a_inv(l, 0) * tab.a_inv(0, k));
                for r in 0..n {
                    let row = &mut z.schur[((l - 1) * n + r) * q + (k - 1) * n..][..n];
                    let crow = &z.c0[r * n..(r + 1) * n];
                    for (c, v) in row.iter_mut().enumerate() {
                        let mut b = if r == c { all } else { 0.0 };
                        if l == k {
                            b -= h * jl[c * n + r];
                        }
                        *v = b - coupling * crow[c];
                    }
                }
            }
        }
        q == 0 || dense_lu(&mut z.schur, q, &mut z.piv_s)
    }

    /// X = B⁻¹ R in place for R (mn × cols, row-major) by the factors of
    /// [`Self::factor_z_form`]: T = C R_0, S X_rest = R_rest − ā_·0 T,
    /// X_0 = T − C Σ_k ā_0k X_k.
    fn solve_z_form(&mut self, tab: &Tableau, x: &mut [f64], cols: usize) {
        let (n, m) = (self.n, self.m);
        let z = &mut self.zform;
        let (first, rest) = x.split_at_mut(n * cols);
        z.t.clear();
        z.t.resize(n * cols, 0.0);
        mat_rows(&z.c0, n, first, cols, &mut z.t);
        for l in 1..m {
            let w = tab.a_inv(l, 0);
            let rl = &mut rest[(l - 1) * n * cols..l * n * cols];
            rl.iter_mut().zip(&z.t).for_each(|(r, t)| *r -= w * t);
        }
        if m > 1 {
            dense_solve_rows(&z.schur, (m - 1) * n, &z.piv_s, rest, cols);
        }
        let mut u = std::mem::take(&mut z.u);
        u.clear();
        u.resize(n * cols, 0.0);
        for k in 1..m {
            let w = tab.a_inv(0, k);
            let xk = &rest[(k - 1) * n * cols..k * n * cols];
            u.iter_mut().zip(xk).for_each(|(a, b)| *a += w * b);
        }
        // X_0 = T − C U, into the first block row.
        mat_rows(&z.c0, n, &u, cols, first);
        first.iter_mut().zip(&z.t).for_each(|(x, t)| *x = t - *x);
        z.u = u;
    }

    /// The blocks of I − h Λ ⊗ J̄ (`StageBlocks` of `collocation/tableau.rs`),
    /// J̄ = `self.jbar`, factored; false if one is singular.
    fn factor_blocks(&mut self, tab: &Tableau, h: f64) -> bool {
        let n = self.n;
        let jbar = &self.jbar;
        // J̄(r, c) from its column-major storage.
        let j = |r: usize, c: usize| jbar[c * n + r];
        if let Some(g) = tab.blocks.real {
            for r in 0..n {
                for c in 0..n {
                    let id = if r == c { 1.0 } else { 0.0 };
                    self.real_block[r * n + c] = id - h * g * j(r, c);
                }
            }
            if !dense_lu(&mut self.real_block, n, &mut self.real_piv) {
                return false;
            }
        }
        if let Some((al, be)) = tab.blocks.pair {
            let d = 2 * n;
            for r in 0..n {
                for c in 0..n {
                    let id = if r == c { 1.0 } else { 0.0 };
                    let (diag, off) = (id - h * al * j(r, c), h * be * j(r, c));
                    self.pair_block[r * d + c] = diag;
                    self.pair_block[r * d + n + c] = -off;
                    self.pair_block[(n + r) * d + c] = off;
                    self.pair_block[(n + r) * d + n + c] = diag;
                }
            }
            if !dense_lu(&mut self.pair_block, d, &mut self.pair_piv) {
                return false;
            }
        }
        true
    }

    /// `self.r` ← (I − h A ⊗ J̄)⁻¹ `self.r` by the factored blocks:
    /// (T ⊗ I)(I − h Λ ⊗ J̄)⁻¹(T⁻¹ ⊗ I).
    fn solve_blocks(&mut self, tab: &Tableau) {
        let (n, m) = (self.n, self.m);
        let sb = &tab.blocks;
        transform(&sb.t_inv, m, n, &self.r, &mut self.z);
        let mut k = 0;
        if sb.real.is_some() {
            dense_solve(&self.real_block, n, &self.real_piv, &mut self.z[..n]);
            k = n;
        }
        if sb.pair.is_some() {
            dense_solve(
                &self.pair_block,
                2 * n,
                &self.pair_piv,
                &mut self.z[k..k + 2 * n],
            );
        }
        transform(&sb.t, m, n, &self.z, &mut self.r);
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

/// `out` ← M V for the n × n row-major M and V (n × cols, row-major), by
/// contiguous axpys over the rows of V.
fn mat_rows(mat: &[f64], n: usize, v: &[f64], cols: usize, out: &mut [f64]) {
    out.fill(0.0);
    for r in 0..n {
        let o = &mut out[r * cols..(r + 1) * cols];
        for (c, vr) in v.chunks_exact(cols).enumerate() {
            let w = mat[r * n + c];
            if w != 0.0 {
                o.iter_mut().zip(vr).for_each(|(a, b)| *a += w * b);
            }
        }
    }
}

/// `out` ← (M ⊗ I) `v` for the m × m row-major M and m blocks of n.
fn transform(mat: &[f64], m: usize, n: usize, v: &[f64], out: &mut [f64]) {
    for p in 0..m {
        let o = &mut out[p * n..(p + 1) * n];
        o.fill(0.0);
        for q in 0..m {
            let w = mat[p * m + q];
            let vq = &v[q * n..(q + 1) * n];
            o.iter_mut().zip(vq).for_each(|(a, b)| *a += w * b);
        }
    }
}

/// Gauss steps of one tableau with their stage buffers, sized at the
/// first step and reused by every later one (a segment map is called
/// once per interval and Newton iterate: no allocation per step but the
/// returned state and Φ).
pub(crate) struct GaussStepper {
    tab: Tableau,
    ws: Option<StageWork>,
}

impl GaussStepper {
    pub(crate) fn new(tab: Tableau) -> Self {
        GaussStepper { tab, ws: None }
    }

    /// y(s + h) and Φ(s + h) = ∂y(s + h)/∂(unknowns) from y0 and Φ0
    /// (n × cols, cols may be 0) by one Gauss step.
    ///
    /// With `forcing`, the last column of Φ is the parameter sensitivity
    /// z = ∂y/∂p at fixed σ = s/L: its stage equations gain the explicit
    /// ∂f/∂p ([`RodEquations::rhs_parameter`]), (I − h A ⊗ J) dK =
    /// (J_i z0 + ∂f/∂p(s_i, Y_i))_i. A Gauss step on s = Lσ with h = L/K
    /// is the same step on σ with 1/K, so this is the exact p-derivative
    /// of the discrete step, a length rate included.
    pub(crate) fn step(
        &mut self,
        eq: &dyn RodEquations,
        s: f64,
        h: f64,
        y0: &[f64],
        phi0: &DMatrix<f64>,
        forcing: Option<&RodTangent>,
    ) -> Result<(Vec<f64>, DMatrix<f64>), IntegrationError> {
        let tab = &self.tab;
        let (m, n) = (tab.m, eq.dim());
        if self.ws.as_ref().is_some_and(|w| w.n != n) {
            self.ws = None;
        }
        let ws = self.ws.get_or_insert_with(|| StageWork::new(n, m));
        solve_stages(eq, tab, s, h, y0, ws)?;
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
        Ok((y1, sensitivity(eq, tab, s, h, phi0, forcing, ws)?))
    }
}

/// The stage derivatives K of the step into `ws.k` (and their stage
/// states into `ws.y`), by Newton from
/// K_i = f(s + c_i h, y0 + c_i h f(s, y0)).
///
/// Simplified Newton on I − h A ⊗ J̄ with J̄ = ∂f/∂y at the midpoint
/// Euler state y0 + (h/2) f(s, y0), factored by A's real block form
/// (`StageBlocks` of `collocation/tableau.rs`: an n × n and a 2n × 2n
/// factorization instead of the (mn)² one, and one Jacobian evaluation
/// instead of m), kept while the corrections contract at least twofold
/// (its error is O(h) in the stages, so the rate is O(h²)). Where they do
/// not, the exact Newton matrix I − h (diag J_i)(A ⊗ I) at the current
/// stages replaces it. The fixed point is the same as Newton's.
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
    // iteration fewer. J̄ at the middle of the step is O(h/2) from every
    // stage's (4.4 against 4.6 iterations per step from J(s, y0) on
    // `problems/lateral_torsional_buckling.toml`).
    eq.rhs(s, y0, &mut ws.f);
    {
        let mid = &mut ws.z[..n];
        mid.iter_mut()
            .zip(y0)
            .zip(&ws.f)
            .for_each(|((y, a), f)| *y = a + 0.5 * h * f);
        eq.rhs_linearized(
            s + 0.5 * h,
            &ws.z[..n],
            n,
            &ws.ident,
            &mut ws.r[..n],
            &mut ws.jbar,
        );
    }
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
    // Which matrix solves the corrections: the blocks of I − h A ⊗ J̄,
    // or the exact matrix factored at the stages of an iterate.
    let mut exact = !ws.factor_blocks(tab, h);
    let mut refresh = exact;
    let mut previous = f64::INFINITY;
    for _ in 0..30 {
        ws.stage_states(tab, h, y0);
        if !ws.residual(eq, tab, s, h) {
            return Err(IntegrationError::NotFinite { s });
        }
        if refresh {
            ws.stage_jacobians(eq, tab, s, h);
            if !ws.factor_stage_matrix(tab, h) {
                return Err(IntegrationError::StepSizeUnderflow { s });
            }
            exact = true;
        }
        if exact {
            dense_solve(&ws.w, mn, &ws.piv, &mut ws.r);
        } else {
            ws.solve_blocks(tab);
        }
        let mut size = 0.0f64;
        for (k, d) in ws.k.iter_mut().zip(&ws.r) {
            *k -= d;
            size = size.max(d.abs());
        }
        let size = h * size;
        if !size.is_finite() {
            return Err(IntegrationError::NotFinite { s });
        }
        // Converged when this correction, or the next one it predicts at
        // the observed contraction θ (the error left is ≈ θ/(1 − θ) times
        // it, Hairer & Wanner II, §IV.8), is below round-off: the second
        // test saves the iteration that would only confirm it.
        let theta = size / previous;
        if size <= 1e-15 * scale
            || (previous.is_finite()
                && theta < 0.5
                && theta / (1.0 - theta) * size <= 1e-15 * scale)
        {
            ws.stage_states(tab, h, y0);
            return Ok(());
        }
        refresh = size > 0.5 * previous;
        previous = size;
    }
    Err(IntegrationError::StepSizeUnderflow { s })
}

/// Φ1 = Φ0 + h Σ_i b_i dK_i with (I − h (diag J_i)(A ⊗ I)) dK = (J_i Φ0)_i
/// (plus ∂f/∂p in the last column with `forcing`), J_i at the converged
/// stages: one factorization, all columns solved together. Where the
/// block elimination of [`ZForm`] is stable it solves B X = (J_i Φ0)_i
/// instead, and Φ1 = Φ0 + h Σ_i d_i X_i (W = B (A ⊗ I), bᵀA⁻¹ = dᵀ).
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
    // The Z-form by blocks where it is stable, else the pivoted LU of W.
    let zform = ws.factor_z_form(tab, h);
    if !zform && !ws.factor_stage_matrix(tab, h) {
        return Err(IntegrationError::StepSizeUnderflow { s });
    }
    // ∂f/∂p at every stage, once: K_i = f(s_i, Y_i) to the stage Newton's 1e-15.
    let mut fp = std::mem::take(&mut ws.fp);
    fp.resize(if forcing.is_some() { mn } else { 0 }, 0.0);
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
    // Φ0 by rows (n × cols), so that every update below is a contiguous
    // axpy over the columns (a DMatrix row is strided).
    let mut rows = std::mem::take(&mut ws.rows);
    rows.clear();
    for r in 0..n {
        rows.extend(phi0.row(r).iter());
    }
    // The nonzeros of Φ0's rows: at an interior node Φ0 = [I | 0], so
    // J_i Φ0 costs n² per stage, not n²·cols.
    let mut nz = std::mem::take(&mut ws.nonzeros);
    nz.clear();
    nz.extend(
        rows.iter()
            .enumerate()
            .filter(|&(_, &v)| v != 0.0)
            .map(|(k, &v)| (k / cols, k % cols, v)),
    );
    // The right-hand sides J_i Φ0 (+ ∂f/∂p), mn × cols row-major, each
    // entry summed over c in order.
    let mut dk = std::mem::take(&mut ws.dk);
    dk.clear();
    dk.resize(mn * cols, 0.0);
    for i in 0..m {
        let ji = &ws.jac[i * nn..(i + 1) * nn];
        for r in 0..n {
            let row = &mut dk[(i * n + r) * cols..(i * n + r + 1) * cols];
            for &(c, q, v) in &nz {
                let j = ji[c * n + r];
                if j != 0.0 {
                    row[q] += j * v;
                }
            }
        }
    }
    ws.nonzeros = nz;
    if forcing.is_some() {
        for (row, f) in dk.chunks_exact_mut(cols).zip(&fp) {
            row[cols - 1] += f;
        }
    }
    // dK = W⁻¹ R, or X = B⁻¹ R with Σ_i b_i dK_i = Σ_i d_i X_i (d = A⁻ᵀ b).
    let weights = if zform {
        ws.solve_z_form(tab, &mut dk, cols);
        &tab.d
    } else {
        dense_solve_rows(&ws.w, mn, &ws.piv, &mut dk, cols);
        &tab.b
    };
    let finite = dk.iter().all(|v| v.is_finite());
    ws.fp = fp;
    if !finite {
        ws.dk = dk;
        ws.rows = rows;
        return Err(IntegrationError::NotFinite { s });
    }
    // Φ1 = Φ0 + h Σ_i b_i dK_i, accumulated by rows in stage order.
    for i in 0..m {
        let w = h * weights[i];
        let dki = &dk[i * n * cols..(i + 1) * n * cols];
        rows.iter_mut().zip(dki).for_each(|(a, d)| *a += w * d);
    }
    let phi1 = DMatrix::from_row_slice(n, cols, &rows);
    ws.rows = rows;
    ws.dk = dk;
    Ok(phi1)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::Vector3;

    use super::*;
    use crate::equations::KirchhoffEquations;
    use crate::model::{Clamp, DeadLoads, LinearElastic, Rod};

    /// A deterministic pseudo-random value in [−1, 1) (an LCG).
    fn noise(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// Stage buffers with the Jacobians J_i = `scale` · noise (and J̄ = J_0).
    fn work_with_jacobians(tab: &Tableau, n: usize, scale: f64, same: bool) -> StageWork {
        let mut ws = StageWork::new(n, tab.m);
        let mut st = 7u64;
        let nn = n * n;
        for i in 0..tab.m {
            for v in 0..nn {
                let x = scale * noise(&mut st);
                ws.jac[i * nn + v] = if same && i > 0 { ws.jac[v] } else { x };
            }
        }
        ws.jbar.copy_from_slice(&ws.jac[..nn]);
        ws
    }

    /// The block elimination of B = A⁻¹ ⊗ I − h diag(J_i) gives the same
    /// dK = (A⁻¹ ⊗ I) X as the pivoted LU of W = I − h (diag J_i)(A ⊗ I),
    /// for every stage count and both state sizes; and declines where
    /// ‖h J_0‖ exceeds ā_00/2.
    #[test]
    fn z_form_matches_the_pivoted_stage_matrix() {
        for m in 1..=3 {
            for n in [4, 12] {
                let tab = Tableau::gauss(m).unwrap();
                let (mn, cols, h) = (m * n, 5, 0.05);
                let mut ws = work_with_jacobians(&tab, n, 1.0, false);
                assert!(ws.factor_z_form(&tab, h), "m {m} n {n}");
                assert!(ws.factor_stage_matrix(&tab, h));
                let mut st = 11u64;
                let rhs: Vec<f64> = (0..mn * cols).map(|_| noise(&mut st)).collect();
                let mut dk = rhs.clone();
                dense_solve_rows(&ws.w, mn, &ws.piv, &mut dk, cols);
                let mut x = rhs;
                ws.solve_z_form(&tab, &mut x, cols);
                for i in 0..m {
                    for v in 0..n * cols {
                        let z: f64 = (0..m).map(|l| tab.a_inv(i, l) * x[l * n * cols + v]).sum();
                        let d = dk[i * n * cols + v];
                        assert!(
                            (z - d).abs() < 1e-13 * (1.0 + d.abs()),
                            "m {m} n {n}: {z} vs {d}"
                        );
                    }
                }
                let mut stiff = work_with_jacobians(&tab, n, 1e3, false);
                assert!(!stiff.factor_z_form(&tab, h), "m {m} n {n}");
            }
        }
    }

    /// With one Jacobian for all stages, the blocks of A's real form solve
    /// I − h A ⊗ J̄ as its pivoted LU does.
    #[test]
    fn stage_blocks_solve_the_simplified_newton_matrix() {
        for m in 1..=3 {
            for n in [4, 12] {
                let tab = Tableau::gauss(m).unwrap();
                let (mn, h) = (m * n, 0.3);
                let mut ws = work_with_jacobians(&tab, n, 1.0, true);
                assert!(ws.factor_blocks(&tab, h));
                assert!(ws.factor_stage_matrix(&tab, h));
                let mut st = 5u64;
                let rhs: Vec<f64> = (0..mn).map(|_| noise(&mut st)).collect();
                let mut exact = rhs.clone();
                dense_solve(&ws.w, mn, &ws.piv, &mut exact);
                ws.r.copy_from_slice(&rhs);
                ws.solve_blocks(&tab);
                for (a, b) in ws.r.iter().zip(&exact) {
                    assert!(
                        (a - b).abs() < 1e-13 * (1.0 + b.abs()),
                        "m {m} n {n}: {a} vs {b}"
                    );
                }
            }
        }
    }

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
        let mut stepper = GaussStepper::new(tab);
        let (_, phi) = stepper
            .step(&eq, s, h, &y0, &DMatrix::identity(12, 12), None)
            .unwrap();
        let none = DMatrix::zeros(12, 0);
        for j in 0..12 {
            let (mut a, mut b) = (y0.clone(), y0.clone());
            a[j] += 1e-6;
            b[j] -= 1e-6;
            let ya = stepper.step(&eq, s, h, &a, &none, None).unwrap().0;
            let yb = stepper.step(&eq, s, h, &b, &none, None).unwrap().0;
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
