//! The collocation equations on one mesh and the condensed Newton step.
//!
//! Unknowns x = [u | y_1 … y_N | Y_0 … Y_{N−1}] (y_0 = y(0; u)); per
//! interval i of width h the residual is
//!
//!   Y_ij − y_i − h Σ_l a_jl f(s_i + c_l h, Y_il),   j = 1 … m,
//!   y_{i+1} − y_i − h Σ_j b_j f(s_i + c_j h, Y_ij),
//!
//! then the tip conditions g(y_N), all scaled by the state scales.
//!
//! The Newton matrix is condensed interval by interval (AMR §7.2.1): with
//! the stage matrix W = I − h (A ⊗ I) diag(J_j), J_j = ∂f/∂y at stage j,
//! the stage corrections are δY = v + Z δy_i with W Z = E (stacked
//! identities), which leaves δy_{i+1} − Γ_i δy_i = c_i with
//! Γ_i = I + h Σ_j b_j J_j Z_j. These node rows, δy_0 = S δu and the tip
//! rows form a banded system factored by [`BandLu`], so a Newton step
//! costs O(N). Also the starting unknowns (warm, IVP or straight rod) and
//! the conversion of converged unknowns into a [`CollocationSolution`].

use nalgebra::DMatrix;

use super::iteration::{Linearization, NewtonOutcome};
use super::lu::BandLu;
use super::stage_lu::StageSplit;

/// An output slice filled in order (the residual written in place).
struct Slots<'o> {
    out: &'o mut [f64],
    at: usize,
}

impl Slots<'_> {
    fn push(&mut self, v: f64) {
        self.out[self.at] = v;
        self.at += 1;
    }

    fn extend_from_slice(&mut self, v: &[f64]) {
        self.out[self.at..self.at + v.len()].copy_from_slice(v);
        self.at += v.len();
    }
}

use super::{CollocationSolution, Tableau};
use crate::equations::{RodEquations, RodSample};
use crate::numerics::integrator::{Dop853, Stops, Tolerances};

/// The collocation equations on one mesh. Unknown vector layout:
/// [u (p) | y_1 … y_N (n each) | Y_0 … Y_{N−1} (m·n each)].
pub(super) struct Grid<'a> {
    pub(super) eq: &'a dyn RodEquations,
    pub(super) tab: Tableau,
    pub(super) mesh: Vec<f64>,
    pub(super) n: usize,
    pub(super) p: usize,
    /// 1 / state scale, per component.
    pub(super) w: Vec<f64>,
    /// ∂y_0/∂u.
    pub(super) sens: DMatrix<f64>,
    /// The n × n identity, column-major: the tangent vectors that make
    /// `rhs_linearized` return the Jacobian ∂f/∂y (one call per point).
    pub(super) ident: Vec<f64>,
    /// The stage matrices' components without the position.
    pub(super) split: StageSplit,
    /// The place of each state component in a node's block of the band
    /// ([`StageSplit::band_order`]).
    band_order: Vec<usize>,
}

/// Buffers of one interval's stage computations, reused across intervals
/// and iterations (no allocation per interval).
pub(super) struct Scratch {
    /// f at the m stages (m·n).
    pub(super) f: Vec<f64>,
    /// ∂f/∂y at the m stages, each n × n column-major.
    pub(super) jac: Vec<f64>,
    /// The stage matrix W factored by [`StageSplit::factor`].
    pub(super) w: Vec<f64>,
    pub(super) piv: Vec<u8>,
    /// A stage-sized right-hand side (m·n).
    pub(super) g: Vec<f64>,
    /// W_CC⁻¹E_C of one interval, or the work of a stage solve.
    pub(super) z: Vec<f64>,
}

impl Scratch {
    pub(super) fn new(grid: &Grid) -> Self {
        let (n, m) = (grid.n, grid.tab.m);
        let mn = m * n;
        Scratch {
            f: vec![0.0; mn],
            jac: vec![0.0; m * n * n],
            w: vec![0.0; grid.split.len()],
            piv: vec![0; grid.split.coupled_rows()],
            g: vec![0.0; mn],
            z: vec![0.0; mn * n],
        }
    }
}

