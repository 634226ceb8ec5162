//! The stage matrix of one interval, factored without the position.
//!
//! The stage block of the Newton matrix is W = I − h (A ⊗ I) diag(J_l),
//! J_l = ∂f/∂y at stage l (stage-major: row j·n + k is component k of
//! stage j). The right-hand side never depends on the centreline position
//! P ([`crate::equations::RodEquations::quadrature_components`]: dead
//! loads make the equations translation invariant), so the columns of W
//! for P are those of the identity, and with the other components C
//!
//!   W = [W_CC 0; W_PC I],   W_PC = −h (A ⊗ I) diag(J_l[P, C]).
//!
//! W x = b is then W_CC x_C = b_C, by dense LU with row partial pivoting
//! of m·|C| rows (m·2 planar, m·9 spatial, instead of m·n), and
//! x_P = b_P + h (A ⊗ I) diag(J_l[P, C]) x_C. Kept per interval: the
//! factors of W_CC, their interchanges and the blocks J_l[P, C] — for
//! order 6, 48 numbers instead of W's 144 planar, 810 instead of 1296
//! spatial — and the work of a factorization is an eighth (planar).

use std::ops::Range;

use super::lu::{dense_lu, dense_solve, dense_solve_rows};
use super::tableau::Tableau;

/// How the state's components enter the stage matrix: the coupled ones C
/// and the quadrature ones P.
#[derive(Debug, Clone)]
pub(super) struct StageSplit {
    n: usize,
    m: usize,
    /// C, in order.
    coupled: Vec<usize>,
    /// P, a range of components f does not depend on.
    quadrature: Range<usize>,
}

impl StageSplit {
    /// The split of n components, m stages, P = `quadrature`.
    pub(super) fn new(n: usize, m: usize, quadrature: Range<usize>) -> Self {
        assert!(
            quadrature.end <= n,
            "quadrature components within the state"
        );
        StageSplit {
            n,
            m,
            coupled: (0..n).filter(|k| !quadrature.contains(k)).collect(),
            quadrature,
        }
    }

    /// Where each component goes in a node's block of the condensed band
    /// (`grid.rs`): P first, then C, so that the node map Γ, whose
    /// Γ[P, P] = I and Γ[C, P] = 0, is block upper triangular but for
    /// Γ[C, C] and the band's lower half-bandwidth shrinks by |P| (the
    /// identity where P comes first, as planar).
    pub(super) fn band_order(&self) -> Vec<usize> {
        let mut order = vec![0; self.n];
        for (slot, k) in self
            .quadrature
            .clone()
            .chain(self.coupled.iter().copied())
            .enumerate()
        {
            order[k] = slot;
        }
        order
    }

    /// |P|.
    pub(super) fn quadrature_count(&self) -> usize {
        self.quadrature.len()
    }

    /// Rows of W_CC, m·|C|: the interchanges kept per interval.
    pub(super) fn coupled_rows(&self) -> usize {
        self.m * self.coupled.len()
    }

    /// Numbers kept per interval: the factors of W_CC, then the m blocks
    /// J_l[P, C] (|P| × |C| each, row-major).
    pub(super) fn len(&self) -> usize {
        let rows = self.coupled_rows();
        rows * rows + self.m * self.quadrature.len() * self.coupled.len()
    }

    /// Factors W of an interval of width h with stage Jacobians `jac` (m
    /// blocks n × n, column-major) into `out` ([`Self::len`] numbers) and
    /// `piv` ([`Self::coupled_rows`]); false if W_CC is singular.
    pub(super) fn factor(
        &self,
        tab: &Tableau,
        h: f64,
        jac: &[f64],
        out: &mut [f64],
        piv: &mut [u8],
    ) -> bool {
        let (n, m, nc) = (self.n, self.m, self.coupled.len());
        let rows = m * nc;
        let (w, blocks) = out.split_at_mut(rows * rows);
        for j in 0..m {
            for l in 0..m {
                let coef = h * tab.a(j, l);
                let jl = &jac[l * n * n..(l + 1) * n * n];
                for (ri, &r) in self.coupled.iter().enumerate() {
                    let at = (j * nc + ri) * rows + l * nc;
                    for (ci, (v, &c)) in w[at..at + nc].iter_mut().zip(&self.coupled).enumerate() {
                        let id = if j == l && ri == ci { 1.0 } else { 0.0 };
                        *v = id - jl[c * n + r] * coef;
                    }
                }
            }
        }
        let mut at = 0;
        for l in 0..m {
            for a in self.quadrature.clone() {
                for &c in &self.coupled {
                    blocks[at] = jac[l * n * n + c * n + a];
                    at += 1;
                }
            }
        }
        dense_lu(w, rows, piv)
    }

