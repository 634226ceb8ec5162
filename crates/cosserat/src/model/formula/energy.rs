//! [`FormulaEnergy`]: a [`StoredEnergy`] given by a [`Formula`], its
//! derivatives by forward-mode automatic differentiation.
//!
//! With u = κ − κ⁰(s) the formula's `k`, one evaluation over a
//! second-order vector dual number (value, gradient, Hessian in the three
//! strains; num-dual's `Dual2SVec64<3>`) gives W, M = ∇W and H = ∇²W. The
//! s-rates ∂s∇W, ∂sH (at fixed κ, so u moves by −κ⁰′(s) and B_i by
//! B_i′(s)) and the contraction ∂(H v)/∂κ = Σ_k W_ijk v_k come from the
//! same evaluation with a first-order dual (`Dual64`) inside each entry,
//! seeded with the s-direction or with v: exact to rounding, no step size.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};
use num_dual::{Derivative, Dual2SVec, Dual64, DualNum};

use super::expr::Inputs;
use super::{Formula, Variable};
use crate::model::{Profile, ProfileKind, StoredEnergy};

/// W(s, κ) = formula(s, κ − κ⁰(s), B(s)), with the file's stiffness and
/// intrinsic-curvature profiles.
#[derive(Debug, Clone)]
pub struct FormulaEnergy {
    formula: Arc<Formula>,
    stiffness: [Profile; 3],
    kappa0: [Profile; 3],
}

/// Why a formula cannot be a bending-twisting energy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormulaEnergyError(pub String);

impl FormulaEnergy {
    /// The energy of `formula` over the profiles; refused when the formula
    /// reads the shear-extension strains `v1, v2, v3` (a quadratic shear
    /// and extension part is added by `energy.shear`).
    pub fn new(
        formula: Formula,
        stiffness: [Profile; 3],
        kappa0: [Profile; 3],
    ) -> Result<Self, FormulaEnergyError> {
        if (0..3).any(|i| formula.reads(Variable::ShearExtension(i))) {
            return Err(FormulaEnergyError(
                "reads v1, v2 or v3: a formula is, for now, the bending and twisting energy \
                 W(s, k); give a quadratic shear and extension part with energy.shear"
                    .into(),
            ));
        }
        Ok(FormulaEnergy {
            formula: Arc::new(formula),
            stiffness,
            kappa0,
        })
    }

    /// The formula.
    pub fn formula(&self) -> &Formula {
        &self.formula
    }

    /// The inputs at s, κ for a number type whose value parts are set by
    /// `lift` from (value, s-rate) of each input.
    fn inputs<D: DualNum<Primitive = f64> + Copy>(
        &self,
        s: f64,
        kappa: &Vector3<f64>,
        lift: impl Fn(usize, f64, f64) -> D,
    ) -> Inputs<D> {
        let mut x = [D::from(0.0); 10];
        x[Variable::ArcLength.slot()] = lift(usize::MAX, s, 1.0);
        for i in 0..3 {
            let u = kappa[i] - self.kappa0[i].value(s);
            x[Variable::Curvature(i).slot()] = lift(i, u, -self.kappa0[i].derivative(s));
            x[Variable::ShearExtension(i).slot()] = D::from(if i == 2 { 1.0 } else { 0.0 });
            x[Variable::Stiffness(i).slot()] = lift(
                usize::MAX,
                self.stiffness[i].value(s),
                self.stiffness[i].derivative(s),
            );
        }
        x
    }

    /// W, ∇W, ∇²W in the strains, with an inner dual part seeded by
    /// `inner(i, value, s-rate)` (i = usize::MAX for s and B).
    fn second_order(
        &self,
        s: f64,
        kappa: &Vector3<f64>,
        inner: impl Fn(usize, f64, f64) -> Dual64,
    ) -> (Vector3<Dual64>, Matrix3<Dual64>) {
        let x = self.inputs::<Dual2SVec<Dual64, 3>>(s, kappa, |i, v, rate| {
            let d = Dual2SVec::from_re(inner(i, v, rate));
            if i < 3 {
                d.derivative(i)
            } else {
                d
            }
        });
        let w = self.formula.value(&x);
        (gradient(&w.v1), hessian(&w.v2))
    }
}

