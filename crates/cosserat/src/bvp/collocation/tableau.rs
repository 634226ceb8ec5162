//! The Gauss–Legendre Butcher tableau and the Lagrange basis of the
//! collocation polynomial.
//!
//! With the m Gauss points c_1 … c_m of [0, 1] and the Lagrange basis ℓ_l
//! on them, a_jl = ∫_0^{c_j} ℓ_l and b_l = ∫_0^1 ℓ_l (AMR §5.6.1): stage
//! order m, order 2m at the nodes. The basis on (0, c_1 … c_m) evaluates
//! the collocation polynomial of an interval between its node and stages
//! (interpolation of a solution, the half steps of the error estimate).
//! The tableau is shared with the Gauss steps of shooting.

/// The Butcher tableau of Gauss–Legendre collocation with m stages:
/// a_jl = ∫_0^{c_j} ℓ_l, b_l = ∫_0^1 ℓ_l for the Lagrange basis ℓ_l on the
/// Gauss points c (AMR §5.6.1).
#[derive(Debug, Clone)]
pub(crate) struct Tableau {
    pub(crate) m: usize,
    pub(crate) c: Vec<f64>,
    /// m × m, row-major.
    a: Vec<f64>,
    pub(crate) b: Vec<f64>,
    /// d = A⁻ᵀ b: the node equation less Σ_j d_j times stage equation j is
    /// y_{i+1} − y_i − Σ_j d_j (Y_j − y_i), linear (no f), so the condensed
    /// Newton step needs no stage Jacobians after the condensation.
    pub(crate) d: Vec<f64>,
    /// A block-diagonalized by a real similarity (the Kronecker form of
    /// the stage Newton matrix).
    pub(crate) blocks: StageBlocks,
    /// A⁻¹, m × m row-major.
    a_inv: Vec<f64>,
}

/// A = T Λ T⁻¹ with Λ real block diagonal: the real eigenvalue γ of A
/// (m odd) first, then the 2 × 2 block [[α, β], [−β, α]] of a complex
/// pair α ± iβ (m ≥ 2), whose eigenvector u + iw gives T's columns u, w
/// (A u = α u − β w, A w = β u + α w). With one Jacobian J for all
/// stages, (T⁻¹ ⊗ I)(I − h A ⊗ J)(T ⊗ I) = I − h Λ ⊗ J splits into
/// I − hγJ (n × n) and [[I − hαJ, −hβJ], [hβJ, I − hαJ]] (2n × 2n),
/// the simplified Newton matrix of the stage equations factored in
/// O(n³ + (2n)³) instead of O((mn)³) (Hairer & Wanner II, §IV.8).
#[derive(Debug, Clone)]
pub(crate) struct StageBlocks {
    /// T, m × m row-major.
    pub(crate) t: Vec<f64>,
    /// T⁻¹, m × m row-major.
    pub(crate) t_inv: Vec<f64>,
    /// The real eigenvalue γ (m = 1, 3).
    pub(crate) real: Option<f64>,
    /// The complex pair (α, β), β > 0 (m = 2, 3).
    pub(crate) pair: Option<(f64, f64)>,
}

impl StageBlocks {
    /// The real block form of the m × m matrix `a` (row-major, m ≤ 3,
    /// at most one complex pair); None if it has none of that shape.
    fn of(a: &[f64], m: usize) -> Option<StageBlocks> {
        use nalgebra::{Complex, DMatrix};
        let am = DMatrix::from_row_slice(m, m, a);
        let eig = am.clone().complex_eigenvalues();
        let (mut real, mut pair) = (None, None);
        let mut columns: Vec<Vec<f64>> = Vec::with_capacity(m);
        let mut pair_columns = Vec::new();
        for lam in eig.iter() {
            let v = null_vector(&am, *lam)?;
            if lam.im.abs() <= 1e-12 * lam.norm() {
                if real.is_some() {
                    return None;
                }
                real = Some(lam.re);
                columns.push(v.iter().map(|z| z.re).collect());
            } else if lam.im > 0.0 {
                if pair.is_some() {
                    return None;
                }
                pair = Some((lam.re, lam.im));
                pair_columns.push(v.iter().map(|z| z.re).collect());
                pair_columns.push(v.iter().map(|z: &Complex<f64>| z.im).collect());
            }
        }
        columns.extend(pair_columns);
        if columns.len() != m {
            return None;
        }
        let t = DMatrix::from_fn(m, m, |r, c| columns[c][r]);
        let t_inv = t.clone().try_inverse()?;
        let row_major = |x: &DMatrix<f64>| x.transpose().as_slice().to_vec();
        Some(StageBlocks {
            t: row_major(&t),
            t_inv: row_major(&t_inv),
            real,
            pair,
        })
    }
}

/// A vector spanning the null space of A − λI (m ≤ 3, λ a simple
/// eigenvalue): for m = 3 the largest bilinear cross product of two of
/// its rows, for m = 2 a row turned by 90°, for m = 1 the unit.
fn null_vector(
    a: &nalgebra::DMatrix<f64>,
    lam: nalgebra::Complex<f64>,
) -> Option<Vec<nalgebra::Complex<f64>>> {
    use nalgebra::Complex;
    let m = a.nrows();
    let row = |i: usize| -> Vec<Complex<f64>> {
        (0..m)
            .map(|j| {
                Complex::new(a[(i, j)], 0.0) - if i == j { lam } else { Complex::new(0.0, 0.0) }
            })
            .collect()
    };
    let norm = |v: &[Complex<f64>]| v.iter().map(Complex::norm_sqr).sum::<f64>();
    let v = match m {
        1 => vec![Complex::new(1.0, 0.0)],
        2 => [row(0), row(1)]
            .into_iter()
            .map(|r| vec![-r[1], r[0]])
            .max_by(|x, y| norm(x).total_cmp(&norm(y)))?,
        3 => [(0, 1), (0, 2), (1, 2)]
            .into_iter()
            .map(|(i, j)| {
                let (p, q) = (row(i), row(j));
                vec![
                    p[1] * q[2] - p[2] * q[1],
                    p[2] * q[0] - p[0] * q[2],
                    p[0] * q[1] - p[1] * q[0],
                ]
            })
            .max_by(|x, y| norm(x).total_cmp(&norm(y)))?,
        _ => return None,
    };
    (norm(&v) > 0.0).then_some(v)
}

