//! Energies W(s, κ, ν) written once, generic over the number type:
//! [`StrainDensity`] gives W for any dual number, [`StrainAutoDiff`] turns
//! it into a [`StoredEnergy`] with a [`StrainEnergy`] whose gradient,
//! 6 × 6 Hessian, s-rates and third derivative are exact by forward-mode
//! automatic differentiation (num-dual), as [`super::AutoDiff`] does for
//! W(s, κ): one evaluation over `Dual2SVec<Dual64, 6>` gives ∇W and ∇²W in
//! the six strains, the inner `Dual64` seeded with the s-direction (the
//! s-rates) or with a direction v (the contraction Σ_k W_ijk v_k).

use nalgebra::{Const, Matrix3, Matrix6, Vector3, Vector6, U1};
use num_dual::{Derivative, Dual2SVec, Dual64, DualNum};

use super::strain::{StrainEnergy, StrainJet};
use super::StoredEnergy;

/// A stored energy density W(s, κ, ν) written once for any number type
/// (ν = e3 = (0, 0, 1) unstrained).
///
/// ```
/// use cosserat::model::{StrainAutoDiff, StrainDensity, StoredEnergy};
/// use num_dual::DualNum;
///
/// /// Bending, shear and a stiffening axial law φ(ν3) = ½EA(ν3 − 1)² + ¼c(ν3 − 1)⁴.
/// #[derive(Debug)]
/// struct Stiffening;
///
/// impl StrainDensity for Stiffening {
///     fn strain_density<D: DualNum<Primitive = f64> + Copy>(&self, _s: D, k: [D; 3], v: [D; 3]) -> D {
///         let e = v[2] - 1.0;
///         (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]) * 0.5 + (v[0] * v[0] + v[1] * v[1]) * 50.0
///             + e * e * 50.0 + e.powi(4) * 250.0
///     }
///     fn name(&self) -> &str { "stiffening" }
/// }
///
/// let e = StrainAutoDiff::new(Stiffening);
/// assert!(e.strain_energy().is_some());
/// ```
pub trait StrainDensity: std::fmt::Debug + Send + Sync {
    /// W(s, κ, ν) ≥ 0 in the arithmetic of `D`; C³ in the strains, C¹ in
    /// s, with a positive definite 6 × 6 Hessian where the rod lives.
    fn strain_density<D: DualNum<Primitive = f64> + Copy>(
        &self,
        s: D,
        kappa: [D; 3],
        nu: [D; 3],
    ) -> D;
    /// A short name for reports.
    fn name(&self) -> &str;
}

/// ∇W and ∇²W at (s, z) over `Dual64` entries, the inner dual parts
/// seeded by `seed(i, value)` for z_i (i < 6) and for s (i = 6).
pub(super) fn strain_second_order<E: StrainDensity + ?Sized>(
    e: &E,
    s: f64,
    z: &Vector6<f64>,
    seed: impl Fn(usize, f64) -> Dual64,
) -> (Vector6<Dual64>, Matrix6<Dual64>) {
    let x: [Dual2SVec<Dual64, 6>; 6] =
        std::array::from_fn(|i| Dual2SVec::from_re(seed(i, z[i])).derivative(i));
    let w = e.strain_density(
        Dual2SVec::from_re(seed(6, s)),
        [x[0], x[1], x[2]],
        [x[3], x[4], x[5]],
    );
    (gradient(&w.v1), hessian(&w.v2))
}

fn gradient(d: &Derivative<Dual64, U1, Const<6>>) -> Vector6<Dual64> {
    match &d.0 {
        Some(m) => Vector6::from_fn(|i, _| m[i]),
        None => Vector6::from_element(Dual64::from(0.0)),
    }
}

fn hessian(d: &Derivative<Dual64, Const<6>, Const<6>>) -> Matrix6<Dual64> {
    match &d.0 {
        Some(m) => Matrix6::from_fn(|i, j| m[(i, j)]),
        None => Matrix6::from_element(Dual64::from(0.0)),
    }
}