impl<'a> Grid<'a> {
    pub(super) fn new(eq: &'a dyn RodEquations, tab: Tableau, mesh: Vec<f64>) -> Self {
        let n = eq.dim();
        let split = StageSplit::new(n, tab.m, eq.quadrature_components());
        Grid {
            eq,
            tab,
            mesh,
            n,
            p: eq.unknowns(),
            w: eq.state_scales().iter().map(|v| 1.0 / v).collect(),
            sens: eq.initial_sensitivity(),
            ident: DMatrix::<f64>::identity(n, n).as_slice().to_vec(),
            band_order: split.band_order(),
            split,
        }
    }

    pub(super) fn intervals(&self) -> usize {
        self.mesh.len() - 1
    }

    pub(super) fn size(&self) -> usize {
        let (n, m, k) = (self.n, self.tab.m, self.intervals());
        self.p + n * k + m * n * k
    }

    /// Offset of the stage values of interval i.
    pub(super) fn stage_offset(&self, i: usize) -> usize {
        self.p + self.n * self.intervals() + i * self.tab.m * self.n
    }

    /// The node state y_i (y_0 from u).
    pub(super) fn node(&self, x: &[f64], i: usize) -> Vec<f64> {
        let (n, p) = (self.n, self.p);
        if i == 0 {
            let mut y0 = vec![0.0; n];
            self.eq.initial_state(&x[..p], &mut y0);
            y0
        } else {
            x[p + n * (i - 1)..p + n * i].to_vec()
        }
    }

    /// The node state y_i for i ≥ 1, or `y0` (y_0 computed by the caller).
    pub(super) fn node_ref<'x>(&self, x: &'x [f64], y0: &'x [f64], i: usize) -> &'x [f64] {
        let (n, p) = (self.n, self.p);
        if i == 0 {
            y0
        } else {
            &x[p + n * (i - 1)..p + n * i]
        }
    }

