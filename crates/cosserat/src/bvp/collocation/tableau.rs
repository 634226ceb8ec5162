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
        Some(Tableau { m, c, a, b, d })
    }

    pub(crate) fn a(&self, j: usize, l: usize) -> f64 {
        self.a[j * self.m + l]
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
}
