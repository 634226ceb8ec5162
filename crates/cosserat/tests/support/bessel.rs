//! Zeros of Bessel functions of the first kind from their power series
//! (DLMF 10.2.2): J_ν(x) = (x/2)^ν Σ_m (−x²/4)^m / (m! Γ(m + ν + 1)). For
//! x > 0 the factor (x/2)^ν/Γ(ν + 1) is positive, so the zeros of J_ν are
//! those of S(x) = Σ_m (−x²/4)^m / (m! (ν + 1)_m), which needs no Γ.

/// S(x) summed until the terms are below round-off.
fn reduced_series(nu: f64, x: f64) -> f64 {
    let q = -x * x / 4.0;
    let (mut term, mut sum) = (1.0, 1.0);
    for m in 1..200 {
        term *= q / (m as f64 * (nu + m as f64));
        sum += term;
        if term.abs() < 1e-18 * sum.abs().max(1e-300) {
            break;
        }
    }
    sum
}

/// The first positive zero of J_ν, bracketed in (lo, hi) by a sign change.
pub fn first_zero(nu: f64, lo: f64, hi: f64) -> f64 {
    let (mut a, mut b) = (lo, hi);
    let fa = reduced_series(nu, a);
    assert!(
        fa * reduced_series(nu, b) < 0.0,
        "no sign change in the bracket"
    );
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if reduced_series(nu, m) * fa > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}