impl Tableau {
    pub(crate) fn gauss(m: usize) -> Option<Tableau> {
        if m > 3 {
            return None;
        }
        let (c, b) = crate::numerics::quadrature::gauss_legendre(m, 0.0, 1.0)?;
        let a = c
            .iter()
            .flat_map(|&cj| integral_weights(&c, &b, cj))
            .collect::<Vec<f64>>();
        let d = nalgebra::DMatrix::from_row_slice(m, m, &a)
            .transpose()
            .lu()
            .solve(&nalgebra::DVector::from_column_slice(&b))?
            .as_slice()
            .to_vec();
        let blocks = StageBlocks::of(&a, m)?;
        let a_inv = nalgebra::DMatrix::from_row_slice(m, m, &a)
            .try_inverse()?
            .transpose()
            .as_slice()
            .to_vec();
        Some(Tableau {
            m,
            c,
            a,
            b,
            d,
            blocks,
            a_inv,
        })
    }

    pub(crate) fn a(&self, j: usize, l: usize) -> f64 {
        self.a[j * self.m + l]
    }

    /// (A⁻¹)_jl.
    pub(crate) fn a_inv(&self, j: usize, l: usize) -> f64 {
        self.a_inv[j * self.m + l]
    }
}

/// The nodes (0, c_1 … c_m) of the collocation polynomial on [0, 1] and
/// their count m + 1 (the Gauss points of [`Tableau::gauss`], without its
/// allocations).
pub(super) fn interpolation_nodes(m: usize) -> ([f64; 4], usize) {
    let m = if matches!(m, 1 | 2) { m } else { 3 };
    let (c, _) = crate::numerics::quadrature::gauss_legendre_unit(m).expect("tabulated");
    let mut nodes = [0.0; 4];
    nodes[1..=c.len()].copy_from_slice(c);
    (nodes, c.len() + 1)
}

/// ℓ_q(t) for the Lagrange basis on `nodes`.
pub(super) fn lagrange(nodes: &[f64], q: usize, t: f64) -> f64 {
    nodes
        .iter()
        .enumerate()
        .filter(|&(r, _)| r != q)
        .map(|(_, &x)| (t - x) / (nodes[q] - x))
        .product()
}

/// ∫_0^τ ℓ_l(t) dt for every l, exact by the m-point Gauss rule (c, w)
/// mapped to [0, τ] since ℓ_l has degree m − 1.
fn integral_weights(c: &[f64], w: &[f64], tau: f64) -> Vec<f64> {
    (0..c.len())
        .map(|l| {
            tau * c
                .iter()
                .zip(w)
                .map(|(&cq, &wq)| wq * lagrange(c, l, tau * cq))
                .sum::<f64>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tableau integrates polynomials of degree ≤ m − 1 exactly on
    /// [0, c_j] (stage order m) and of degree ≤ 2m − 1 on [0, 1].
    #[test]
    fn gauss_tableaus_have_their_orders() {
        for m in 1..=3 {
            let t = Tableau::gauss(m).unwrap();
            for q in 0..2 * m {
                let quad: f64 = (0..m).map(|j| t.b[j] * t.c[j].powi(q as i32)).sum();
                assert!((quad - 1.0 / (q as f64 + 1.0)).abs() < 1e-14, "m {m} q {q}");
            }
            for j in 0..m {
                for q in 0..m {
                    let s: f64 = (0..m).map(|l| t.a(j, l) * t.c[l].powi(q as i32)).sum();
                    let exact = t.c[j].powi(q as i32 + 1) / (q as f64 + 1.0);
                    assert!((s - exact).abs() < 1e-14, "m {m} j {j} q {q}");
                }
            }
        }
    }

    /// T⁻¹ A T is the block form the stage blocks claim, to round-off.
    #[test]
    fn stage_blocks_diagonalize_a() {
        for m in 1..=3 {
            let t = Tableau::gauss(m).unwrap();
            let sb = &t.blocks;
            let mut lam = vec![0.0; m * m];
            let mut k = 0;
            if let Some(g) = sb.real {
                lam[0] = g;
                k = 1;
            }
            if let Some((al, be)) = sb.pair {
                lam[k * m + k] = al;
                lam[k * m + k + 1] = be;
                lam[(k + 1) * m + k] = -be;
                lam[(k + 1) * m + k + 1] = al;
                k += 2;
            }
            assert_eq!(k, m, "m {m}");
            for i in 0..m {
                for j in 0..m {
                    let v: f64 = (0..m)
                        .flat_map(|p| (0..m).map(move |q| (p, q)))
                        .map(|(p, q)| sb.t_inv[i * m + p] * t.a(p, q) * sb.t[q * m + j])
                        .sum();
                    assert!((v - lam[i * m + j]).abs() < 1e-14, "m {m} ({i}, {j}): {v}");
                }
            }
        }
    }
}
