//! Closed-form rod solutions.

use super::elliptic::{ellip_e, ellip_f};
use std::f64::consts::FRAC_PI_2;

/// Tip of the planar cantilever of unit length under a tip force
/// perpendicular to the clamp's tangent, k = F L²/B (Bisshopp & Drucker,
/// Q. Appl. Math. 3, 1945). With the tip angle φ0 and
/// p² = (1 + sin φ0)/2, sin θ0 = 1/(p√2):
///   √k = K(p) − F(θ0, p),
///   deflection  x = 1 − 2 (E(p) − E(θ0, p)) / √k,
///   projection  z = √(2 sin φ0 / k).
pub struct CantileverTip {
    /// Deflection along the force.
    pub x: f64,
    /// Coordinate along the clamp's tangent.
    pub z: f64,
    /// Tip angle φ0 from the clamp's tangent.
    pub angle: f64,
}

pub fn cantilever_tip(k: f64) -> CantileverTip {
    let sqrt_k = k.sqrt();
    let lhs = |p: f64| {
        let theta0 = (1.0 / (p * 2f64.sqrt())).asin();
        ellip_f(FRAC_PI_2, p) - ellip_f(theta0, p)
    };
    // K(p) − F(θ0, p) increases from 0 at p = 1/√2 to ∞ at p = 1: bisection.
    let (mut lo, mut hi) = (std::f64::consts::FRAC_1_SQRT_2, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if lhs(mid) < sqrt_k {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let p = 0.5 * (lo + hi);
    let theta0 = (1.0 / (p * 2f64.sqrt())).asin();
    let sin_phi0 = 2.0 * p * p - 1.0;
    CantileverTip {
        x: 1.0 - 2.0 * (ellip_e(FRAC_PI_2, p) - ellip_e(theta0, p)) / sqrt_k,
        z: (2.0 * sin_phi0 / k).sqrt(),
        angle: sin_phi0.asin(),
    }
}
