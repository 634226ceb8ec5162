//! The constrained eigensolver cannot be fooled by the problem's scaling
//! (issue 16: a held rod's pairs with backward error 3e-12 were refused as
//! "not converged" because their vectors left the constraints' null space
//! by round-off). A clamped–clamped string by linear elements — the
//! clamped–free column of `support::columns`' kind with its last node held
//! by a constraint — against its discrete eigenvalues in closed form, with
//! K scaled by 10⁻⁶, 1 and 10⁶.

use cosserat::numerics::banded::SymmetricBanded;
use cosserat::numerics::constrained::{
    count_below_constrained, lowest_eigenpairs_constrained, Constraints,
};
use cosserat::numerics::eigen::Inertia;
use nalgebra::DVector;

/// −u'' − p u = λ u on (0, 1), u(0) = 0, by `n` linear elements (node 0
/// eliminated, nodes 1..n kept), K scaled by `scale`.
fn string(n: usize, p: f64, scale: f64) -> (SymmetricBanded, SymmetricBanded) {
    let h = 1.0 / n as f64;
    let (mut k, mut g) = (SymmetricBanded::zeros(n, 1), SymmetricBanded::zeros(n, 1));
    for e in 0..n {
        let nodes = [e.checked_sub(1), Some(e)];
        for (a, ia) in nodes.iter().enumerate() {
            for (b, ib) in nodes.iter().enumerate() {
                if let (Some(i), Some(j)) = (ia, ib) {
                    if i >= j {
                        let same = a == b;
                        let stiff = if same { 1.0 } else { -1.0 } / h;
                        let mass = if same { h / 3.0 } else { h / 6.0 };
                        k.add(*i, *j, scale * (stiff - p * mass));
                        g.add(*i, *j, mass);
                    }
                }
            }
        }
    }
    (k, g)
}

/// The discrete eigenvalues with both ends held: the modes sin(iθ_j) at
/// the nodes, θ_j = jπ/n, give λ_j = 6(1 − cos θ_j)/(h²(2 + cos θ_j)) − p.
fn held_eigenvalue(n: usize, p: f64, j: usize) -> f64 {
    let h = 1.0 / n as f64;
    let theta = j as f64 * std::f64::consts::PI / n as f64;
    6.0 * (1.0 - theta.cos()) / (h * h * (2.0 + theta.cos())) - p
}

/// u(1) = 0 as a constraint on the last node.
fn tip_held(n: usize) -> Constraints {
    let mut row = DVector::zeros(n);
    row[n - 1] = 1.0;
    Constraints::from_rows(&[row], n)
}

/// Scaling K by 10±⁶ scales every eigenvalue by the same factor and keeps
/// the Morse index, for a stable (p = 0) and a twice unstable (p = 50:
/// π² and 4π² below it) pencil.
#[test]
fn constrained_spectrum_scales_with_the_stiffness() {
    let n = 400;
    for p in [0.0, 50.0] {
        let exact: Vec<f64> = (1..=4).map(|j| held_eigenvalue(n, p, j)).collect();
        let negative = exact.iter().filter(|&&l| l < 0.0).count();
        for scale in [1e-6, 1.0, 1e6] {
            let (k, g) = string(n, p, scale);
            let c = tip_held(n);
            let pairs = lowest_eigenpairs_constrained(&k, &g, &c, 4, None)
                .unwrap_or_else(|e| panic!("p = {p}, scale {scale:e}: {e}"));
            assert_eq!(pairs.values.len(), 4);
            for (got, want) in pairs.values.iter().zip(&exact) {
                let want = scale * want;
                assert!(
                    (got - want).abs() <= 1e-9 * want.abs(),
                    "p = {p}, scale {scale:e}: {got} against {want}"
                );
            }
            assert_eq!(
                count_below_constrained(&k, &g, &c, 0.0),
                Inertia::Below(negative),
                "p = {p}, scale {scale:e}"
            );
        }
    }
}
