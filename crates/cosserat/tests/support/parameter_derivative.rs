//! An independent reference for ∂F/∂p of a continued family: central
//! differences of the residual F(x, p ± h) alone, Richardson extrapolated
//! from h, h/2, h/4 (error O(h⁶)). It never touches the tangent, the energy
//! rates or the sensitivity column the library computes, so it can check
//! them.

use cosserat::continuation::Family;
use nalgebra::DVector;

/// F_p(x, p) by central differences at h, h/2, h/4, extrapolated twice
/// (D(h/2)·4 − D(h))/3 then (R(h/4)·16 − R(h/2))/15.
pub fn richardson_parameter_derivative(family: &Family, x: &[f64], p: f64, h: f64) -> DVector<f64> {
    let n = x.len();
    let central = |h: f64| {
        let (mut up, mut down) = (DVector::zeros(n), DVector::zeros(n));
        family.residual_only(x, p + h, &mut up).unwrap();
        family.residual_only(x, p - h, &mut down).unwrap();
        (up - down) / (2.0 * h)
    };
    let d = [central(h), central(h / 2.0), central(h / 4.0)];
    let r1 = (&d[1] * 4.0 - &d[0]) / 3.0;
    let r2 = (&d[2] * 4.0 - &d[1]) / 3.0;
    (r2 * 16.0 - r1) / 15.0
}
