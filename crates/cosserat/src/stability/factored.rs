//! The second variation's quadratic forms evaluated from their factors,
//! K = Dᵀ B D, instead of from the assembled matrix: D maps the nodal
//! unknowns to (ω, ω') at the quadrature points, B holds the form's
//! coefficients there, and vᵀKv = Σ_q w_q q(ω_q, ω'_q) (eq. (23) summed by
//! the same Gauss rule that assembled K).
//!
//! Why: the assembled K has entries ~B/h and zero row sums (a constant ω
//! has no ω'), and rounding each entry breaks those sums by ε/h, so vᵀKv of
//! a smooth mode — O(1) from terms of size N² — carries a relative error
//! ε N² whatever the arithmetic after it: at 10⁵ elements a λ_1 off by
//! 4e-6 (issue 18). From the factors, ω' = Σ_a φ_a' v_a / h cancels only a
//! factor N (values of size |ω| to a difference of size h|ω'|), and the
//! sum of the positive stiffness terms cancels nothing: the error is ε N.
//! The eigenvector from the assembled matrices is accurate to the same
//! relative ε N² (a perturbation of K), and the Rayleigh quotient is
//! stationary at an eigenvector, so its value from the factors errs by
//! (ε N²)² + ε N — below 1e-10 at 10⁵ elements.

use super::second_variation::{Block, FiniteElements, FormCoefficients};
use crate::numerics::constrained::Constraints;
use crate::numerics::eigen::Eigenpairs;

/// vᵀKv from the factors: Σ_q w_q q(ω_q, ω'_q) for the block unknowns `v`
/// and the coefficients at the quadrature points.
pub fn form(fe: &FiniteElements, coeffs: &[FormCoefficients], block: Block, v: &[f64]) -> f64 {
    let comps = block.components();
    let mut sum = 0.0;
    fe.for_each_point_of(block, &[v], |q, weight, points| {
        let (w, dw) = &points[0];
        sum += weight * coeffs[q].evaluate_on(comps, w, dw);
    });
    sum
}

/// The Rayleigh quotient vᵀKv / vᵀGv from the factors: an eigenvalue of
/// (K, G) to second order in the error of its vector `v`.
pub fn rayleigh_quotient(
    fe: &FiniteElements,
    coeffs: &[FormCoefficients],
    block: Block,
    v: &[f64],
) -> f64 {
    rayleigh_quotients(fe, coeffs, block, &[v])[0]
}

/// [`rayleigh_quotient`] of several vectors in one pass over the
/// quadrature points (each point's coefficients read once for all).
fn rayleigh_quotients(
    fe: &FiniteElements,
    coeffs: &[FormCoefficients],
    block: Block,
    vectors: &[&[f64]],
) -> Vec<f64> {
    let comps = block.components();
    let mut sums = vec![(0.0, 0.0); vectors.len()];
    fe.for_each_point_of(block, vectors, |q, weight, points| {
        let c = &coeffs[q];
        for ((stiffness, metric), (w, dw)) in sums.iter_mut().zip(points) {
            *stiffness += weight * c.evaluate_on(comps, w, dw);
            *metric += weight * w.norm_squared();
        }
    });
    sums.into_iter().map(|(k, g)| k / g).collect()
}

/// vᵀGv from the factors: Σ_q w_q |ω_q|².
fn metric(fe: &FiniteElements, block: Block, v: &[f64]) -> f64 {
    let mut sum = 0.0;
    fe.for_each_point(block, v, |weight, w, _| sum += weight * w.norm_squared());
    sum
}

/// The load factor λ = −vᵀK0v / vᵀK1v of the pencil K0 + λK1 at its null
/// vector `v`, both forms from the factors (`coeffs` = (K0's, K1's)): the
/// critical load to second order in the error of `v`. None when the load
/// does not lower the energy along `v` (vᵀK1v ≥ 0) or the value is not
/// finite, which leaves the caller's matrix value standing.
pub fn load_factor(
    fe: &FiniteElements,
    coeffs: (&[FormCoefficients], &[FormCoefficients]),
    block: Block,
    v: &[f64],
) -> Option<f64> {
    let (stiffness, load) = (form(fe, coeffs.0, block, v), form(fe, coeffs.1, block, v));
    let lambda = -stiffness / load;
    (load < 0.0 && lambda.is_finite() && lambda > 0.0).then_some(lambda)
}

/// The pairs with each eigenvalue replaced by its Rayleigh quotient from
/// the factors (plus the support's springs, Σ (u_j·v)² over vᵀGv), in
/// increasing order again (a cluster may swap by round-off).
pub fn refined(
    fe: &FiniteElements,
    coeffs: &[FormCoefficients],
    block: Block,
    support: &Constraints,
    pairs: Eigenpairs,
) -> Eigenpairs {
    let vectors: Vec<&[f64]> = pairs.vectors.iter().map(Vec::as_slice).collect();
    let quotients = rayleigh_quotients(fe, coeffs, block, &vectors);
    let mut all: Vec<(f64, Vec<f64>)> = quotients
        .into_iter()
        .zip(pairs.vectors)
        .map(|(quotient, v)| {
            let springs = if support.is_empty() {
                0.0
            } else {
                support.spring_form(&v) / metric(fe, block, &v)
            };
            (quotient + springs, v)
        })
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    Eigenpairs {
        values: all.iter().map(|p| p.0).collect(),
        vectors: all.into_iter().map(|p| p.1).collect(),
    }
}