fn gradient<T: DualNum<Primitive = f64> + Copy>(
    d: &Derivative<T, nalgebra::U1, nalgebra::Const<3>>,
) -> Vector3<T> {
    match &d.0 {
        Some(m) => Vector3::new(m[0], m[1], m[2]),
        // No entry: the formula does not depend on the strains.
        None => Vector3::from_element(T::from(0.0)),
    }
}

fn hessian<T: DualNum<Primitive = f64> + Copy>(
    d: &Derivative<T, nalgebra::Const<3>, nalgebra::Const<3>>,
) -> Matrix3<T> {
    match &d.0 {
        Some(m) => Matrix3::from_fn(|i, j| m[(i, j)]),
        None => Matrix3::from_element(T::from(0.0)),
    }
}

/// The inner dual of a plain evaluation (no inner direction).
fn plain(_: usize, v: f64, _: f64) -> Dual64 {
    Dual64::from(v)
}

/// The inner dual seeded with the s-direction.
fn along_s(_: usize, v: f64, rate: f64) -> Dual64 {
    Dual64::new(v, rate)
}

impl StoredEnergy for FormulaEnergy {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        self.formula.value(&self.inputs(s, kappa, |_, v, _| v))
    }

    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        self.second_order(s, kappa, plain).0.map(|d| d.re)
    }

    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        self.second_order(s, kappa, plain).1.map(|d| d.re)
    }

    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        self.second_order(s, kappa, along_s).0.map(|d| d.eps)
    }

    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        self.second_order(s, kappa, along_s).1.map(|d| d.eps)
    }

    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        let seeded = |i: usize, value: f64, _: f64| {
            if i < 3 {
                Dual64::new(value, v[i])
            } else {
                Dual64::from(value)
            }
        };
        self.second_order(s, kappa, seeded).1.map(|d| d.eps)
    }

    /// Proved from the formula's structure: W even under (k1, k3) →
    /// (−k1, −k3) and κ⁰₁ = κ⁰₃ = 0 give M1 = M3 = 0 on κ1 = κ3 = 0
    /// (R∇W(Rκ) = ∇W(κ) with R the sign change). Not proved: the rod runs
    /// the three-dimensional equations.
    fn admits_planar_bending(&self) -> bool {
        self.kappa0[0].is_zero()
            && self.kappa0[2].is_zero()
            && self
                .formula
                .is_even_in(&[Variable::Curvature(0), Variable::Curvature(2)])
    }

    fn name(&self) -> &'static str {
        "formula"
    }

    /// Exact by automatic differentiation.
    fn derivatives_trusted(&self) -> bool {
        true
    }

    fn intrinsic_profiles(&self) -> Option<&[Profile; 3]> {
        Some(&self.kappa0)
    }

    fn with_intrinsic_scaled(&self, factor: f64) -> Option<Arc<dyn StoredEnergy>> {
        let mut e = self.clone();
        e.kappa0 = self.kappa0.clone().map(|p| p.scaled(factor));
        Some(Arc::new(e))
    }

    fn with_constant(
        &self,
        profile: ProfileKind,
        i: usize,
        value: f64,
    ) -> Option<Arc<dyn StoredEnergy>> {
        let mut e = self.clone();
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
        let other = target.intrinsic_profiles()?;
        let mut e = self.clone();
        for (slot, (mine, theirs)) in e.kappa0.iter_mut().zip(self.kappa0.iter().zip(other)) {
            *slot = mine.blend(theirs, p)?;
        }
        Some(Arc::new(e))
    }
}
