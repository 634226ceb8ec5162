//! Gauss–Legendre quadrature: the m-point rule ∫_a^b f ≈ Σ_q w_q f(x_q) is
//! exact for polynomials of degree ≤ 2m − 1. On [0, 1] the nodes are the
//! roots of the shifted Legendre polynomial P_m(2x − 1) and the weights
//! w_q = ∫_0^1 ℓ_q for the Lagrange basis ℓ_q on the nodes (Abramowitz &
//! Stegun, Table 25.4, mapped from [−1, 1] by x = (1 + ξ)/2, w = w_ξ/2).
//!
//! The tables hold the values to the last bit, written as the nearest
//! doubles (1/2 ∓ √3/6 for m = 2, 1/2 ∓ √15/10 for m = 3, and the halved
//! roots of 35ξ⁴ − 30ξ² + 3 for m = 4).

/// The largest number of points tabulated.
pub const MAX_POINTS: usize = 4;

const NODES_1: [f64; 1] = [0.5];
const WEIGHTS_1: [f64; 1] = [1.0];
const NODES_2: [f64; 2] = [0.211_324_865_405_187_13, 0.788_675_134_594_812_9];
const WEIGHTS_2: [f64; 2] = [0.5, 0.5];
const NODES_3: [f64; 3] = [0.112_701_665_379_258_3, 0.5, 0.887_298_334_620_741_7];
const WEIGHTS_3: [f64; 3] = [
    0.277_777_777_777_777_8,
    0.444_444_444_444_444_4,
    0.277_777_777_777_777_8,
];
const NODES_4: [f64; 4] = [
    0.069_431_844_202_973_71,
    0.330_009_478_207_571_87,
    0.669_990_521_792_428_1,
    0.930_568_155_797_026_2,
];
const WEIGHTS_4: [f64; 4] = [
    0.173_927_422_568_726_92,
    0.326_072_577_431_273_1,
    0.326_072_577_431_273_1,
    0.173_927_422_568_726_92,
];

/// The m-point Gauss–Legendre nodes (increasing) and weights on [0, 1],
/// for m = 1 to [`MAX_POINTS`]; None for another m.
pub fn gauss_legendre_unit(m: usize) -> Option<(&'static [f64], &'static [f64])> {
    match m {
        1 => Some((&NODES_1, &WEIGHTS_1)),
        2 => Some((&NODES_2, &WEIGHTS_2)),
        3 => Some((&NODES_3, &WEIGHTS_3)),
        4 => Some((&NODES_4, &WEIGHTS_4)),
        _ => None,
    }
}

/// The m-point Gauss–Legendre nodes x_q = a + (b − a) x̂_q and weights
/// w_q = (b − a) ŵ_q on [a, b], from the table on [0, 1]
/// ([`gauss_legendre_unit`]); None for m outside 1 to [`MAX_POINTS`]. On
/// [0, 1] they are the table's values to the bit.
pub fn gauss_legendre(m: usize, a: f64, b: f64) -> Option<(Vec<f64>, Vec<f64>)> {
    let (x, w) = gauss_legendre_unit(m)?;
    let h = b - a;
    Some((
        x.iter().map(|&x| a + h * x).collect(),
        w.iter().map(|&w| h * w).collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The m-point rule integrates x^k exactly for k ≤ 2m − 1 on [a, b].
    #[test]
    fn integrates_polynomials_to_degree_2m_minus_1() {
        let (a, b) = (-0.3, 1.7);
        for m in 1..=MAX_POINTS {
            let (x, w) = gauss_legendre(m, a, b).unwrap();
            for k in 0..2 * m {
                let quad: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                let exact = (b.powi(k as i32 + 1) - a.powi(k as i32 + 1)) / (k as f64 + 1.0);
                assert!(
                    (quad - exact).abs() < 1e-14,
                    "m = {m}, k = {k}: {quad} vs {exact}"
                );
            }
        }
        assert!(gauss_legendre_unit(0).is_none() && gauss_legendre(5, 0.0, 1.0).is_none());
    }

    /// The tables are the closed forms they were computed from before they
    /// were written down.
    #[test]
    fn tables_are_the_closed_forms() {
        let d2 = 3f64.sqrt() / 6.0;
        assert_eq!(NODES_2, [0.5 - d2, 0.5 + d2]);
        let d3 = 15f64.sqrt() / 10.0;
        assert_eq!(NODES_3, [0.5 - d3, 0.5, 0.5 + d3]);
        assert_eq!(WEIGHTS_3, [5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0]);
        let r = (6.0f64 / 5.0).sqrt();
        let (p, q) = (
            ((3.0 - 2.0 * r) / 7.0).sqrt(),
            ((3.0 + 2.0 * r) / 7.0).sqrt(),
        );
        let x: Vec<f64> = [-q, -p, p, q].iter().map(|v| 0.5 * (v + 1.0)).collect();
        assert_eq!(x, NODES_4);
        let (wp, wq) = ((18.0 + 30f64.sqrt()) / 36.0, (18.0 - 30f64.sqrt()) / 36.0);
        let w: Vec<f64> = [wq, wp, wp, wq].iter().map(|v| 0.5 * v).collect();
        assert_eq!(w, WEIGHTS_4);
        assert_eq!(gauss_legendre(3, 0.0, 1.0).unwrap().0, NODES_3);
    }
}
