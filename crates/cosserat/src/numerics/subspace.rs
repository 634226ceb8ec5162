//! The lowest eigenpairs of a symmetric-definite banded pencil (K, G)
//! warm-started from the eigenvectors of a nearby pencil (the previous
//! point of a continuation branch): shift-invert subspace iteration with
//! Rayleigh–Ritz (Bathe & Wilson, Int. J. Numer. Meth. Eng. 5, 1973;
//! Saad, *Numerical Methods for Large Eigenvalue Problems*, 2nd ed.,
//! Sec. 5.2), certified by one Sturm count.
//!
//! From p = `count` + guard vectors V: the Ritz values θ of (VᵀKV, VᵀGV)
//! place a shift σ below θ₁, and each sweep is
//!
//!   W = (K − σG)⁻¹ G V,   (WᵀKW) s = θ (WᵀGW) s,   V ← W S,
//!
//! p banded solves and a p × p dense pencil: O(n) per sweep. The error of
//! λ_i shrinks by (λ_i − σ)/(λ_{p+1} − σ) per sweep, so from a nearby
//! start a few sweeps reach round-off. The first `count` pairs are accepted
//! as soon as their backward error ‖Kv − λGv‖/((‖K‖ + |λ|‖G‖)‖v‖) is at
//! most [`ACCEPT`] (already on the start vectors, without a sweep, when the
//! pencil has not moved them), and they are the `count` lowest only if exactly `count`
//! eigenvalues lie below τ, halfway from λ_count to the next Ritz value
//! (Sylvester's inertia of K − τG): converged, G-orthogonal pairs below τ
//! are then all of them. Anything else — a factorization that breaks down,
//! no convergence in [`SWEEPS`] sweeps, another count — is `None`, and the
//! caller runs the full solve ([`super::eigen`]); a warm start never
//! decides alone.
//!
//! The certificate also counts the eigenvalues below any σ < τ that no
//! pair's error interval reaches ([`WarmPairs::count_below`]): all
//! eigenvalues below τ are the certified pairs, so those below σ are the
//! pairs whose values lie below σ — the Morse index (σ = 0) without a
//! Sturm count of its own where the spectrum keeps clear of zero.

use super::banded::SymmetricBanded;
use super::eigen::{count_below, diagonal_ratio, dot, row_sum_norm, Eigenpairs, Inertia};

/// Backward error every accepted pair meets, as the Lanczos of
/// [`super::eigen`]; the sweeps stop at the first that meets it. The
/// eigenvalues, Rayleigh quotients, err by its square: on the Euler
/// column's branches (16 elements of order 2) pairs stopped at a backward
/// error of 2–5e-9 differ from the same pairs swept on to 1e-13 by 2e-12
/// (λ ≈ 2.5) and 4e-15 (λ ≈ 3e-7), and the diagram's stored eigenvalues
/// (|λ| ≤ 30) moved by at most 4.4e-11 when this rule replaced the one
/// below — far inside the eigenvalues' mesh error. (The sweeps used to aim at 1e-13 and stop early only when a
/// sweep gained less than a factor 10: where the shifted iteration
/// converges by a factor just under 10 a sweep, as on the buckled column,
/// that took 8–9 sweeps instead of 3–4 for no eigenvalue an event or a
/// stored column could tell apart; the events locate their zeros with the
/// full solve, [`super::eigen`].)
pub const ACCEPT: f64 = 1e-8;

/// Sweeps at most before the warm start gives up.
pub const SWEEPS: usize = 12;

/// Certified warm eigenpairs ([`lowest_eigenpairs_from`]): the pairs and
/// what certifies them.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmPairs {
    /// All p Ritz pairs in increasing order: the first `count` verified
    /// and certified the lowest, the rest the guard vectors.
    pub pairs: Eigenpairs,
    /// Pairs certified.
    count: usize,
    /// Exactly `count` eigenvalues of the pencil lie below τ (Sylvester).
    tau: f64,
    /// The bound on |λ − θ| of each certified pair (backward error times
    /// max K_ii/G_ii, see [`certified`]).
    bound: f64,
}

