//! Critical loads of columns with a held tip, from the linearized
//! equations, independent of the code under test.

use nalgebra::{Complex, DMatrix};

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

/// Greenhill's problem with clamped ends: a rod (bending stiffness B,
/// length L) under a thrust P and an axial torque M, clamped at s = 0, its
/// tip held on the axis and in direction but free to slide along and spin
/// about it. The lateral deflection w = x + i y obeys
/// B w'''' − i M w''' + P w'' = 0 (Greenhill 1883; Ziegler, *Principles of
/// Structural Stability*, Sec. 2.7), so w = a + b s + c e^{i k1 s} +
/// d e^{i k2 s} with k = (M ± √(M² + 4BP))/(2B), and w(0) = w'(0) =
/// w(L) = w'(L) = 0 has a non-trivial solution where the 4 × 4 determinant
/// vanishes. det · e^{−iML/(2B)} is purely imaginary; its imaginary part is
/// bisected for the smallest critical P.
pub fn greenhill_clamped(m: f64, b: f64, l: f64) -> f64 {
    let f = |p: f64| {
        let r = (m * m + 4.0 * b * p).sqrt();
        let (k1, k2) = ((m + r) / (2.0 * b), (m - r) / (2.0 * b));
        let i = Complex::new(0.0, 1.0);
        let e = |k: f64| (i * k * l).exp();
        let one = Complex::new(1.0, 0.0);
        let zero = Complex::new(0.0, 0.0);
        let a = DMatrix::from_row_slice(
            4,
            4,
            &[
                one,
                zero,
                one,
                one,
                zero,
                one,
                i * k1,
                i * k2,
                one,
                one * l,
                e(k1),
                e(k2),
                zero,
                one,
                i * k1 * e(k1),
                i * k2 * e(k2),
            ],
        );
        (a.determinant() * (-i * m * l / (2.0 * b)).exp()).im
    };
    // Scan up from a small thrust to the first sign change, then bisect.
    let step = 0.01 * b / (l * l);
    let mut lo = step;
    while f(lo) * f(lo + step) > 0.0 {
        lo += step;
        assert!(lo < 100.0 * b / (l * l), "no root below 100 B/L²");
    }
    bisect(f, lo, lo + step)
}
