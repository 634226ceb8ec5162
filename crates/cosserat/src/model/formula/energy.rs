//! [`FormulaEnergy`]: a [`StoredEnergy`] given by a [`Formula`]. Its
//! derivatives are the formula's symbolic derivative trees (differentiated
//! once when read, evaluated in `f64`); a formula whose trees would be too
//! large uses forward-mode automatic differentiation instead
//! ([`crate::model::autodiff`]: the formula is a [`Density`] whose profiles
//! B_i(s), κ⁰_i(s) are lifted to the number type of s). The tests check
//! each against the other.

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use num_dual::DualNum;

use super::derivative::{CURVATURE_RATE, DIRECTION, PAIRS, SLOTS, STIFFNESS_RATE};
use super::expr::Expr;
use super::{Formula, Variable};
use crate::model::autodiff::{along, jet, lift, new_identity, second_order, Density};
use crate::model::strain_autodiff::{strain_contraction, strain_jet_of};
use crate::model::{
    intrinsic_profiles, Profile, ProfileEdits, ProfileKind, StoredEnergy, StrainDensity,
    StrainEnergy, StrainJet,
};

/// W(s, κ) = formula(s, κ − κ⁰(s), B(s)), with the file's stiffness and
/// intrinsic-curvature profiles.
#[derive(Debug, Clone)]
pub struct FormulaEnergy {
    formula: Arc<Formula>,
    stiffness: [Profile; 3],
    kappa0: [Profile; 3],
    /// Renewed whenever a profile changes (the jet cache's key).
    id: u64,
}

/// Why a formula cannot be a bending-twisting energy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormulaEnergyError(pub String);

impl FormulaEnergy {
    /// The energy of `formula` over the profiles. A formula that reads the
    /// shear-extension strains `v1, v2, v3` (ν itself: v3 = 1 unstrained,
    /// so an extension energy is written in `v3 - 1`) is a Cosserat energy
    /// W(s, κ, ν) ([`StoredEnergy::strain_energy`]); one that does not is
    /// the bending and twisting energy W(s, κ). Never refused today; the
    /// `Result` keeps the constructor checked for future conditions.
    pub fn new(
        formula: Formula,
        stiffness: [Profile; 3],
        kappa0: [Profile; 3],
    ) -> Result<Self, FormulaEnergyError> {
        Ok(FormulaEnergy {
            formula: Arc::new(formula),
            stiffness,
            kappa0,
            id: new_identity(),
        })
    }

    /// The formula.
    pub fn formula(&self) -> &Formula {
        &self.formula
    }