impl WarmPairs {
    /// The number of eigenvalues of the pencil below σ, read from the
    /// certificate: for σ < τ every eigenvalue below σ is one of the
    /// certified pairs, and a pair whose value θ lies farther than ten
    /// error bounds from σ is on the side of σ that θ is. None where σ is
    /// not below τ or some certified θ lies that close to σ (the caller
    /// counts by Sylvester's inertia instead).
    #[must_use]
    pub fn count_below(&self, sigma: f64) -> Option<usize> {
        let certified = &self.pairs.values[..self.count];
        let clear = certified
            .iter()
            .all(|&theta| (theta - sigma).abs() > 10.0 * self.bound);
        (sigma < self.tau && self.tau - sigma > 10.0 * self.bound && clear)
            .then(|| certified.iter().filter(|&&theta| theta < sigma).count())
    }
}

/// The `count` lowest eigenpairs of K v = λ G v from the start vectors
/// `start` (more than `count` of them, the extra ones guarding the
/// convergence of λ_count), or None when the warm start cannot vouch for
/// them (see the module documentation). On success all p Ritz pairs are
/// returned in increasing order ([`WarmPairs::pairs`]): the first `count`
/// verified and certified the lowest, the rest the guard vectors of the
/// next warm start; with their certificate.
pub fn lowest_eigenpairs_from(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    count: usize,
    start: &[Vec<f64>],
) -> Option<WarmPairs> {
    let n = k.size();
    let p = start.len();
    if count == 0 || p <= count || p > n || start.iter().any(|v| v.len() != n) {
        return None;
    }
    let scale = diagonal_ratio(k, g);
    let norms = (row_sum_norm(k), row_sum_norm(g));
    let mut ritz = Ritz::new(n, p);
    ritz.basis.clone_from_slice(start);
    for ((w, kw), gw) in ritz
        .basis
        .iter()
        .zip(&mut ritz.k_basis)
        .zip(&mut ritz.g_basis)
    {
        k.matvec(w, kw);
        g.matvec(w, gw);
    }
    ritz.project()?;
    let mut error = ritz.backward_error(count, norms);
    if error <= ACCEPT {
        return certified(k, g, count, ritz.into_pairs(), error * scale);
    }
    // Below θ₁ by a twentieth of its gap, or by half of it where that
    // shift is not below λ₁ (θ₁ ≥ λ₁ by Rayleigh–Ritz, and the start may
    // be far), never closer than 1e-6 of the wanted spread (as
    // [`super::eigen::shift_below`]: not 1e-8 of the spectrum's scale
    // ∝ N², which at 10⁵ elements put σ far below every wanted eigenvalue
    // and stalled the sweeps). The nearer shift converges λ_count at the
    // rate (λ_count − σ)/(λ_{p+1} − σ) with σ ≈ λ₁: on the buckled Euler
    // column 0.2 a sweep became 0.1.
    let spread = ritz.values[p - 1] - ritz.values[0];
    let gap = ritz.values[1] - ritz.values[0];
    let (sigma, shifted) = [0.05, 0.5].into_iter().find_map(|fraction| {
        let margin = (fraction * gap)
            .max(1e-3 * ritz.values[0].abs())
            .max(1e-6 * spread)
            .max(1e-14 * scale);
        let sigma = ritz.values[0] - margin;
        let shifted = k.shifted_ldlt(-sigma, g).ok()?;
        (shifted.negative_pivots() == 0).then_some((sigma, shifted))
    })?;
    for _ in 0..SWEEPS {
        // W = (K − σG)⁻¹ G V, G V known from the last projection, and
        // K W = (K − σG) W + σ G W = G V + σ G W without a product by K.
        for (((w, kw), gw), gv) in ritz
            .basis
            .iter_mut()
            .zip(&mut ritz.k_basis)
            .zip(&mut ritz.g_basis)
            .zip(&ritz.gv)
        {
            w.copy_from_slice(gv);
            shifted.solve_in_place(w);
            g.matvec(w, gw);
            kw.iter_mut()
                .zip(gv.iter().zip(gw.iter()))
                .for_each(|(a, (b, c))| *a = b + sigma * c);
        }
        ritz.project()?;
        error = ritz.backward_error(count, norms);
        if error <= ACCEPT {
            return certified(k, g, count, ritz.into_pairs(), error * scale);
        }
    }
    None
}

/// Rayleigh–Ritz on a basis W: the Ritz values and vectors V = W S with
/// their products K V and G V formed from K W and G W (no further
/// products), in buffers kept across sweeps.
struct Ritz {
    basis: Vec<Vec<f64>>,
    k_basis: Vec<Vec<f64>>,
    g_basis: Vec<Vec<f64>>,
    values: Vec<f64>,
    v: Vec<Vec<f64>>,
    kv: Vec<Vec<f64>>,
    gv: Vec<Vec<f64>>,
    /// The projected pencil and its solution ([`SmallPencil`]).
    pencil: SmallPencil,
}

