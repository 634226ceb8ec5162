//! Edits of an energy's separate profiles: the intrinsic curvature κ⁰(s)
//! and the constant stiffnesses B_i of energies that are given by such
//! profiles (linear, quartic, formula, and a Cosserat energy whose bending
//! part has them). Only the continuation lenses (`continuation/lens.rs`)
//! and the longest arm's control paths edit a material this way, so these
//! hooks sit apart from [`StoredEnergy`], which is what every stage reads;
//! an energy reaches them through [`StoredEnergy::profile_edits`].

use std::sync::Arc;

use super::{Profile, StoredEnergy};

/// Which profile of an energy [`ProfileEdits::with_constant`] sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileKind {
    /// The stiffness B_i.
    Stiffness,
    /// The intrinsic curvature κ⁰_i.
    IntrinsicCurvature,
}

/// The same material with one of its profiles changed.
pub trait ProfileEdits {
    /// The intrinsic curvature profiles κ⁰1, κ⁰2, κ⁰3.
    fn intrinsic_profiles(&self) -> &[Profile; 3];
    /// The same material with κ⁰(s) multiplied by `factor` (None when its
    /// checked constructor refuses the result): the control path of a
    /// designed arm raises κ⁰ with the load (paper Sec. 5).
    fn with_intrinsic_scaled(&self, factor: f64) -> Option<Arc<dyn StoredEnergy>>;
    /// The same material with one constant profile set to `value`: the
    /// stiffness B_i or the intrinsic curvature κ⁰_i. None where that
    /// profile is not a constant (replacing a varying profile by a number
    /// would change the rod silently) and where the material's own checked
    /// constructor refuses the value (a non-finite number, a non-positive
    /// stiffness). Every other part of the material (the other profiles, a
    /// shear and extension part) is kept. Continuation in
    /// `energy.stiffness[i]` or `energy.intrinsic_curvature[i]`.
    fn with_constant(
        &self,
        profile: ProfileKind,
        i: usize,
        value: f64,
    ) -> Option<Arc<dyn StoredEnergy>>;
    /// The same material with κ⁰ = (1 − p) κ⁰_self + p κ⁰_target (None
    /// when the target has no κ⁰ profiles or they do not blend): a control
    /// moving κ⁰ from one profile to another while the load is applied.
    fn with_intrinsic_towards(
        &self,
        target: &dyn StoredEnergy,
        p: f64,
    ) -> Option<Arc<dyn StoredEnergy>>;
}

/// The intrinsic curvature profiles of `energy`, where it has them.
pub fn intrinsic_profiles(energy: &dyn StoredEnergy) -> Option<&[Profile; 3]> {
    energy.profile_edits().map(ProfileEdits::intrinsic_profiles)
}