    /// The inputs of the symbolic derivatives at (s, κ), with direction v.
    fn slots(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> [f64; SLOTS] {
        let mut x = [0.0; SLOTS];
        x[Variable::ArcLength.slot()] = s;
        x[Variable::ShearExtension(2).slot()] = 1.0;
        for i in 0..3 {
            let (k0, b) = (&self.kappa0[i], &self.stiffness[i]);
            x[Variable::Curvature(i).slot()] = kappa[i] - k0.value(s);
            x[Variable::Stiffness(i).slot()] = b.value(s);
            x[STIFFNESS_RATE + i] = b.derivative(s);
            x[CURVATURE_RATE + i] = k0.derivative(s);
            x[DIRECTION + i] = v[i];
        }
        x
    }

    /// The vector of three trees at x.
    fn vector(trees: &[Expr; 3], x: &[f64]) -> Vector3<f64> {
        Vector3::from_fn(|i, _| trees[i].eval(x))
    }

    /// The symmetric matrix of six trees (upper triangle) at x.
    fn symmetric(trees: &[Expr; 6], x: &[f64]) -> Matrix3<f64> {
        let mut m = Matrix3::zeros();
        for (t, &(i, j)) in trees.iter().zip(&PAIRS) {
            m[(i, j)] = t.eval(x);
            m[(j, i)] = m[(i, j)];
        }
        m
    }

    /// A copy with its profiles about to change: a new identity.
    fn modified(&self) -> Self {
        FormulaEnergy {
            id: new_identity(),
            ..self.clone()
        }
    }
}

impl FormulaEnergy {
    /// Whether the formula reads v1, v2 or v3: a Cosserat energy.
    fn shears(&self) -> bool {
        (0..3).any(|i| self.formula.reads(Variable::ShearExtension(i)))
    }
}

impl StrainDensity for FormulaEnergy {
    /// The formula at s, with k = κ − κ⁰(s), v = ν and B(s).
    fn strain_density<D: DualNum<Primitive = f64> + Copy>(
        &self,
        s: D,
        kappa: [D; 3],
        nu: [D; 3],
    ) -> D {
        let at = s.re();
        let mut x = [D::from(0.0); 10];
        x[Variable::ArcLength.slot()] = s;
        for i in 0..3 {
            x[Variable::ShearExtension(i).slot()] = nu[i];
        }
        for i in 0..3 {
            let k0 = &self.kappa0[i];
            x[Variable::Curvature(i).slot()] = kappa[i] - lift(s, k0.value(at), k0.derivative(at));
            let b = &self.stiffness[i];
            x[Variable::Stiffness(i).slot()] = lift(s, b.value(at), b.derivative(at));
        }
        self.formula.value(&x)
    }

    fn name(&self) -> &'static str {
        "formula"
    }
}

/// The derivatives in all six strains by automatic differentiation (the
/// symbolic trees cover the κ-derivatives at ν = e3 only).
impl StrainEnergy for FormulaEnergy {
    fn strain_density(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> f64 {
        StrainDensity::strain_density(
            self,
            s,
            [kappa[0], kappa[1], kappa[2]],
            [nu[0], nu[1], nu[2]],
        )
    }

    fn strain_jet(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> StrainJet {
        strain_jet_of(self, s, kappa, nu)
    }

    fn strain_hessian_derivative(
        &self,
        s: f64,
        kappa: &Vector3<f64>,
        nu: &Vector3<f64>,
        v: &Vector6<f64>,
    ) -> Matrix6<f64> {
        strain_contraction(self, s, kappa, nu, v)
    }
}

impl Density for FormulaEnergy {
    /// The formula at s, with k = κ − κ⁰(s), v = e3 and B(s).
    fn density<D: DualNum<Primitive = f64> + Copy>(&self, s: D, kappa: [D; 3]) -> D {
        let e3 = [D::from(0.0), D::from(0.0), D::from(1.0)];
        StrainDensity::strain_density(self, s, kappa, e3)
    }

    fn name(&self) -> &'static str {
        "formula"
    }

    /// Proved from the formula's structure: W even under (k1, k3) →
    /// (−k1, −k3) and κ⁰₁ = κ⁰₃ = 0 give M1 = M3 = 0 on κ1 = κ3 = 0
    /// (R∇W(Rκ) = ∇W(κ) with R the sign change). Not proved: the rod runs
    /// the three-dimensional equations. A formula in ν is proved even
    /// under the whole planar reflection (k1, k3, v2) → (−k1, −k3, −v2):
    /// a rod bending in the d1–d3 plane has out-of-plane shear ν2, and the
    /// reflection about that plane flips it with the out-of-plane turns
    /// (then m1 = m3 = N2 = 0 on κ1 = κ3 = ν2 = 0).
    fn admits_planar_bending(&self) -> bool {
        let mut flipped = vec![Variable::Curvature(0), Variable::Curvature(2)];
        if self.shears() {
            flipped.push(Variable::ShearExtension(1));
        }
        self.kappa0[0].is_zero() && self.kappa0[2].is_zero() && self.formula.is_even_in(&flipped)
    }
}

impl StoredEnergy for FormulaEnergy {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        Density::density(self, s, [kappa[0], kappa[1], kappa[2]])
    }

    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        match self.formula.derivatives() {
            Some(d) => Self::vector(&d.moment, &self.slots(s, kappa, &Vector3::zeros())),
            None => jet(self, self.id, s, kappa).m,
        }
    }

    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        match self.formula.derivatives() {
            Some(d) => Self::symmetric(&d.stiffness, &self.slots(s, kappa, &Vector3::zeros())),
            None => jet(self, self.id, s, kappa).h,
        }
    }

    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        match self.formula.derivatives() {
            Some(d) => Self::vector(&d.moment_rate, &self.slots(s, kappa, &Vector3::zeros())),
            None => jet(self, self.id, s, kappa).m_s,
        }
    }

    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        match self.formula.derivatives() {
            Some(d) => Self::symmetric(&d.stiffness_rate, &self.slots(s, kappa, &Vector3::zeros())),
            None => jet(self, self.id, s, kappa).h_s,
        }
    }

    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        match self.formula.derivatives() {
            Some(d) => Self::symmetric(&d.contracted, &self.slots(s, kappa, v)),
            None => second_order(self, s, kappa, along(v)).1.map(|d| d.eps),
        }
    }

    /// Exact: symbolic derivatives, or automatic differentiation.
    fn derivatives_trusted(&self) -> bool {
        true
    }

    /// Constant profiles and a formula that does not read s.
    fn is_uniform(&self) -> bool {
        let constant = |p: &Profile| matches!(p, Profile::Constant(_));
        self.stiffness.iter().all(constant)
            && self.kappa0.iter().all(constant)
            && !self.formula.reads(Variable::ArcLength)
    }

    /// Proved from the formula's structure, component by component.
    fn even_components(&self) -> [bool; 3] {
        std::array::from_fn(|i| self.formula.is_even_in(&[Variable::Curvature(i)]))
    }

    fn admits_planar_bending(&self) -> bool {
        Density::admits_planar_bending(self)
    }

    fn name(&self) -> &'static str {
        "formula"
    }

    /// The formula's own W(s, κ, ν) when it reads v1, v2 or v3.
    fn strain_energy(&self) -> Option<&dyn StrainEnergy> {
        self.shears().then_some(self as &dyn StrainEnergy)
    }

    fn profile_edits(&self) -> Option<&dyn ProfileEdits> {
        Some(self)
    }
}

