//! The smallest singular triplets of a large F_x in O(N) work and memory:
//! branch switching and Govaerts' bordered test on multiple shooting and
//! collocation, whose F_x is almost block diagonal
//! ([`crate::numerics::staircase::Staircase`]), without the dense SVD of
//! the small systems (O(N³) work, O(N²) memory).
//!
//! F_x is copied into general band storage by column probing (Curtis,
//! Powell & Reid, *J. Inst. Math. Appl.* 13 (1974) 117: columns 2B + 1
//! apart share no row of a matrix of half-bandwidth B, so 2B + 1 products
//! F_x e recover every entry), checked against the staircase's own
//! product, and F_x and F_xᵀ are factored by band LU with partial pivoting
//! ([`BandLu`]). The right singular vectors of the smallest singular
//! values come from subspace inverse iteration on F_xᵀF_x (Golub & Van
//! Loan, *Matrix Computations*, 4th ed., §8.2.4 and §8.6.1: each sweep
//! V ← orth(F_x⁻¹ F_x⁻ᵀ V)); the singular values and the left vectors
//! from the SVD of the thin product F_x V (Rayleigh–Ritz), O(N q²) for q
//! vectors. Own code, not a sparse SVD crate: the band LU is the one the
//! stepping already uses, and the transposed factor is its band copy.

use nalgebra::{DMatrix, DVector};

use crate::numerics::band_lu::BandLu;
use crate::numerics::staircase::Staircase;

/// Vectors iterated beyond the wanted ones: the subspace's error in the
/// k-th vector shrinks by (σ_k/σ_{k+GUARD+1})² per sweep.
const GUARD: usize = 2;

/// Inverse-iteration sweeps. At a located singular point σ_k/σ_{k+1} is
/// of the order of the location's tolerance, so the first sweep already
/// converges; the others serve the regular ends of a step, where only
/// borders that complement the kernel are needed.
const SWEEPS: usize = 6;

/// F_x in band storage, factored with its transpose.
#[derive(Debug, Clone)]
pub(super) struct BandedJacobian {
    /// The nonzero entries (row, column, value).
    entries: Vec<(usize, usize, f64)>,
    n: usize,
    lu: BandLu,
    lu_t: BandLu,
    frobenius: f64,
}

/// The k smallest singular values (ascending) of F_x with their right and
/// left vectors as the columns of n × k matrices.
#[derive(Debug, Clone)]
pub(super) struct SmallestSingular {
    /// σ_1 ≤ … ≤ σ_k.
    pub values: Vec<f64>,
    /// Right singular vectors (F_x v = σ u).
    pub right: DMatrix<f64>,
    /// Left singular vectors.
    pub left: DMatrix<f64>,
}

impl BandedJacobian {
    /// The band copy of `a`, factored with its transpose; None where the
    /// copy does not reproduce a's product (to 1e-12 of its size) or
    /// either factor meets an exactly zero pivot.
    pub fn of(a: &Staircase) -> Option<Self> {
        let n = a.size();
        let entries = probe(a);
        let (kl, ku) = entries.iter().fold((0, 0), |(kl, ku), &(i, j, _)| {
            (kl.max(i.saturating_sub(j)), ku.max(j.saturating_sub(i)))
        });
        let mut lu = BandLu::default();
        let mut lu_t = BandLu::default();
        lu.reset(n, kl, ku);
        lu_t.reset(n, ku, kl);
        let mut frobenius = 0.0;
        for &(i, j, v) in &entries {
            lu.add(i, j, v);
            lu_t.add(j, i, v);
            frobenius += v * v;
        }
        let mut banded = BandedJacobian {
            entries,
            n,
            lu,
            lu_t,
            frobenius: frobenius.sqrt(),
        };
        if !banded.reproduces(a) {
            return None;
        }
        // An exactly singular F_x (a fold located to round-off) is where
        // inverse iteration works best: a zero pivot is floored, not fatal.
        banded.lu.factor_for_inverse_iteration(f64::EPSILON).ok()?;
        banded
            .lu_t
            .factor_for_inverse_iteration(f64::EPSILON)
            .ok()?;
        Some(banded)
    }

    /// ‖F_x‖_F.
    pub fn frobenius(&self) -> f64 {
        self.frobenius
    }

