//! Critical loads of columns with a held tip, from the linearized
//! equations, independent of the code under test (the twisted column,
//! Greenhill's, is `cosserat::references::greenhill_clamped`).

/// The smallest root of tan x = x above π (the clamped–pinned column,
/// P L²/B = x² ≈ 20.19; Timoshenko & Gere, *Theory of Elastic Stability*,
/// Sec. 2.4), by bisection on sin x − x cos x in (π, 3π/2).
pub fn clamped_pinned() -> f64 {
    let f = |x: f64| x.sin() - x * x.cos();
    let x = bisect(f, std::f64::consts::PI, 1.5 * std::f64::consts::PI - 1e-9);
    x * x
}

/// The root of f in [lo, hi], where f changes sign, to round-off.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(lo) * f(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}