impl Ritz {
    fn new(n: usize, p: usize) -> Self {
        let block = || vec![vec![0.0; n]; p];
        Ritz {
            basis: block(),
            k_basis: block(),
            g_basis: block(),
            values: vec![0.0; p],
            v: block(),
            kv: block(),
            gv: block(),
            pencil: SmallPencil::new(p),
        }
    }

    /// The Ritz pairs of (K, G) on span(basis) (with K and G times the
    /// basis already in `k_basis`, `g_basis`), in increasing order, with
    /// G-orthonormal vectors; None when the basis is (numerically)
    /// dependent.
    fn project(&mut self) -> Option<()> {
        let p = self.basis.len();
        let (w, kw, gw) = (&self.basis, &self.k_basis, &self.g_basis);
        // One product per pair i ≤ j; the lower triangle mirrors it.
        let pencil = &mut self.pencil;
        for (i, wi) in w.iter().enumerate() {
            for j in i..p {
                let (k, g) = (dot(wi, &kw[j]), dot(wi, &gw[j]));
                pencil.k[i * p + j] = k;
                pencil.k[j * p + i] = k;
                pencil.g[i * p + j] = g;
                pencil.g[j * p + i] = g;
            }
        }
        pencil.solve()?;
        for (slot, &col) in pencil.order.iter().enumerate() {
            self.values[slot] = pencil.values[col];
            let s = &pencil.vectors[col * p..(col + 1) * p];
            combine(w, s, &mut self.v[slot]);
            combine(kw, s, &mut self.kv[slot]);
            combine(gw, s, &mut self.gv[slot]);
        }
        Some(())
    }

    /// The largest backward error ‖Kv − λGv‖/((‖K‖ + |λ|‖G‖)‖v‖) of the
    /// first `count` pairs (`norms`: max row sums of K and G).
    fn backward_error(&self, count: usize, norms: (f64, f64)) -> f64 {
        (0..count)
            .map(|i| {
                let lambda = self.values[i];
                let r = self.kv[i]
                    .iter()
                    .zip(&self.gv[i])
                    .map(|(a, b)| (a - lambda * b).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let v = dot(&self.v[i], &self.v[i]).sqrt();
                r / ((norms.0 + lambda.abs() * norms.1) * v).max(f64::MIN_POSITIVE)
            })
            .fold(0.0, f64::max)
    }

    fn into_pairs(self) -> Eigenpairs {
        Eigenpairs {
            values: self.values,
            vectors: self.v,
        }
    }
}

/// The p × p symmetric-definite pencil (K_r, G_r) of a Rayleigh–Ritz
/// projection (p = the tracked eigenvalues and their guard, a handful),
/// solved in buffers kept across sweeps, with no allocation: G_r = L Lᵀ
/// (Cholesky), C = L⁻¹ K_r L⁻ᵀ symmetrized, C = Q Θ Qᵀ by cyclic Jacobi
/// rotations (Golub & Van Loan, *Matrix Computations*, 4th ed., Sec. 8.5:
/// eigenvalues to a few ulps of ‖C‖, as the QR algorithm), S = L⁻ᵀ Q
/// (G_r-orthonormal columns). At this size Jacobi's O(p³) per sweep is a
/// few hundred operations, and a general dense eigensolver's setup costs
/// more than the solve.
struct SmallPencil {
    p: usize,
    /// K_r and G_r, row-major; G_r's lower triangle becomes L.
    k: Vec<f64>,
    g: Vec<f64>,
    /// C, then Θ on its diagonal.
    c: Vec<f64>,
    /// The eigenvalues θ (unsorted) and S's columns (column j at
    /// `vectors[j p..(j + 1) p]`).
    values: Vec<f64>,
    vectors: Vec<f64>,
    /// The columns in increasing θ.
    order: Vec<usize>,
}

/// Jacobi sweeps at most; each squares the off-diagonal norm's relative
/// size once the rotations are small, so 4–6 reach round-off.
const JACOBI_SWEEPS: usize = 30;

impl SmallPencil {
    fn new(p: usize) -> Self {
        SmallPencil {
            p,
            k: vec![0.0; p * p],
            g: vec![0.0; p * p],
            c: vec![0.0; p * p],
            values: vec![0.0; p],
            vectors: vec![0.0; p * p],
            order: (0..p).collect(),
        }
    }

