//! The exact gradient of a design's reach with respect to c2..cM.
//!
//! R̂ = L̂(λ) ρ with L̂ = λ^e (e = ½ with a tip load, paper (54)) and
//! ρ = |r̄(1)| the chord, so
//!
//!   ∂R̂/∂c_j = e L̂/λ ρ dλ/dc_j + L̂ ∂ρ/∂c_j.
//!
//! c1 is not free: it turns the shape so that the tip lies at elevation α,
//! c1 = −α − atan2(x̄, z̄) with (x̄, z̄) = ∫_0^1 (sin φ, cos φ) ds̄ by the
//! design's quadrature ([`super::ArmProblem::full_coefficients`]); so
//! dλ/dc_j = ∂λ/∂c_j + ∂λ/∂c_1 ∂c1/∂c_j with
//! ∂c1/∂c_j = −(z̄ ∂x̄/∂c_j − x̄ ∂z̄/∂c_j)/ρ², and ∂x̄/∂c_j = ∫ cos φ s̄^{j−1},
//! ∂z̄/∂c_j = −∫ sin φ s̄^{j−1} by the same quadrature (exact derivatives of
//! the computed chord). ∂λ/∂c_i is the eigenvector formula of
//! [`crate::stability::critical_load_gradient`]. Where λ_crit is not simple
//! (two modes within [`crate::stability::SIMPLE_GAP`]) or the actuators
//! limit the load (λ is then a root of the curvature limit, not an
//! eigenvalue), the reach is given without a gradient.

use crate::stability::{critical_load_gradients, SIMPLE_GAP};

use super::design::{polynomial, quadrature};
use super::{ArmDesign, ArmProblem, ArmScene};

/// A design's reach with its gradient in c2..cM where it exists.
#[derive(Debug, Clone, PartialEq)]
pub struct ReachSlope {
    /// The design (as [`ArmProblem::design_in`] gives it).
    pub design: ArmDesign,
    /// ∂R̂/∂c_2, …, ∂R̂/∂c_M; None where R̂ is not differentiable (module
    /// doc).
    pub gradient: Option<Vec<f64>>,
    /// The reach of each block's critical load (in-plane, out-of-plane;
    /// R̂ is the least) with its gradient where that block's load is
    /// simple: the smooth branches whose minimum R̂ is, for a max–min step
    /// where two blocks' loads meet.
    pub branches: Vec<(f64, Option<Vec<f64>>)>,
}

impl ArmProblem {
    /// R̂ of the shape c2..cM in a scene with its exact gradient (module
    /// doc); None when the shape has no finite critical load.
    pub fn reach_slope(&self, scene: &ArmScene, rest: &[f64]) -> Option<ReachSlope> {
        if scene.max_curvature.is_some() {
            let design = self.design_in(scene, rest)?;
            return Some(ReachSlope {
                branches: vec![(design.reach, None)],
                design,
                gradient: None,
            });
        }
        let (c, chord) = self.full_coefficients(rest);
        let rod = self.rod_in(scene).ok()?;
        let loads = critical_load_gradients(&rod, &c, &self.stability).ok()?;
        let lowest = loads
            .iter()
            .min_by(|a, b| a.load_factor.total_cmp(&b.load_factor))?;
        let lambda = lowest.load_factor;
        let (dchord, dc1) = chord_rates(&c);
        let e = scene.length_exponent();
        let branches = loads
            .iter()
            .map(|load| {
                let length = scene.length(load.load_factor);
                let gradient = load.gradient.as_ref().map(|dl| {
                    (1..c.len())
                        .map(|j| {
                            let total = dl[j] + dl[0] * dc1[j - 1];
                            e * length / load.load_factor * chord * total + length * dchord[j - 1]
                        })
                        .collect()
                });
                (length * chord, gradient)
            })
            .collect::<Vec<(f64, Option<Vec<f64>>)>>();
        let index = loads
            .iter()
            .position(|l| std::ptr::eq(l, lowest))
            .expect("the lowest is one of them");
        // Differentiable where no other block's load is within the gap.
        let alone = loads
            .iter()
            .all(|l| std::ptr::eq(l, lowest) || l.load_factor > lambda * (1.0 + SIMPLE_GAP));
        Some(ReachSlope {
            design: ArmDesign {
                reach: scene.length(lambda) * chord,
                gamma: lambda,
                shape_coefficients: c,
            },
            gradient: if alone {
                branches[index].1.clone()
            } else {
                None
            },
            branches,
        })
    }
}

/// (∂ρ/∂c_j, ∂c1/∂c_j) for j = 2..M at the full coefficients `c` (module
/// doc; both invariant under the rigid turn c1).
pub(super) fn chord_rates(c: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let free = c.len() - 1;
    let (mut x, mut z) = (0.0, 0.0);
    let (mut dx, mut dz) = (vec![0.0; free], vec![0.0; free]);
    for (s, w) in quadrature() {
        let (sin, cos) = polynomial(c, s).sin_cos();
        x += w * sin;
        z += w * cos;
        let mut p = w;
        for k in 0..free {
            p *= s;
            dx[k] += p * cos;
            dz[k] -= p * sin;
        }
    }
    let rho2 = x * x + z * z;
    let rho = rho2.sqrt();
    let dchord = dx
        .iter()
        .zip(&dz)
        .map(|(a, b)| (x * a + z * b) / rho)
        .collect();
    let dc1 = dx
        .iter()
        .zip(&dz)
        .map(|(a, b)| -(z * a - x * b) / rho2)
        .collect();
    (dchord, dc1)
}
