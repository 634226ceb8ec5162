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

use nalgebra::DMatrix;

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
        let shifted = k.combine(1.0, g, -sigma).ldlt().ok()?;
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
        let (mut kr, mut gr) = (DMatrix::zeros(p, p), DMatrix::zeros(p, p));
        for i in 0..p {
            for j in i..p {
                kr[(i, j)] = dot(&w[i], &kw[j]);
                kr[(j, i)] = kr[(i, j)];
                gr[(i, j)] = dot(&w[i], &gw[j]);
                gr[(j, i)] = gr[(i, j)];
            }
        }
        let l_inv = gr.cholesky()?.l().try_inverse()?;
        let c = &l_inv * kr * l_inv.transpose();
        let eig = ((&c + c.transpose()) * 0.5).symmetric_eigen();
        if eig.eigenvalues.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut order: Vec<usize> = (0..p).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let s = l_inv.transpose() * &eig.eigenvectors;
        for (slot, &col) in order.iter().enumerate() {
            self.values[slot] = eig.eigenvalues[col];
            combine(w, s.column(col).as_slice(), &mut self.v[slot]);
            combine(kw, s.column(col).as_slice(), &mut self.kv[slot]);
            combine(gw, s.column(col).as_slice(), &mut self.gv[slot]);
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
