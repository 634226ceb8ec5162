//! Energies written once, generic over the number type: [`Density`] gives
//! W(s, κ) for any dual number, [`AutoDiff`] turns it into a
//! [`StoredEnergy`] whose moment, stiffness, s-rates and third derivative
//! are exact by forward-mode automatic differentiation (num-dual).
//!
//! One evaluation over a second-order vector dual number (value, gradient
//! and Hessian in the three strains; `Dual2SVec<_, 3>`) gives W, M = ∇W
//! and H = ∇²W. The s-rates ∂s∇W, ∂sH (at fixed κ) and the contraction
//! ∂(H v)/∂κ = Σ_k W_ijk v_k come from the same evaluation with a
//! first-order dual (`Dual64`) inside each entry, seeded with the
//! s-direction or with v: exact to rounding, no step size. The equations
//! need no higher derivative in s, so a profile of s may be lifted to first
//! order ([`lift`]).

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::{Const, Matrix3, Vector3, U1};
use num_dual::{Derivative, Dual2SVec, Dual64, DualNum};

use super::StoredEnergy;

/// A stored energy density W(s, κ) written once for any number type.
///
/// ```
/// use cosserat::model::{AutoDiff, Density, StoredEnergy};
/// use num_dual::DualNum;
///
/// /// W = B/a² Σ (cosh(a κ_i) − 1): linear for small κ, stiffening beyond 1/a.
/// #[derive(Debug)]
/// struct Hyperbolic { b: f64, a: f64 }
///
/// impl Density for Hyperbolic {
///     fn density<D: DualNum<Primitive = f64> + Copy>(&self, _s: D, k: [D; 3]) -> D {
///         k.iter().map(|&x| ((x * self.a).cosh() - 1.0) * (self.b / (self.a * self.a))).sum()
///     }
///     fn name(&self) -> &str { "hyperbolic" }
///     fn admits_planar_bending(&self) -> bool { true }
/// }
///
/// let e = AutoDiff::new(Hyperbolic { b: 2.0, a: 0.5 });
/// let h = e.stiffness(0.0, &nalgebra::Vector3::new(0.0, 1.0, 0.0));
/// assert!((h[(1, 1)] - 2.0 * 0.5f64.cosh()).abs() < 1e-14);
/// ```
pub trait Density: std::fmt::Debug + Send + Sync {
    /// W(s, κ) ≥ 0 in the arithmetic of `D`; C³ in κ, C¹ in s, with a
    /// positive definite Hessian in κ where the rod lives.
    fn density<D: DualNum<Primitive = f64> + Copy>(&self, s: D, kappa: [D; 3]) -> D;
    /// A short name for reports.
    fn name(&self) -> &str;
    /// True when M1 = M3 = 0 whenever κ1 = κ3 = 0 (e.g. W even in
    /// (κ1, κ3)): the rod may then run the planar equations.
    fn admits_planar_bending(&self) -> bool {
        false
    }
}

/// A profile value `value` with s-rate `rate` at `s`, lifted to the number
/// type of `s` to first order: exact for the first s-derivative, the only
/// one the equations use.
pub fn lift<D: DualNum<Primitive = f64> + Copy>(s: D, value: f64, rate: f64) -> D {
    (s - s.re()) * rate + value
}

/// The [`StoredEnergy`] of a [`Density`], derivatives by automatic
/// differentiation.
#[derive(Debug, Clone)]
pub struct AutoDiff<E: Density> {
    density: E,
    id: u64,
}

impl<E: Density> AutoDiff<E> {
    /// The energy of `density`.
    pub fn new(density: E) -> Self {
        AutoDiff {
            density,
            id: new_identity(),
        }
    }

    /// The density.
    pub fn density_function(&self) -> &E {
        &self.density
    }
}