    /// The eigenpairs of the pencil in `k`, `g`; None where G_r is not
    /// positive definite (a dependent basis) or a value is not finite.
    fn solve(&mut self) -> Option<()> {
        let p = self.p;
        self.cholesky()?;
        // X = L⁻¹ K_r (column by column), then C = L⁻¹ Xᵀ = L⁻¹ K_r L⁻ᵀ.
        let (l, c) = (&self.g, &mut self.c);
        c.copy_from_slice(&self.k);
        for _ in 0..2 {
            for col in 0..p {
                for i in 0..p {
                    let mut v = c[i * p + col];
                    for j in 0..i {
                        v -= l[i * p + j] * c[j * p + col];
                    }
                    c[i * p + col] = v / l[i * p + i];
                }
            }
            // Transpose in place: the second pass solves for (L⁻¹ K_r)ᵀ.
            for i in 0..p {
                for j in 0..i {
                    c.swap(i * p + j, j * p + i);
                }
            }
        }
        for i in 0..p {
            for j in 0..i {
                let mean = 0.5 * (c[i * p + j] + c[j * p + i]);
                c[i * p + j] = mean;
                c[j * p + i] = mean;
            }
        }
        self.jacobi();
        // S = L⁻ᵀ Q, column by column (back substitution with Lᵀ).
        let l = &self.g;
        for col in 0..p {
            let s = &mut self.vectors[col * p..(col + 1) * p];
            for i in (0..p).rev() {
                let mut v = s[i];
                for j in i + 1..p {
                    v -= l[j * p + i] * s[j];
                }
                s[i] = v / l[i * p + i];
            }
        }
        if self.values.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let values = &self.values;
        self.order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        Some(())
    }

    /// G_r = L Lᵀ in place (L in the lower triangle of `g`); None where a
    /// pivot is not positive.
    fn cholesky(&mut self) -> Option<()> {
        let (p, g) = (self.p, &mut self.g);
        for j in 0..p {
            let mut d = g[j * p + j];
            for k in 0..j {
                d -= g[j * p + k] * g[j * p + k];
            }
            if d.is_nan() || d <= 0.0 {
                return None;
            }
            let d = d.sqrt();
            g[j * p + j] = d;
            for i in j + 1..p {
                let mut v = g[i * p + j];
                for k in 0..j {
                    v -= g[i * p + k] * g[j * p + k];
                }
                g[i * p + j] = v / d;
            }
        }
        Some(())
    }

    /// C = Q Θ Qᵀ by cyclic Jacobi: Θ into `values`, Q's columns into
    /// `vectors`, stopped when every off-diagonal entry is below round-off
    /// of its diagonal pair (or after [`JACOBI_SWEEPS`]).
    fn jacobi(&mut self) {
        let (p, a, q) = (self.p, &mut self.c, &mut self.vectors);
        q.fill(0.0);
        for i in 0..p {
            q[i * p + i] = 1.0;
        }
        for _ in 0..JACOBI_SWEEPS {
            let mut rotated = false;
            for i in 0..p {
                for j in i + 1..p {
                    let aij = a[i * p + j];
                    let (aii, ajj) = (a[i * p + i], a[j * p + j]);
                    if aij.abs() <= f64::EPSILON * 0.5 * (aii.abs() + ajj.abs()) || aij == 0.0 {
                        continue;
                    }
                    rotated = true;
                    // The rotation that zeroes a_ij (Golub & Van Loan,
                    // Alg. 8.5.1): t = tan of the smaller angle.
                    let tau = (ajj - aii) / (2.0 * aij);
                    let t = tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt());
                    let cs = 1.0 / (1.0 + t * t).sqrt();
                    let sn = t * cs;
                    for k in 0..p {
                        let (akj, aki) = (a[k * p + j], a[k * p + i]);
                        a[k * p + i] = cs * aki - sn * akj;
                        a[k * p + j] = sn * aki + cs * akj;
                    }
                    for k in 0..p {
                        let (ajk, aik) = (a[j * p + k], a[i * p + k]);
                        a[i * p + k] = cs * aik - sn * ajk;
                        a[j * p + k] = sn * aik + cs * ajk;
                    }
                    // Q's columns i and j (column c at q[c p..]).
                    for k in 0..p {
                        let (qi, qj) = (q[i * p + k], q[j * p + k]);
                        q[i * p + k] = cs * qi - sn * qj;
                        q[j * p + k] = sn * qi + cs * qj;
                    }
                }
            }
            if !rotated {
                break;
            }
        }
        for i in 0..p {
            self.values[i] = a[i * p + i];
        }
    }
}