    /// y = F_x x.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for &(i, j, v) in &self.entries {
            y[i] += v * x[j];
        }
    }

    /// Whether the copy's product with a fixed pseudo-random vector is
    /// the staircase's to 1e-12 of the product's size.
    fn reproduces(&self, a: &Staircase) -> bool {
        let x = start_vectors(self.n, 1);
        let (mut want, mut got) = (vec![0.0; self.n], vec![0.0; self.n]);
        a.mul(x.as_slice(), &mut want);
        self.apply(x.as_slice(), &mut got);
        let size = want.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
        let error = want
            .iter()
            .zip(&got)
            .fold(0.0, |m: f64, (a, b)| m.max((a - b).abs()));
        error.is_finite() && error <= 1e-12 * size.max(self.frobenius * 1e-300)
    }

    /// The `k` smallest singular triplets by subspace inverse iteration
    /// on F_xᵀF_x with [`GUARD`] extra vectors; None where k = 0, k + 1
    /// exceeds N or an iterate is not finite.
    pub fn smallest(&self, k: usize) -> Option<SmallestSingular> {
        let q = (k + GUARD).min(self.n);
        if k == 0 || k > q {
            return None;
        }
        let mut v = start_vectors(self.n, q);
        for _ in 0..SWEEPS {
            for mut column in v.column_iter_mut() {
                let c = column.as_mut_slice();
                self.lu_t.solve(c);
                self.lu.solve(c);
            }
            if !v.iter().all(|x| x.is_finite()) {
                return None;
            }
            v = v.qr().q();
        }
        // Rayleigh–Ritz: F_x V = U Σ Wᵀ, so the Ritz vectors are V W, U.
        let mut av = DMatrix::zeros(self.n, q);
        for (c, column) in v.column_iter().enumerate() {
            let mut y = vec![0.0; self.n];
            self.apply(column.as_slice(), &mut y);
            av.set_column(c, &DVector::from_vec(y));
        }
        let svd = av.svd(true, true);
        let (u, w_t) = (svd.u.as_ref()?, svd.v_t.as_ref()?);
        let mut order: Vec<usize> = (0..q).collect();
        order.sort_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]));
        let order = &order[..k];
        let right = DMatrix::from_fn(self.n, k, |r, c| {
            (0..q).map(|l| v[(r, l)] * w_t[(order[c], l)]).sum()
        });
        let left = DMatrix::from_fn(self.n, k, |r, c| u[(r, order[c])]);
        Some(SmallestSingular {
            values: order.iter().map(|&i| svd.singular_values[i]).collect(),
            right,
            left,
        })
    }
}

/// The entries of `a` by column probing: with B a bound of its
/// half-bandwidth, the columns j ≡ c (mod 2B + 1) are summed into one
/// probe, and row i of the product belongs to the one such column within
/// B of it.
fn probe(a: &Staircase) -> Vec<(usize, usize, f64)> {
    let n = a.size();
    let segments = a.segments();
    // Rows of segment j reach the columns of x_j and x_{j+1}'s coupling:
    // |i − j| ≤ 2·dim, dim ≤ ⌈N/(K − 1)⌉ (a single block is dense).
    let half = if segments > 1 {
        (2 * n.div_ceil(segments - 1)).min(n)
    } else {
        n
    };
    let width = (2 * half + 1).min(n);
    let mut entries = vec![];
    let (mut e, mut y) = (vec![0.0; n], vec![0.0; n]);
    for colour in 0..width {
        e.iter_mut()
            .enumerate()
            .for_each(|(j, v)| *v = f64::from(u8::from(j % width == colour)));
        a.mul(&e, &mut y);
        for (i, &v) in y.iter().enumerate() {
            if v == 0.0 {
                continue;
            }
            // The probed column within `half` of row i with this colour.
            let lo = i.saturating_sub(half);
            let j = lo + (colour + width - lo % width) % width;
            if j < n && j <= i + half {
                entries.push((i, j, v));
            }
        }
    }
    entries
}

/// `q` fixed pseudo-random start vectors (a 64-bit LCG, Knuth's MMIX
/// constants): the same on every run, so a resumed diagram switches as
/// the uninterrupted one.
fn start_vectors(n: usize, q: usize) -> DMatrix<f64> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    DMatrix::from_fn(n, q, |_, _| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        // The top 53 bits as a number in [−1, 1).
        (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A staircase of K segments with a prescribed pseudo-random fill.
    fn staircase(first: usize, dim: usize, segments: usize) -> Staircase {
        let mut a = Staircase::zeros(first, dim, segments);
        let mut s = 1.0_f64;
        for j in 0..segments {
            a.block_mut(j).iter_mut().for_each(|v| {
                s = (s * 7.3 + 0.31).fract();
                *v = s - 0.5;
            });
            if j + 1 < segments {
                a.coupling_mut(j).iter_mut().for_each(|v| *v = -1.0);
            }
        }
        a
    }

    #[test]
    fn band_copy_is_the_staircase() {
        for (first, dim, k) in [(2, 4, 1), (2, 4, 7), (4, 4, 30), (3, 9, 5)] {
            let a = staircase(first, dim, k);
            let b = BandedJacobian::of(&a).expect("a regular staircase");
            let dense = a.to_dense();
            let mut copy = DMatrix::zeros(a.size(), a.size());
            for &(i, j, v) in &b.entries {
                copy[(i, j)] += v;
            }
            assert_eq!(copy, dense, "first {first}, dim {dim}, K {k}");
        }
    }

    #[test]
    fn smallest_triplets_match_the_dense_svd() {
        let a = staircase(2, 4, 40);
        let b = BandedJacobian::of(&a).unwrap();
        let got = b.smallest(2).unwrap();
        let svd = a.to_dense().svd(true, true);
        let mut s: Vec<f64> = svd.singular_values.iter().copied().collect();
        s.sort_by(f64::total_cmp);
        for i in 0..2 {
            // Residuals of the triplet, F_x v = σ u, to round-off relative
            // to ‖F_x‖ (the Ritz values converge as (σ_2/σ_5)^(2·sweeps)).
            let mut av = vec![0.0; a.size()];
            b.apply(got.right.column(i).as_slice(), &mut av);
            let r = DVector::from_vec(av) - got.left.column(i) * got.values[i];
            assert!(r.norm() < 1e-8 * b.frobenius(), "residual {}", r.norm());
            assert!(
                (got.values[i] - s[i]).abs() <= 1e-8 * s[s.len() - 1],
                "σ_{i} {} against {}",
                got.values[i],
                s[i]
            );
        }
    }
}