/// The jet of W at (s, κ, ν): one evaluation seeded along s.
pub(super) fn strain_jet_of<E: StrainDensity + ?Sized>(
    e: &E,
    s: f64,
    kappa: &Vector3<f64>,
    nu: &Vector3<f64>,
) -> StrainJet {
    let z = super::strain::stack(kappa, nu);
    let (g, h) = strain_second_order(e, s, &z, |i, v| {
        Dual64::new(v, if i == 6 { 1.0 } else { 0.0 })
    });
    StrainJet {
        gradient: g.map(|d| d.re),
        hessian: h.map(|d| d.re),
        gradient_rate: g.map(|d| d.eps),
        hessian_rate: h.map(|d| d.eps),
    }
}

/// Σ_k W_ijk v_k at (s, κ, ν): one evaluation seeded along v.
pub(super) fn strain_contraction<E: StrainDensity + ?Sized>(
    e: &E,
    s: f64,
    kappa: &Vector3<f64>,
    nu: &Vector3<f64>,
    v: &Vector6<f64>,
) -> Matrix6<f64> {
    let z = super::strain::stack(kappa, nu);
    strain_second_order(e, s, &z, |i, value| {
        Dual64::new(value, if i < 6 { v[i] } else { 0.0 })
    })
    .1
    .map(|d| d.eps)
}

/// The [`StoredEnergy`] of a [`StrainDensity`]: a Cosserat energy whose
/// κ-methods are W at ν = e3, derivatives by automatic differentiation.
#[derive(Debug, Clone)]
pub struct StrainAutoDiff<E: StrainDensity> {
    density: E,
}

impl<E: StrainDensity> StrainAutoDiff<E> {
    /// The energy of `density`.
    pub fn new(density: E) -> Self {
        StrainAutoDiff { density }
    }

    /// The density.
    pub fn density_function(&self) -> &E {
        &self.density
    }

    fn kirchhoff(&self, s: f64, kappa: &Vector3<f64>) -> StrainJet {
        strain_jet_of(&self.density, s, kappa, &Vector3::z())
    }
}

/// The κ-block of a 6-vector.
fn upper(v: &Vector6<f64>) -> Vector3<f64> {
    v.fixed_rows::<3>(0).into_owned()
}

/// The κκ-block of a 6 × 6 matrix.
fn corner(m: &Matrix6<f64>) -> Matrix3<f64> {
    m.fixed_view::<3, 3>(0, 0).into_owned()
}

impl<E: StrainDensity> StoredEnergy for StrainAutoDiff<E> {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        self.strain_density(s, kappa, &Vector3::z())
    }

    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        upper(&self.kirchhoff(s, kappa).gradient)
    }

    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        corner(&self.kirchhoff(s, kappa).hessian)
    }

    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        upper(&self.kirchhoff(s, kappa).gradient_rate)
    }

    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        corner(&self.kirchhoff(s, kappa).hessian_rate)
    }

    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        let v6 = super::strain::stack(v, &Vector3::zeros());
        corner(&strain_contraction(
            &self.density,
            s,
            kappa,
            &Vector3::z(),
            &v6,
        ))
    }

    /// The Cosserat level runs three-dimensional equations.
    fn admits_planar_bending(&self) -> bool {
        false
    }

    fn name(&self) -> &str {
        self.density.name()
    }

    /// Exact by automatic differentiation.
    fn derivatives_trusted(&self) -> bool {
        true
    }

    fn strain_energy(&self) -> Option<&dyn StrainEnergy> {
        Some(self)
    }
}

impl<E: StrainDensity> StrainEnergy for StrainAutoDiff<E> {
    fn strain_density(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> f64 {
        self.density
            .strain_density(s, [kappa[0], kappa[1], kappa[2]], [nu[0], nu[1], nu[2]])
    }

    fn strain_jet(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> StrainJet {
        strain_jet_of(&self.density, s, kappa, nu)
    }

    fn strain_hessian_derivative(
        &self,
        s: f64,
        kappa: &Vector3<f64>,
        nu: &Vector3<f64>,
        v: &Vector6<f64>,
    ) -> Matrix6<f64> {
        strain_contraction(&self.density, s, kappa, nu, v)
    }
}