/// out = Σ_j s_j w_j.
fn combine(w: &[Vec<f64>], s: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (wj, sj) in w.iter().zip(s) {
        out.iter_mut().zip(wj).for_each(|(o, x)| *o += sj * x);
    }
}

/// The pairs with their certificate, if exactly `count` eigenvalues lie
/// below τ halfway between
/// λ_count and the next Ritz value (which bounds λ_{count+1} from above),
/// and the half gap is well above the pairs' error `bound`: a backward
/// error β bounds |λ − θ| by ‖r‖_{G⁻¹} ≲ β·max K_ii/G_ii (the residual
/// measured against ‖K‖ ∝ 1/h and G ∝ h). The bound used to be 1e-9 of the
/// scale whatever the pairs' accuracy, ∝ N²: at 10⁵ elements a half gap of
/// 175 that no warm start met.
fn certified(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    count: usize,
    pairs: Eigenpairs,
    bound: f64,
) -> Option<WarmPairs> {
    let (last, next) = (pairs.values[count - 1], pairs.values[count]);
    let tau = 0.5 * (last + next);
    if tau - last <= 10.0 * bound {
        return None;
    }
    (count_below(k, g, tau) == Inertia::Below(count)).then_some(WarmPairs {
        pairs,
        count,
        tau,
        bound,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::eigen::lowest_eigenpairs;

    /// −u'' = λ u on (0, 1), u(0) = 0, u'(1) = 0 by linear elements:
    /// λ_j → ((2j − 1)π/2)², with a load term −q u'' shifting it.
    fn column(n: usize, q: f64) -> (SymmetricBanded, SymmetricBanded) {
        let h = 1.0 / n as f64;
        let (mut k, mut g) = (SymmetricBanded::zeros(n, 1), SymmetricBanded::zeros(n, 1));
        for e in 0..n {
            // Element between nodes e and e + 1 (node 0 clamped: index e − 1).
            let nodes = [e.checked_sub(1), Some(e)];
            for (a, ia) in nodes.iter().enumerate() {
                for (b, ib) in nodes.iter().enumerate() {
                    if let (Some(i), Some(j)) = (ia, ib) {
                        if i >= j {
                            let same = a == b;
                            let stiff = if same { 1.0 } else { -1.0 } * (1.0 - q) / h;
                            let mass = if same { h / 3.0 } else { h / 6.0 };
                            k.add(*i, *j, stiff);
                            g.add(*i, *j, mass);
                        }
                    }
                }
            }
        }
        (k, g)
    }

    /// The discrete eigenvalues of [`column`]: the modes sin(iθ_j) at the
    /// nodes, θ_j = (2j − 1)π/(2n), give
    /// λ_j = (1 − q) 6(1 − cos θ_j)/(h²(2 + cos θ_j)).
    fn column_eigenvalue(n: usize, q: f64, j: usize) -> f64 {
        let h = 1.0 / n as f64;
        let theta = (2 * j - 1) as f64 * std::f64::consts::PI / (2 * n) as f64;
        (1.0 - q) * 6.0 * (1.0 - theta.cos()) / (h * h * (2.0 + theta.cos()))
    }

    #[test]
    fn warm_start_finds_the_next_pencils_eigenvalues() {
        let (k0, g) = column(120, 0.0);
        let start = lowest_eigenpairs(&k0, &g, 4).unwrap();
        let (k1, _) = column(120, 0.02);
        let warm = lowest_eigenpairs_from(&k1, &g, 2, &start.vectors)
            .unwrap()
            .pairs;
        for j in 1..=2 {
            let exact = column_eigenvalue(120, 0.02, j);
            let rel = (warm.values[j - 1] - exact).abs() / exact;
            assert!(
                rel < 1e-12,
                "λ{j}: warm {} exact {exact}",
                warm.values[j - 1]
            );
        }
    }

    #[test]
    fn the_certificate_counts_the_eigenvalues_below_zero() {
        // K − 10 G: λ_1 = column_eigenvalue(1) − 10 ≈ −7.5 < 0 < λ_2 ≈ 12.2,
        // so one eigenvalue lies below 0 (Sylvester's count agrees).
        let (k0, g) = column(120, 0.0);
        let k = k0.combine(1.0, &g, -10.0);
        let start = lowest_eigenpairs(&k0, &g, 4).unwrap();
        let warm = lowest_eigenpairs_from(&k, &g, 2, &start.vectors).unwrap();
        let below = (1..=120)
            .filter(|&j| column_eigenvalue(120, 0.0, j) < 10.0)
            .count();
        assert_eq!(below, 1);
        assert_eq!(warm.count_below(0.0), Some(below));
        assert_eq!(count_below(&k, &g, 0.0), Inertia::Below(below));
        // At a certified value itself the sign is not read: undecided.
        assert_eq!(warm.count_below(warm.pairs.values[0]), None);
        // Beyond τ the certificate says nothing.
        assert_eq!(warm.count_below(warm.pairs.values[2]), None);
    }

    /// The projected pencil's solver: K = tridiag(−1, 2, −1) of size 5
    /// with G = 2 I has λ_j = (1 − cos(jπ/6)) (the discrete Laplacian's
    /// 2 − 2cos(jπ/(p + 1)), halved); with a full G (K and G mixed by a
    /// congruence X, which leaves the eigenvalues) the same values, the
    /// vectors G-orthonormal with K s = λ G s.
    #[test]
    fn the_small_pencil_has_the_laplacians_eigenvalues() {
        let p = 5;
        let laplacian = |i: usize, j: usize| match i.abs_diff(j) {
            0 => 2.0,
            1 => -1.0,
            _ => 0.0,
        };
        // X = I + 0.1·(i + 2j)/p² off the diagonal: invertible, not orthogonal.
        let x = |i: usize, j: usize| {
            if i == j {
                1.0
            } else {
                0.1 * (i + 2 * j) as f64 / (p * p) as f64
            }
        };
        for mixed in [false, true] {
            let mut pencil = SmallPencil::new(p);
            for i in 0..p {
                for j in 0..p {
                    // Xᵀ K X and Xᵀ (2I) X, or K and 2I.
                    let (mut k, mut g) = (0.0, 0.0);
                    for a in 0..p {
                        for b in 0..p {
                            let (xa, xb) = if mixed {
                                (x(a, i), x(b, j))
                            } else {
                                (f64::from(u8::from(a == i)), f64::from(u8::from(b == j)))
                            };
                            k += xa * laplacian(a, b) * xb;
                            g += xa * if a == b { 2.0 } else { 0.0 } * xb;
                        }
                    }
                    pencil.k[i * p + j] = k;
                    pencil.g[i * p + j] = g;
                }
            }
            let (k, g) = (pencil.k.clone(), pencil.g.clone());
            pencil.solve().expect("a definite pencil");
            for (rank, &col) in pencil.order.iter().enumerate() {
                let exact = 1.0 - ((rank + 1) as f64 * std::f64::consts::PI / 6.0).cos();
                let theta = pencil.values[col];
                assert!((theta - exact).abs() < 1e-14, "θ{rank} {theta} vs {exact}");
                let s = &pencil.vectors[col * p..(col + 1) * p];
                for i in 0..p {
                    let (ks, gs): (f64, f64) = (0..p)
                        .map(|j| (k[i * p + j] * s[j], g[i * p + j] * s[j]))
                        .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
                    assert!(
                        (ks - theta * gs).abs() < 1e-13,
                        "residual {}",
                        ks - theta * gs
                    );
                }
                for &other in &pencil.order {
                    let t = &pencil.vectors[other * p..(other + 1) * p];
                    let gst: f64 = (0..p)
                        .map(|i| s[i] * (0..p).map(|j| g[i * p + j] * t[j]).sum::<f64>())
                        .sum();
                    let expected = if other == col { 1.0 } else { 0.0 };
                    assert!((gst - expected).abs() < 1e-13, "sᵀGt = {gst}");
                }
            }
        }
    }

    #[test]
    fn a_start_that_misses_the_lowest_mode_is_refused() {
        // Start vectors spanning modes 2..5 of the pencil only: the Sturm
        // count at τ finds the lowest eigenvalue they miss.
        let (k, g) = column(120, 0.0);
        let modes = lowest_eigenpairs(&k, &g, 5).unwrap();
        let warm = lowest_eigenpairs_from(&k, &g, 2, &modes.vectors[1..]);
        assert!(warm.is_none());
    }
}
