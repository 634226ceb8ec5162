//! One design: the shape coefficients c2..cM to the reach R̂.
//!
//! The loaded shape is φ(s̄) = Σ c_i s̄^{i−1}; c1 turns it so that the tip
//! (x̄(1), z̄(1)) = ∫_0^1 (sin φ, cos φ) ds̄ (composite Gauss–Legendre) lies
//! at elevation α. The fixed shape's critical load γ_crit is a generalized
//! eigenvalue of the second variation, and the reach is
//! R̂ = √γ_crit |(x̄(1), z̄(1))| (paper (54)–(55)); in a scene with a
//! curvature limit the design load is the operating load instead. Also the
//! polynomial helpers and the unloaded shape of the intrinsic curvature
//! κ̄⁰2 = φ' − γ m̄2 (paper (43)).

use crate::model::ModelError;
use std::sync::Arc;

use crate::model::{Clamp, LinearElastic, Profile, Rod};
use crate::stability::{critical_load, FixedShape};

use super::{ArmDesign, ArmProblem, ArmScene};

/// Composite Gauss–Legendre nodes (5 points on each of 32 panels) on [0, 1].
pub(super) fn quadrature() -> Vec<(f64, f64)> {
    const X: [f64; 5] = [
        -0.906_179_845_938_664,
        -0.538_469_310_105_683_1,
        0.0,
        0.538_469_310_105_683_1,
        0.906_179_845_938_664,
    ];
    const W: [f64; 5] = [
        0.236_926_885_056_189_1,
        0.478_628_670_499_366_5,
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
    ];
    let panels = 32;
    let h = 1.0 / f64::from(panels);
    (0..panels)
        .flat_map(|p| {
            X.iter()
                .zip(W)
                .map(move |(x, w)| ((f64::from(p) + 0.5 * (x + 1.0)) * h, 0.5 * w * h))
        })
        .collect()
}

pub(super) fn polynomial(c: &[f64], s: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, ci| acc * s + ci)
}

impl ArmProblem {
    /// M, the number of shape coefficients.
    pub fn coefficients(&self) -> usize {
        self.bounds.len() + 1
    }

    /// The non-dimensional rod: L = 1, B = (B̄1, 1, B̄3), a unit tip load
    /// pulling down (e1), clamped at the origin with d3 horizontal; refused
    /// as in [`Rod::new`].
    pub fn rod(&self) -> Result<Rod, ModelError> {
        self.rod_in(&ArmScene::default())
    }

    /// The non-dimensional rod under the scene's loads per unit λ; refused
    /// as in [`Rod::new`] (a non-finite weight).
    pub fn rod_in(&self, scene: &ArmScene) -> Result<Rod, ModelError> {
        Rod::new(
            1.0,
            Arc::new(LinearElastic::uniform([self.b1, 1.0, self.b3], [0.0; 3])?),
            Clamp::paper(),
            scene.loads(),
            None,
        )
    }

    /// The full coefficients c1..cM: c1 turns the shape so that the tip
    /// lies at elevation α (atan2(−x̄, z̄) = α).
    pub fn full_coefficients(&self, rest: &[f64]) -> (Vec<f64>, f64) {
        let mut c = vec![0.0];
        c.extend_from_slice(rest);
        let (mut z, mut x) = (0.0, 0.0);
        for (s, w) in quadrature() {
            let (sin, cos) = polynomial(&c, s).sin_cos();
            z += w * cos;
            x += w * sin;
        }
        c[0] = -self.alpha - x.atan2(z);
        (c, x.hypot(z))
    }

    /// R̂ and γ_crit of the shape with coefficients c2..cM; None when the
    /// shape is stable under any load (no finite critical load).
    pub fn design(&self, rest: &[f64]) -> Option<ArmDesign> {
        self.design_in(&ArmScene::default(), rest)
    }

    /// R̂ and the design load of the shape c2..cM in a scene: λ_crit of the
    /// fixed shape under the scene's loads, lowered to what the actuators
    /// can hold when |κ⁰| is limited; R̂ = L̂(λ) |r̄(1)|.
    pub fn design_in(&self, scene: &ArmScene, rest: &[f64]) -> Option<ArmDesign> {
        let (c, chord) = self.full_coefficients(rest);
        let rod = self.rod_in(scene).ok()?;
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(c.clone()),
        };
        let crit = critical_load(&rod, &shape, &self.stability).ok()?;
        let mut gamma = crit.load_factor?;
        if scene.max_curvature.is_some() {
            let points: Vec<f64> = (0..=200).map(|i| f64::from(i) / 200.0).collect();
            let samples = shape.samples(&rod, &points).ok()?;
            let dphi = derivative(&c);
            let phi1: Vec<f64> = points.iter().map(|s| polynomial(&dphi, *s)).collect();
            let m2: Vec<f64> = samples.iter().map(|p| p.moment[1]).collect();
            gamma = scene.operating_load(gamma, &phi1, &m2)?;
        }
        Some(ArmDesign {
            reach: scene.length(gamma) * chord,
            gamma,
            shape_coefficients: c,
        })
    }
}

/// The coefficients of p' for p = Σ c_i s^{i−1}.
pub(super) fn derivative(c: &[f64]) -> Vec<f64> {
    c.iter()
        .enumerate()
        .skip(1)
        .map(|(i, ci)| i as f64 * ci)
        .collect()
}

/// The unloaded shape: φ⁰ = c1 + ∫κ⁰ (trapezoidal on the fine grid), then
/// positions by the same rule; scaled by √γ.
pub(super) fn intrinsic_shape(phi0: f64, s: &[f64], kappa0: &[f64], scale: f64) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]];
    let (mut phi, mut x, mut z) = (phi0, 0.0, 0.0);
    for i in 1..s.len() {
        let h = s[i] - s[i - 1];
        let next = phi + 0.5 * h * (kappa0[i] + kappa0[i - 1]);
        x += 0.5 * h * (phi.sin() + next.sin());
        z += 0.5 * h * (phi.cos() + next.cos());
        phi = next;
        out.push([x * scale, 0.0, z * scale]);
    }
    out
}

/// Coefficients b1..bM of the least-squares polynomial Σ b_i s^{i−1}.
pub(super) fn least_squares_polynomial(s: &[f64], y: &[f64], m: usize) -> Vec<f64> {
    let a = nalgebra::DMatrix::from_fn(s.len(), m, |i, j| s[i].powi(j as i32));
    let b = nalgebra::DVector::from_column_slice(y);
    // SVD::solve fails only when U or Vᵀ was not computed; both are, so
    // no failure can turn into numbers here (it had been NaN coefficients).
    a.svd(true, true)
        .solve(&b, 1e-14)
        .map(|v| v.as_slice().to_vec())
        .expect("the SVD was computed with U and Vᵀ")
}
