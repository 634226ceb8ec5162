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

use super::strain::{assemble_blocks, stack, StrainEnergy, StrainJet};
use super::{ModelError, Profile, ProfileEdits, ProfileKind, StoredEnergy};

/// A bending energy W_b(s, κ) with the quadratic shear and extension
/// energy ½ (ν − e3)ᵀ diag(S) (ν − e3). Built by the checked
/// [`Shearable::new`], so that S is positive definite.
#[derive(Debug, Clone)]
pub struct Shearable {
    bending: Arc<dyn StoredEnergy>,
    shear: Vector3<f64>,
}

impl Shearable {
    /// The bending energy W_b with shear and extension stiffnesses
    /// S = (S1, S2, S3) = (k G A, k G A, E A) (N). Refused with
    /// [`ModelError::Stiffness`] unless every S_i is positive and finite
    /// (ν = e3 + S⁻¹N needs S invertible; a negative S_i has no minimum).
    pub fn new(bending: Arc<dyn StoredEnergy>, shear: Vector3<f64>) -> Result<Self, ModelError> {
        if let Some(index) = (0..3).find(|&i| !(shear[i].is_finite() && shear[i] > 0.0)) {
            return Err(ModelError::Stiffness {
                what: "shear/extension stiffness S",
                index,
                value: shear[index],
            });
        }
        Ok(Shearable { bending, shear })
    }

    /// W_b(s, κ).
    pub fn bending(&self) -> &Arc<dyn StoredEnergy> {
        &self.bending
    }

    /// S = (S1, S2, S3): shear stiffnesses k G A about d1, d2 and the
    /// extensional stiffness E A (N), all positive.
    pub fn shear(&self) -> Vector3<f64> {
        self.shear
    }
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

    fn derivatives_trusted(&self) -> bool {
        self.bending.derivatives_trusted()
    }

    fn even_components(&self) -> [bool; 3] {
        self.bending.even_components()
    }

    fn is_uniform(&self) -> bool {
        self.bending.is_uniform()
    }

    fn breaks(&self, length: f64) -> Vec<f64> {
        self.bending.breaks(length)
    }

    fn shear_stiffness(&self, _s: f64) -> Option<Vector3<f64>> {
        Some(self.shear)
    }

    fn strain_energy(&self) -> Option<&dyn StrainEnergy> {
        Some(self)
    }

    fn profile_edits(&self) -> Option<&dyn ProfileEdits> {
        self.bending
            .profile_edits()
            .map(|_| self as &dyn ProfileEdits)
    }
}

/// The bending energy's edits, the shear part kept. Reached only through
/// [`StoredEnergy::profile_edits`], which gives it where the bending
/// energy has edits.
impl ProfileEdits for Shearable {
    fn intrinsic_profiles(&self) -> &[Profile; 3] {
        self.bending_edits().intrinsic_profiles()
    }

    fn with_intrinsic_scaled(&self, factor: f64) -> Option<Arc<dyn StoredEnergy>> {
        let bending = self.bending_edits().with_intrinsic_scaled(factor)?;
        Some(self.with_bending(bending))
    }

    fn with_constant(
        &self,
        profile: ProfileKind,
        i: usize,
        value: f64,
    ) -> Option<Arc<dyn StoredEnergy>> {
        let bending = self.bending_edits().with_constant(profile, i, value)?;
        Some(self.with_bending(bending))
    }

    fn with_intrinsic_towards(
        &self,
        target: &dyn StoredEnergy,
        p: f64,
    ) -> Option<Arc<dyn StoredEnergy>> {
        let bending = self.bending_edits().with_intrinsic_towards(target, p)?;
        Some(self.with_bending(bending))
    }
}

/// W = W_b(s, κ) + ½ (ν − e3)ᵀ S (ν − e3): H = diag(H_b, S), no coupling,
/// the third derivative that of W_b alone.
impl StrainEnergy for Shearable {
    fn strain_density(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> f64 {
        let e = nu - Vector3::z();
        self.bending.density(s, kappa) + 0.5 * self.shear.component_mul(&e).dot(&e)
    }

    fn strain_jet(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> StrainJet {
        let b = &self.bending;
        let zero = Matrix3::zeros();
        let force = self.shear.component_mul(&(nu - Vector3::z()));
        StrainJet {
            gradient: stack(&b.moment(s, kappa), &force),
            hessian: assemble_blocks(
                &b.stiffness(s, kappa),
                &zero,
                &Matrix3::from_diagonal(&self.shear),
            ),
            gradient_rate: stack(&b.moment_rate(s, kappa), &Vector3::zeros()),
            hessian_rate: assemble_blocks(&b.stiffness_rate(s, kappa), &zero, &zero),
        }
    }

    fn strain_hessian_derivative(
        &self,
        s: f64,
        kappa: &Vector3<f64>,
        _nu: &Vector3<f64>,
        v: &nalgebra::Vector6<f64>,
    ) -> nalgebra::Matrix6<f64> {
        let vk = Vector3::new(v[0], v[1], v[2]);
        let t = self.bending.stiffness_derivative(s, kappa, &vk);
        let zero = Matrix3::zeros();
        assemble_blocks(&t, &zero, &zero)
    }
}

impl Shearable {
    /// The bending energy's profile edits (present whenever these are
    /// reached: [`StoredEnergy::profile_edits`] gives them only then).
    fn bending_edits(&self) -> &dyn ProfileEdits {
        self.bending
            .profile_edits()
            .expect("Shearable's edits are given only where its bending energy has them")
    }

    /// The same shear part (checked when this one was built) on another
    /// bending energy.
    fn with_bending(&self, bending: Arc<dyn StoredEnergy>) -> Arc<dyn StoredEnergy> {
        Arc::new(Shearable {
            bending,
            shear: self.shear,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::LinearElastic;

    #[test]
    fn shear_stiffness_is_checked() {
        let b: Arc<dyn StoredEnergy> =
            Arc::new(LinearElastic::uniform([1.0; 3], [0.0; 3]).unwrap());
        let s = Shearable::new(b.clone(), Vector3::new(10.0, 20.0, 30.0)).unwrap();
        assert_eq!(s.shear(), Vector3::new(10.0, 20.0, 30.0));
        assert_eq!(s.shear_stiffness(0.3), Some(s.shear()));
        assert_eq!(s.bending().name(), "linear");
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                Shearable::new(b.clone(), Vector3::new(1.0, bad, 1.0)),
                Err(ModelError::Stiffness { index: 1, .. })
            ));
        }
    }
}