/// ∇W and ∇²W at (s, κ) over `Dual64` entries, the inner dual parts
/// seeded by `seed(i, value)` for κ_i (i < 3) and for s (i = 3).
pub(super) fn second_order<E: Density + ?Sized>(
    e: &E,
    s: f64,
    kappa: &Vector3<f64>,
    seed: impl Fn(usize, f64) -> Dual64,
) -> (Vector3<Dual64>, Matrix3<Dual64>) {
    let k: [Dual2SVec<Dual64, 3>; 3] =
        std::array::from_fn(|i| Dual2SVec::from_re(seed(i, kappa[i])).derivative(i));
    let w = e.density(Dual2SVec::from_re(seed(3, s)), k);
    (gradient(&w.v1), hessian(&w.v2))
}

fn gradient(d: &Derivative<Dual64, U1, Const<3>>) -> Vector3<Dual64> {
    match &d.0 {
        Some(m) => Vector3::new(m[0], m[1], m[2]),
        // No entry: W does not depend on the strains.
        None => Vector3::from_element(Dual64::from(0.0)),
    }
}

fn hessian(d: &Derivative<Dual64, Const<3>, Const<3>>) -> Matrix3<Dual64> {
    match &d.0 {
        Some(m) => Matrix3::from_fn(|i, j| m[(i, j)]),
        None => Matrix3::from_element(Dual64::from(0.0)),
    }
}

/// The inner direction along s.
pub(super) fn along_s(i: usize, v: f64) -> Dual64 {
    Dual64::new(v, if i == 3 { 1.0 } else { 0.0 })
}

/// The inner direction v in κ.
pub(super) fn along(v: &Vector3<f64>) -> impl Fn(usize, f64) -> Dual64 + '_ {
    move |i, value| Dual64::new(value, if i < 3 { v[i] } else { 0.0 })
}

/// M, H and their s-rates at one (s, κ): what one evaluation seeded along
/// s gives, and what the equations ask for one after the other.
#[derive(Debug, Clone, Copy)]
pub(super) struct Jet {
    pub m: Vector3<f64>,
    pub h: Matrix3<f64>,
    pub m_s: Vector3<f64>,
    pub h_s: Matrix3<f64>,
}

/// A jet with its key: the energy's identity, s and κ.
type CachedJet = (u64, f64, [f64; 3], Jet);

thread_local! {
    /// The last jet computed on this thread, with the identity of its
    /// energy and its (s, κ): the equations ask for H, ∂sM and ∂sH (or M
    /// and H) at the same point in turn, and one evaluation gives all.
    static LAST_JET: Cell<Option<CachedJet>> = const { Cell::new(None) };
}

/// A new identity for an energy value (every constructed or modified
/// energy gets its own, so the jet cache never answers for another).
pub(super) fn new_identity() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// The jet of `e` (identity `id`) at (s, κ), from the cache when this
/// thread's last jet was at the same point of the same energy.
pub(super) fn jet<E: Density + ?Sized>(e: &E, id: u64, s: f64, kappa: &Vector3<f64>) -> Jet {
    let key = [kappa[0], kappa[1], kappa[2]];
    if let Some((i, at, k, jet)) = LAST_JET.get() {
        if i == id && at.to_bits() == s.to_bits() && k.map(f64::to_bits) == key.map(f64::to_bits) {
            return jet;
        }
    }
    let (g, h) = second_order(e, s, kappa, along_s);
    let jet = Jet {
        m: g.map(|d| d.re),
        h: h.map(|d| d.re),
        m_s: g.map(|d| d.eps),
        h_s: h.map(|d| d.eps),
    };
    LAST_JET.set(Some((id, s, key, jet)));
    jet
}

impl<E: Density> StoredEnergy for AutoDiff<E> {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        self.density.density(s, [kappa[0], kappa[1], kappa[2]])
    }

    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        jet(&self.density, self.id, s, kappa).m
    }

    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        jet(&self.density, self.id, s, kappa).h
    }

    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        jet(&self.density, self.id, s, kappa).m_s
    }

    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        jet(&self.density, self.id, s, kappa).h_s
    }

    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        second_order(&self.density, s, kappa, along(v))
            .1
            .map(|d| d.eps)
    }

    /// Exact by automatic differentiation.
    fn derivatives_trusted(&self) -> bool {
        true
    }

    fn admits_planar_bending(&self) -> bool {
        self.density.admits_planar_bending()
    }

    fn name(&self) -> &str {
        self.density.name()
    }
}