    /// b ← W⁻¹ b (m·n numbers, stage-major) with the factors of
    /// [`Self::factor`] at width h; `work` holds m·|C| numbers.
    pub(super) fn solve(
        &self,
        tab: &Tableau,
        h: f64,
        factors: &[f64],
        piv: &[u8],
        b: &mut [f64],
        work: &mut [f64],
    ) {
        let (n, m, nc) = (self.n, self.m, self.coupled.len());
        let rows = m * nc;
        let (w, blocks) = factors.split_at(rows * rows);
        let xc = &mut work[..rows];
        for j in 0..m {
            for (v, &c) in xc[j * nc..(j + 1) * nc].iter_mut().zip(&self.coupled) {
                *v = b[j * n + c];
            }
        }
        dense_solve(w, rows, piv, xc);
        // x_P,j = b_P,j + h Σ_l a_jl J_l[P, C] x_C,l.
        let np = self.quadrature.len();
        for j in 0..m {
            for (a, k) in self.quadrature.clone().enumerate() {
                let mut acc = 0.0;
                for l in 0..m {
                    let g = &blocks[(l * np + a) * nc..(l * np + a + 1) * nc];
                    let t: f64 = g
                        .iter()
                        .zip(&xc[l * nc..(l + 1) * nc])
                        .map(|(g, x)| g * x)
                        .sum();
                    acc += tab.a(j, l) * t;
                }
                b[j * n + k] += h * acc;
            }
        }
        for j in 0..m {
            for (v, &c) in xc[j * nc..(j + 1) * nc].iter().zip(&self.coupled) {
                b[j * n + c] = *v;
            }
        }
    }