impl ProfileEdits for FormulaEnergy {
    fn intrinsic_profiles(&self) -> &[Profile; 3] {
        &self.kappa0
    }

    fn with_intrinsic_scaled(&self, factor: f64) -> Option<Arc<dyn StoredEnergy>> {
        let mut e = self.modified();
        e.kappa0 = self.kappa0.clone().map(|p| p.scaled(factor));
        Some(Arc::new(e))
    }

    fn with_constant(
        &self,
        profile: ProfileKind,
        i: usize,
        value: f64,
    ) -> Option<Arc<dyn StoredEnergy>> {
        let mut e = self.modified();
        let slot = match profile {
            ProfileKind::Stiffness if value > 0.0 => &mut e.stiffness[i],
            ProfileKind::IntrinsicCurvature => &mut e.kappa0[i],
            ProfileKind::Stiffness => return None,
        };
        if !value.is_finite() || !matches!(slot, Profile::Constant(_)) {
            return None;
        }
        *slot = Profile::Constant(value);
        Some(Arc::new(e))
    }

    fn with_intrinsic_towards(
        &self,
        target: &dyn StoredEnergy,
        p: f64,
    ) -> Option<Arc<dyn StoredEnergy>> {
        let other = intrinsic_profiles(target)?;
        let mut e = self.modified();
        for (slot, (mine, theirs)) in e.kappa0.iter_mut().zip(self.kappa0.iter().zip(other)) {
            *slot = mine.blend(theirs, p)?;
        }
        Some(Arc::new(e))
    }
}