    pub(super) fn stages<'x>(&self, x: &'x [f64], i: usize) -> &'x [f64] {
        let o = self.stage_offset(i);
        &x[o..o + self.tab.m * self.n]
    }

    /// (s_i, h_i).
    pub(super) fn span(&self, i: usize) -> (f64, f64) {
        (self.mesh[i], self.mesh[i + 1] - self.mesh[i])
    }

    /// The starting unknowns: interpolated from a warm start, or else a
    /// cold start from the guessed clamp curvature u: the initial value
    /// problem from u integrated with DOP853 (tolerance 1e-8) through the
    /// nodes and stage points — for an unloaded rod that is its intrinsic
    /// shape, however much it spirals — with the straight rod beyond a
    /// blow-up; or, with `straight`, the straight rod.
    pub(super) fn start_from(
        &self,
        warm: Option<&CollocationSolution>,
        guess: Option<&[f64]>,
        straight: bool,
    ) -> Vec<f64> {
        let u = match warm {
            Some(w) => self.eq.unknowns_of(&w.states[0]),
            None => guess.map_or_else(|| self.eq.initial_guess(), <[f64]>::to_vec),
        };
        // Points in order: per interval its stage points, then its right node.
        let k = self.intervals();
        let mut points = Vec::with_capacity(k * (self.tab.m + 1));
        for i in 0..k {
            let (s, h) = self.span(i);
            points.extend(self.tab.c.iter().map(|c| s + c * h));
            points.push(self.mesh[i + 1]);
        }
        let (n, m) = (self.n, self.tab.m);
        let mut x = u;
        x.reserve(self.size());
        if let Some(w) = warm {
            // Interpolated straight into x: the nodes, then the stages.
            let (p, o) = (x.len(), x.len() + n * k);
            x.resize(self.size(), 0.0);
            for i in 0..k {
                for (j, &s) in points[i * (m + 1)..(i + 1) * (m + 1)].iter().enumerate() {
                    let r = if j == m {
                        p + n * i..p + n * (i + 1)
                    } else {
                        o + (i * m + j) * n..o + (i * m + j + 1) * n
                    };
                    w.interpolate_into(s, &mut x[r]);
                }
            }
            return x;
        }
        let states: Vec<Vec<f64>> = if straight {
            points.iter().map(|&s| self.eq.straight_state(s)).collect()
        } else {
            self.integrate_guess(&x, &points)
        };
        for i in 0..k {
            x.extend_from_slice(&states[i * (m + 1) + m]);
        }
        for i in 0..k {
            for j in 0..m {
                x.extend_from_slice(&states[i * (m + 1) + j]);
            }
        }
        debug_assert!(states.iter().all(|y| y.len() == n));
        debug_assert_eq!(x.len(), self.size());
        x
    }

    /// y(s; u) of the initial value problem at sorted `points`.
    pub(super) fn integrate_guess(&self, u: &[f64], points: &[f64]) -> Vec<Vec<f64>> {
        let n = self.n;
        let mut y = vec![0.0; n];
        self.eq.initial_state(u, &mut y);
        let tol = Tolerances {
            rtol: 1e-8,
            atol: 1e-8,
            max_steps: 100_000,
        };
        let eq = self.eq;
        let mut out = Vec::with_capacity(points.len());
        // Points read from the continuous extension: a fine mesh costs the
        // steps the tolerance needs, not one per point.
        let _ = Dop853::new(n).integrate_serving(
            |s, y: &[f64], d: &mut [f64]| eq.rhs(s, y, d),
            (0.0, eq.length(), n),
            &mut y,
            &tol,
            points,
            Stops::Interpolated,
            |_, y| out.push(y.to_vec()),
            |y| eq.project(y),
        );
        let usable = out.len().min(points.len());
        out.truncate(usable);
        let finite = out
            .iter()
            .position(|y| y.iter().any(|v| !v.is_finite()))
            .unwrap_or(usable);
        out.truncate(finite);
        out.extend(points[finite..].iter().map(|&s| eq.straight_state(s)));
        out
    }

    /// f at the m stages `st` of the step of width h from s, into `f`.
    pub(super) fn stage_rates(&self, s: f64, h: f64, st: &[f64], f: &mut [f64]) {
        let n = self.n;
        for (j, c) in self.tab.c.iter().enumerate() {
            let r = j * n..(j + 1) * n;
            self.eq.rhs(s + c * h, &st[r.clone()], &mut f[r]);
        }
    }

    /// f and ∂f/∂y at the m stages `st` (one `rhs_linearized` call each),
    /// into `f` and `jac` (n × n column-major per stage).
    pub(super) fn stage_jacobians(
        &self,
        s: f64,
        h: f64,
        st: &[f64],
        f: &mut [f64],
        jac: &mut [f64],
    ) {
        let n = self.n;
        for (j, c) in self.tab.c.iter().enumerate() {
            let r = j * n..(j + 1) * n;
            self.eq.rhs_linearized(
                s + c * h,
                &st[r.clone()],
                n,
                &self.ident,
                &mut f[r],
                &mut jac[j * n * n..(j + 1) * n * n],
            );
        }
    }

    /// The scaled residual into `out` (of the unknowns' size): per interval
    /// the m·n stage equations and the n node equations, then the p tip
    /// conditions.
    pub(super) fn residual_into(&self, x: &[f64], out: &mut [f64]) {
        let (n, m, p) = (self.n, self.tab.m, self.p);
        let mut r = Slots { out, at: 0 };
        let mut y0 = vec![0.0; n];
        self.eq.initial_state(&x[..p], &mut y0);
        let mut f = vec![0.0; m * n];
        for i in 0..self.intervals() {
            let (s, h) = self.span(i);
            let st = self.stages(x, i);
            self.stage_rates(s, h, st, &mut f);
            let y = self.node_ref(x, &y0, i);
            for j in 0..m {
                for k in 0..n {
                    let acc: f64 = (0..m).map(|l| self.tab.a(j, l) * f[l * n + k]).sum();
                    r.push((st[j * n + k] - y[k] - h * acc) * self.w[k]);
                }
            }
            let next = self.node_ref(x, &y0, i + 1);
            for k in 0..n {
                let acc: f64 = (0..m).map(|j| self.tab.b[j] * f[j * n + k]).sum();
                r.push((next[k] - y[k] - h * acc) * self.w[k]);
            }
        }
        let mut g = vec![0.0; p];
        self.eq
            .tip_residual(self.node_ref(x, &y0, self.intervals()), &mut g);
        r.extend_from_slice(&g);
    }

    /// Storage for the Newton matrix of this mesh.
    pub(super) fn new_linearization(&self) -> Linearization {
        let (n, p, k) = (self.n, self.p, self.intervals());
        Linearization {
            lu: vec![0.0; k * self.split.len()],
            piv: vec![0; k * self.split.coupled_rows()],
            band: BandLu::zeros(p + n * k, self.band_lower(), p),
            valid: false,
        }
    }

    /// The lower half-bandwidth of the condensed node system: unknowns
    /// [δu | δy_1 … δy_N], each node's components in [`Self::band_order`],
    /// rows the node equations w (δy_{i+1} − Γ_i δy_i) in the same order,
    /// then the tip. Row n·i + π(r) meets column p + n(i − 1) + π(c) where
    /// Γ_i[r, c] ≠ 0, n − p + π(r) − π(c) below the diagonal: at most
    /// n − p + n − 1 − |P| (Γ[C, C], with C after P), and the first node
    /// rows and the tip rows at most n − 1 below. Above it, the identity
    /// of δy_{i+1} is p to the right of its row and nothing further.
    fn band_lower(&self) -> usize {
        let (n, p) = (self.n, self.p);
        (n - 1).max(2 * n - 1 - p - self.split.quadrature_count())
    }

    /// The Newton matrix at x, condensed and factored into `lin` (reusing
    /// its storage); false if singular.
    pub(super) fn linearize(&self, x: &[f64], lin: &mut Linearization, ws: &mut Scratch) -> bool {
        lin.valid = false;
        let (n, p, k) = (self.n, self.p, self.intervals());
        lin.band.clear();
        let mut gamma = vec![0.0; n * n];
        let mut gamma0 = vec![0.0; n * p];
        for i in 0..k {
            if !self.condense(i, self.stages(x, i), lin, ws, &mut gamma) {
                return false;
            }
            let (g, cols): (&[f64], usize) = if i == 0 {
                // Γ_0 S (n × p, row-major).
                for r in 0..n {
                    for c in 0..p {
                        gamma0[r * p + c] =
                            (0..n).map(|q| gamma[r * n + q] * self.sens[(q, c)]).sum();
                    }
                }
                (&gamma0, p)
            } else {
                (&gamma, n)
            };
            let order = &self.band_order;
            for r in 0..n {
                let row = n * i + order[r];
                // Γ's structural zeros (Γ[C, P], off the diagonal of
                // Γ[P, P]) lie outside the band: only the rest is added.
                for c in (0..cols).filter(|&c| g[r * cols + c] != 0.0) {
                    let col = if i == 0 {
                        c
                    } else {
                        p + n * (i - 1) + order[c]
                    };
                    lin.band.add(row, col, -g[r * cols + c] * self.w[r]);
                }
                lin.band.add(row, p + n * i + order[r], self.w[r]);
            }
        }
        let y_tip = self.node(x, k);
        let gt = self.eq.tip_residual_jacobian(&y_tip);
        for r in 0..p {
            for c in 0..n {
                let col = p + n * (k - 1) + self.band_order[c];
                lin.band.add(n * k + r, col, gt[(r, c)]);
            }
        }
        lin.valid = lin.band.factor().is_ok();
        lin.valid
    }

    /// Condensation of interval i into `lin`: δY = v + Z δy_i with W Z = E
    /// (stacked identities), and with the node row less Σ_j d_j times the
    /// stage rows, y_{i+1} − y_i − Σ_j d_j (Y_j − y_i) (d = A⁻ᵀb, AMR §7.2.1
    /// with the rows combined), Γ = (1 − Σ_j d_j) I + Σ_j d_j Z_j, into
    /// `gamma` (n × n, row-major); false if W is singular.
    pub(super) fn condense(
        &self,
        i: usize,
        st: &[f64],
        lin: &mut Linearization,
        ws: &mut Scratch,
        gamma: &mut [f64],
    ) -> bool {
        let (s, h) = self.span(i);
        let (len, rows) = (self.split.len(), self.split.coupled_rows());
        self.stage_jacobians(s, h, st, &mut ws.f, &mut ws.jac);
        let lu = &mut lin.lu[i * len..(i + 1) * len];
        let piv = &mut lin.piv[i * rows..(i + 1) * rows];
        self.split.factor(&self.tab, h, &ws.jac, lu, piv)
            && self.split.node_map(&self.tab, h, lu, piv, gamma, &mut ws.z)
    }

    /// The factors of interval i's stage matrix in `lin`.
    fn stage_factors<'l>(&self, lin: &'l Linearization, i: usize) -> (&'l [f64], &'l [u8]) {
        let (len, rows) = (self.split.len(), self.split.coupled_rows());
        (
            &lin.lu[i * len..(i + 1) * len],
            &lin.piv[i * rows..(i + 1) * rows],
        )
    }

    /// −J⁻¹F for a scaled residual F, in the unknowns' layout: the node
    /// corrections ([`Self::node_correction`]), then per interval the
    /// stages δY = W⁻¹(−F_stages + E δy_i).
    pub(super) fn newton_correction(&self, lin: &Linearization, f: &[f64], dx: &mut [f64]) {
        let (n, m, p, k) = (self.n, self.tab.m, self.p, self.intervals());
        let mn = m * n;
        let (head, stages) = dx.split_at_mut(p + n * k);
        let mut work = vec![0.0; 2 * mn];
        self.node_correction(lin, f, head, &mut work);
        let dy0 = self.clamp_correction(head);
        for (i, out) in stages.chunks_exact_mut(mn).enumerate() {
            let dyi = if i == 0 {
                &dy0[..]
            } else {
                &head[p + n * (i - 1)..p + n * i]
            };
            self.stage_correction(lin, f, i, dyi, out, &mut work[..mn]);
        }
    }

    /// [`Self::step_norm`] of −J⁻¹F without keeping its stages: the node
    /// corrections into `head` (p + n·N numbers), each interval's stages
    /// in turn into a buffer of one interval. The sum runs in the order
    /// of [`Self::step_norm`], so the norm is the same to the last bit.
    pub(super) fn correction_norm(&self, lin: &Linearization, f: &[f64], head: &mut [f64]) -> f64 {
        let (n, m, p) = (self.n, self.tab.m, self.p);
        let mn = m * n;
        let mut work = vec![0.0; 2 * mn];
        self.node_correction(lin, f, head, &mut work);
        let dy0 = self.clamp_correction(head);
        let clamp: f64 = dy0
            .iter()
            .enumerate()
            .map(|(r, d)| (d * self.w[r]).powi(2))
            .sum();
        let mut rest = 0.0;
        for (q, d) in head[p..].iter().enumerate() {
            rest += (d * self.w[q % n]).powi(2);
        }
        let (g, work) = work.split_at_mut(mn);
        for i in 0..self.intervals() {
            let dyi = if i == 0 {
                &dy0[..]
            } else {
                &head[p + n * (i - 1)..p + n * i]
            };
            self.stage_correction(lin, f, i, dyi, g, work);
            for (r, d) in g.iter().enumerate() {
                rest += (d * self.w[r % n]).powi(2);
            }
        }
        (clamp + rest).sqrt()
    }

    /// The node part [δu | δy_1 … δy_N] of −J⁻¹F into `head`: per interval
    /// v = W⁻¹(−F_stages), the combined node row's right-hand side
    /// −F_node + Σ_j d_j (F_stage_j − v_j), then the banded solve; `work`
    /// holds 2·m·n numbers.
    fn node_correction(&self, lin: &Linearization, f: &[f64], head: &mut [f64], work: &mut [f64]) {
        let (n, m, p, k) = (self.n, self.tab.m, self.p, self.intervals());
        let mn = m * n;
        let d = &self.tab.d;
        let (v, work) = work.split_at_mut(mn);
        for i in 0..k {
            let base = i * (m + 1) * n;
            v.iter_mut()
                .enumerate()
                .for_each(|(r, a)| *a = -f[base + r] / self.w[r % n]);
            let (lu, piv) = self.stage_factors(lin, i);
            self.split
                .solve(&self.tab, self.span(i).1, lu, piv, v, work);
            for r in 0..n {
                let mut acc = -f[base + mn + r] / self.w[r];
                for (j, dj) in d.iter().enumerate() {
                    acc += dj * (f[base + j * n + r] / self.w[r] + v[j * n + r]);
                }
                head[n * i + self.band_order[r]] = acc * self.w[r];
            }
        }
        for q in 0..p {
            head[n * k + q] = -f[k * (m + 1) * n + q];
        }
        lin.band.solve(head);
        self.unpermute_nodes(&mut head[p..]);
    }

    /// δy_0 = S δu.
    fn clamp_correction(&self, head: &[f64]) -> Vec<f64> {
        (0..self.n)
            .map(|r| (0..self.p).map(|c| self.sens[(r, c)] * head[c]).sum())
            .collect()
    }

    /// Interval i's stage correction δY = W⁻¹(−F_stages + E δy_i) into
    /// `out` (m·n numbers); `work` holds m·n.
    fn stage_correction(
        &self,
        lin: &Linearization,
        f: &[f64],
        i: usize,
        dyi: &[f64],
        out: &mut [f64],
        work: &mut [f64],
    ) {
        let (n, m) = (self.n, self.tab.m);
        let base = i * (m + 1) * n;
        for (r, a) in out.iter_mut().enumerate() {
            *a = -f[base + r] / self.w[r % n] + dyi[r % n];
        }
        let (lu, piv) = self.stage_factors(lin, i);
        self.split
            .solve(&self.tab, self.span(i).1, lu, piv, out, work);
    }

    /// The node states of the band's solution back in state order.
    fn unpermute_nodes(&self, nodes: &mut [f64]) {
        let order = &self.band_order;
        if order.iter().enumerate().all(|(k, &slot)| k == slot) {
            return;
        }
        let mut node = vec![0.0; self.n];
        for block in nodes.chunks_exact_mut(self.n) {
            node.iter_mut()
                .zip(order)
                .for_each(|(v, &slot)| *v = block[slot]);
            block.copy_from_slice(&node);
        }
    }

    /// The typical magnitude of each unknown: the free initial values in
    /// the scale of the state component they set, node states in the
    /// state scales.
    pub(super) fn unknown_scales(&self) -> Vec<f64> {
        let (n, p) = (self.n, self.p);
        let total = p + n * self.intervals();
        (0..total)
            .map(|q| {
                let row = if q < p {
                    (0..n).find(|&r| self.sens[(r, q)] != 0.0).unwrap_or(0)
                } else {
                    (q - p) % n
                };
                1.0 / self.w[row]
            })
            .collect()
    }

    /// A weighted Euclidean norm of a correction (δy_0 = S δu, nodes and
    /// stages, each component divided by its scale).
    pub(super) fn step_norm(&self, dx: &[f64]) -> f64 {
        let (n, p) = (self.n, self.p);
        let head: f64 = (0..n)
            .map(|r| {
                let d: f64 = (0..p).map(|c| self.sens[(r, c)] * dx[c]).sum();
                (d * self.w[r]).powi(2)
            })
            .sum();
        let rest: f64 = dx[p..]
            .iter()
            .enumerate()
            .map(|(q, d)| (d * self.w[q % n]).powi(2))
            .sum();
        (head + rest).sqrt()
    }

    /// Node states and stage values of x, with empty statistics.
    pub(super) fn solution_parts(&self, x: &[f64]) -> CollocationSolution {
        CollocationSolution {
            mesh: self.mesh.clone(),
            states: (0..=self.intervals()).map(|i| self.node(x, i)).collect(),
            iterations: 0,
            residual: f64::NAN,
            residual_history: Vec::new(),
            newton_steps: 0,
            damped_steps: 0,
            contraction: 0.0,
            error_estimate: f64::NAN,
            director_drift: 0.0,
            stage_values: (0..self.intervals())
                .map(|i| self.stages(x, i).to_vec())
                .collect(),
            stage_count: self.tab.m,
        }
    }

    /// The solution with Newton's statistics, the error estimate and the
    /// director drift.
    pub(super) fn solution(&self, out: &NewtonOutcome, errors: &[f64]) -> CollocationSolution {
        let mut sol = self.solution_parts(&out.x);
        sol.iterations = out.iterations;
        sol.residual = *out.history.last().unwrap_or(&f64::NAN);
        sol.residual_history.clone_from(&out.history);
        sol.error_estimate = errors.iter().sum();
        if self.n == 12 {
            sol.director_drift = sol
                .samples(self.eq)
                .iter()
                .map(RodSample::director_drift)
                .fold(0.0, f64::max);
        }
        sol
    }
}