    /// Γ = (1 − Σ_j d_j) I + Σ_j d_j Z_j with W Z = E (stacked
    /// identities), the condensed node map (`grid.rs`), into `gamma`
    /// (n × n, row-major); `z` holds m·|C|·|C| numbers. By the split,
    /// Γ[P, P] = I and Γ[C, P] = 0 exactly, Γ[C, C] comes from
    /// Z_C = W_CC⁻¹ E_C, and Γ[P, C] = h Σ_l b_l J_l[P, C] Z_C,l (since
    /// Aᵀd = b). False if Z is not finite.
    pub(super) fn node_map(
        &self,
        tab: &Tableau,
        h: f64,
        factors: &[f64],
        piv: &[u8],
        gamma: &mut [f64],
        z: &mut [f64],
    ) -> bool {
        let (n, m, nc) = (self.n, self.m, self.coupled.len());
        let rows = m * nc;
        let (w, blocks) = factors.split_at(rows * rows);
        let z = &mut z[..rows * nc];
        for (r, row) in z.chunks_exact_mut(nc).enumerate() {
            row.iter_mut()
                .enumerate()
                .for_each(|(c, v)| *v = if r % nc == c { 1.0 } else { 0.0 });
        }
        dense_solve_rows(w, rows, piv, z, nc);
        if !z.iter().all(|v| v.is_finite()) {
            return false;
        }
        gamma.fill(0.0);
        let d = &tab.d;
        let keep = 1.0 - d.iter().sum::<f64>();
        for (ri, &r) in self.coupled.iter().enumerate() {
            for (ci, &c) in self.coupled.iter().enumerate() {
                let g = &mut gamma[r * n + c];
                *g = if ri == ci { keep } else { 0.0 };
                for (j, dj) in d.iter().enumerate() {
                    *g += dj * z[(j * nc + ri) * nc + ci];
                }
            }
        }
        let np = self.quadrature.len();
        for (a, k) in self.quadrature.clone().enumerate() {
            gamma[k * n + k] = 1.0;
            for (ci, &c) in self.coupled.iter().enumerate() {
                let mut acc = 0.0;
                for (l, bl) in tab.b.iter().enumerate() {
                    let g = &blocks[(l * np + a) * nc..(l * np + a + 1) * nc];
                    let t: f64 = g
                        .iter()
                        .enumerate()
                        .map(|(q, g)| g * z[(l * nc + q) * nc + ci])
                        .sum();
                    acc += bl * t;
                }
                gamma[k * n + c] = h * acc;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    fn random(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }

    /// Stage Jacobians with zero columns at P, and the whole W = I −
    /// h (A ⊗ I) diag(J_l) as a dense matrix.
    fn stage_problem(n: usize, m: usize, p: Range<usize>, h: f64) -> (Vec<f64>, DMatrix<f64>) {
        let tab = Tableau::gauss(m).unwrap();
        let mut seed = 31u64 + n as u64;
        let mut jac = vec![0.0; m * n * n];
        for l in 0..m {
            for c in 0..n {
                for r in 0..n {
                    if !p.contains(&c) {
                        jac[l * n * n + c * n + r] = 4.0 * random(&mut seed);
                    }
                }
            }
        }
        let w = DMatrix::from_fn(m * n, m * n, |row, col| {
            let (j, r, l, c) = (row / n, row % n, col / n, col % n);
            let id = if row == col { 1.0 } else { 0.0 };
            id - h * tab.a(j, l) * jac[l * n * n + c * n + r]
        });
        (jac, w)
    }

    /// The split solve and node map against nalgebra's LU of the whole W,
    /// planar (P = 0..2 of 4) and spatial (P = 9..12 of 12), and with no
    /// split.
    #[test]
    fn split_solve_matches_the_whole_stage_matrix() {
        for (n, p) in [(4, 0..2), (12, 9..12), (6, 0..0)] {
            for m in 1..=3 {
                let (h, tab) = (0.3, Tableau::gauss(m).unwrap());
                let (jac, w) = stage_problem(n, m, p.clone(), h);
                let split = StageSplit::new(n, m, p.clone());
                let mut factors = vec![0.0; split.len()];
                let mut piv = vec![0u8; split.coupled_rows()];
                assert!(split.factor(&tab, h, &jac, &mut factors, &mut piv));
                let mut seed = 7u64;
                let b: Vec<f64> = (0..m * n).map(|_| random(&mut seed)).collect();
                let exact = w
                    .clone()
                    .lu()
                    .solve(&DVector::from_column_slice(&b))
                    .unwrap();
                let (mut x, mut work) = (b.clone(), vec![0.0; m * n]);
                split.solve(&tab, h, &factors, &piv, &mut x, &mut work);
                let err = (DVector::from_column_slice(&x) - &exact).amax();
                assert!(err < 1e-12, "n {n} m {m}: solve {err}");
                let e = DMatrix::from_fn(m * n, n, |row, c| if row % n == c { 1.0 } else { 0.0 });
                let z = w.lu().solve(&e).unwrap();
                let keep = 1.0 - tab.d.iter().sum::<f64>();
                let want = DMatrix::from_fn(n, n, |r, c| {
                    let id = if r == c { keep } else { 0.0 };
                    id + (0..m).map(|j| tab.d[j] * z[(j * n + r, c)]).sum::<f64>()
                });
                let (mut gamma, mut zs) = (vec![0.0; n * n], vec![0.0; m * n * n]);
                assert!(split.node_map(&tab, h, &factors, &piv, &mut gamma, &mut zs));
                let err = (DMatrix::from_row_slice(n, n, &gamma) - want).amax();
                assert!(err < 1e-12, "n {n} m {m}: node map {err}");
            }
        }
    }
}
