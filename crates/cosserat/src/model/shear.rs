//! Shear and extension: the part of a Cosserat rod's stored energy that
//! depends on the strain ν = Rᵀr', the tangent r' in the director frame
//! R = (d1 d2 d3), so that r' = ν_i d_i.
//!
//! The Kirchhoff rod is unshearable and inextensible, ν = e3. The Cosserat
//! rod has W(s, κ, ν) = W_b(s, κ) + ½ (ν − e3)ᵀ S (ν − e3) with
//! S = diag(S1, S2, S3): S1, S2 the shear stiffnesses (k G A) and S3 the
//! extensional stiffness (E A). The body force is then N = S (ν − e3), and
//! with dead loads N is known from the frame, so ν = e3 + S⁻¹N is explicit
//! (Antman, *Nonlinear Problems of Elasticity*, 2nd ed., Ch. 8, §8.2).
//! Any bending energy combines with this quadratic shear part.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::{Profile, StoredEnergy};

/// A bending energy W_b(s, κ) with the quadratic shear and extension
/// energy ½ (ν − e3)ᵀ diag(S) (ν − e3).
#[derive(Debug, Clone)]
pub struct Shearable {
    /// W_b(s, κ).
    pub bending: Arc<dyn StoredEnergy>,
    /// S = (S1, S2, S3): shear stiffnesses k G A about d1, d2 and the
    /// extensional stiffness E A (N), all positive.
    pub shear: Vector3<f64>,
}

impl StoredEnergy for Shearable {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        self.bending.density(s, kappa)
    }

    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        self.bending.moment(s, kappa)
    }

    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        self.bending.stiffness(s, kappa)
    }

    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        self.bending.moment_rate(s, kappa)
    }

    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        self.bending.stiffness_rate(s, kappa)
    }

    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        self.bending.stiffness_derivative(s, kappa, v)
    }

    fn admits_planar_bending(&self) -> bool {
        self.bending.admits_planar_bending()
    }

    fn name(&self) -> &str {
        self.bending.name()
    }

    fn is_quadratic(&self) -> bool {
        self.bending.is_quadratic()
    }

    fn shear_stiffness(&self, _s: f64) -> Option<Vector3<f64>> {
        Some(self.shear)
    }

    fn with_intrinsic_scaled(&self, factor: f64) -> Option<Arc<dyn StoredEnergy>> {
        let bending = self.bending.with_intrinsic_scaled(factor)?;
        Some(self.with_bending(bending))
    }

    fn intrinsic_profiles(&self) -> Option<&[Profile; 3]> {
        self.bending.intrinsic_profiles()
    }

    fn with_constant(
        &self,
        profile: super::energy::ProfileKind,
        i: usize,
        value: f64,
    ) -> Option<Arc<dyn StoredEnergy>> {
        let bending = self.bending.with_constant(profile, i, value)?;
        Some(self.with_bending(bending))
    }

    fn with_intrinsic_towards(
        &self,
        target: &dyn StoredEnergy,
        p: f64,
    ) -> Option<Arc<dyn StoredEnergy>> {
        let bending = self.bending.with_intrinsic_towards(target, p)?;
        Some(self.with_bending(bending))
    }
}

impl Shearable {
    /// The same shear part on another bending energy.
    fn with_bending(&self, bending: Arc<dyn StoredEnergy>) -> Arc<dyn StoredEnergy> {
        Arc::new(Shearable {
            bending,
            shear: self.shear,
        })
    }
}
