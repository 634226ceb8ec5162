//! Stored energy densities W(s, κ) of a hyperelastic Kirchhoff rod.
//!
//! The body moment is M = ∂W/∂κ and the bending/torsion stiffness is the
//! Hessian H = ∂²W/∂κ², κ the director components of the Darboux vector
//! k = κ_i d_i (d_i' = k × d_i). The equilibrium equations are the balance
//! laws n' + f = 0 and m' + r' × n = 0, in director components
//! M' = M × κ + N × ν (ν = e3 for the Kirchhoff rod; Antman, *Nonlinear
//! Problems of Elasticity*, 2nd ed., Ch. 8). They need κ', which follows
//! from M' = H κ' + ∂s∇W as κ' = H⁻¹(M' − ∂s∇W), so H must be positive
//! definite; their variational
//! equations (the shooting Jacobian) need the derivative of H κ' in κ, a
//! third derivative of W. Every energy supplies all of these, so that any
//! hyperelastic material plugs into the same equations.

use nalgebra::{Matrix3, Vector3};

use super::profile::Profile;
use super::profile_edits::{intrinsic_profiles, ProfileEdits, ProfileKind};
use super::ModelError;

/// A stored energy density per unit reference length, W(s, κ) ≥ 0, C² in κ
/// with positive definite Hessian.
pub trait StoredEnergy: std::fmt::Debug + Send + Sync {
    /// W(s, κ).
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64;
    /// The body moment M = ∂W/∂κ (body components).
    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64>;
    /// The stiffness H = ∂²W/∂κ² (symmetric, positive definite).
    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64>;
    /// ∂M/∂s at fixed κ: the explicit s-dependence of the moment
    /// (tapered rods, varying intrinsic curvature).
    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64>;
    /// ∂H/∂s at fixed κ.
    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64>;
    /// ∂(H(κ) v)/∂κ for a fixed vector v: the third derivative of W
    /// contracted with v (zero for quadratic energies).
    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64>;
    /// True when M1 = M3 = 0 whenever κ1 = κ3 = 0, for every κ2 and s: the
    /// energy then admits planar equilibria bent about d2 (planar model).
    fn admits_planar_bending(&self) -> bool;
    /// The strain components i in which W is claimed even about the
    /// intrinsic curvature ([`super::ProfileEdits::intrinsic_profiles`], zero for
    /// an energy without them): W(s, κ⁰ + u) = W(s, κ⁰ + R_i u), R_i flipping
    /// the sign of u_i (a cross-section symmetric about a principal axis).
    /// Checked by [`super::energy_check`]; none claimed by default.
    fn even_components(&self) -> [bool; 3] {
        [false; 3]
    }
    /// A short name for reports ("linear", "quartic", ...).
    fn name(&self) -> &str;
    /// True when H does not depend on κ or on κ⁰ (a quadratic energy in
    /// κ − κ⁰): the second variation of a fixed shape is then linear in
    /// the load (paper Sec. 2.5).
    fn is_quadratic(&self) -> bool {
        false
    }
    /// Whether the derivatives are exact by construction or verified in
    /// this crate's tests (the built-in energies against automatic
    /// differentiation, crates/cosserat/tests/formula_energy.rs; formulas,
    /// differentiated automatically). Otherwise — a program's own energy —
    /// the solver checks them with [`super::energy_check`] before and
    /// after every solve, and refuses an energy that fails.
    fn derivatives_trusted(&self) -> bool {
        false
    }
    /// True when W has no explicit s-dependence (every profile constant):
    /// a length change then moves no material property under the rod's
    /// points, which the exact length derivative of continuation assumes
    /// ([`super::RodTangent::fits`]).
    fn is_uniform(&self) -> bool {
        false
    }
    /// The interior points s in (0, L) where W's explicit s-dependence is
    /// not smooth (a piecewise profile's breakpoints, [`Profile::breaks`]),
    /// sorted: the solvers stop there as at a point force
    /// ([`super::Rod::breaks`]). None by default.
    fn breaks(&self, _length: f64) -> Vec<f64> {
        Vec::new()
    }
    /// The stiffnesses S = (S1, S2, S3) of a quadratic shear and extension
    /// energy ½ (ν − e3)ᵀ diag(S) (ν − e3) at s (see [`super::Shearable`]);
    /// None for an unshearable, inextensible (Kirchhoff) rod.
    fn shear_stiffness(&self, _s: f64) -> Option<Vector3<f64>> {
        None
    }
    /// The energy in all six strains, W(s, κ, ν), for an energy that can
    /// shear or extend (None: an unshearable, inextensible rod, whose
    /// equations are the Kirchhoff or planar ones). Where both this and
    /// [`StoredEnergy::shear_stiffness`] are given they describe the same
    /// W, and the equations may take the quadratic fast path.
    fn strain_energy(&self) -> Option<&dyn super::StrainEnergy> {
        None
    }
    /// The edits of the energy's separate profiles (κ⁰, constant B_i),
    /// for energies given by such profiles: what continuation lenses and
    /// the arm's control paths change ([`super::ProfileEdits`]).
    fn profile_edits(&self) -> Option<&dyn ProfileEdits> {
        None
    }
}

/// The linear-elastic energy with intrinsic curvature,
/// W = ½ Σ B_i(s) (κ_i − κ⁰_i(s))² (paper eq. (17) with B_i varying in s).
/// Built by the checked [`LinearElastic::new`]; the profiles are read
/// through [`LinearElastic::stiffness_profiles`] and
/// [`LinearElastic::intrinsic_curvature`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinearElastic {
    stiffness: [Profile; 3],
    intrinsic_curvature: [Profile; 3],
    /// (B, κ⁰) when every profile is a constant, read once: the energy's
    /// values sit in the innermost loop of every integration.
    uniform: Option<(Vector3<f64>, Vector3<f64>)>,
}

impl LinearElastic {
    /// The energy of the stiffness profiles B1, B2 (bending), B3 (torsion)
    /// (N·m²) and the intrinsic curvature κ⁰ in body components (1/m).
    /// Refused with [`ModelError::Stiffness`] when a profile holds a
    /// non-finite number or a constant stiffness is not positive (H =
    /// diag(B) must be positive definite). A varying stiffness (table,
    /// polynomial, spline) is positive only on some interval, which the
    /// energy does not know: the problem reader certifies it positive on
    /// [0, L] ([`Profile::extremes_on`]), and a solve refuses a Hessian
    /// that is not positive definite along the rod.
    pub fn new(
        stiffness: [Profile; 3],
        intrinsic_curvature: [Profile; 3],
    ) -> Result<Self, ModelError> {
        for (index, b) in stiffness.iter().enumerate() {
            let refused = |value| ModelError::Stiffness {
                what: "bending/torsional stiffness B",
                index,
                value,
            };
            match b {
                _ if !b.is_finite() => return Err(refused(f64::NAN)),
                Profile::Constant(c) if *c <= 0.0 => return Err(refused(*c)),
                _ => {}
            }
        }
        if let Some(index) = intrinsic_curvature.iter().position(|k| !k.is_finite()) {
            return Err(ModelError::IntrinsicCurvature { index });
        }
        let constant = |p: &[Profile; 3]| -> Option<Vector3<f64>> {
            let mut v = Vector3::zeros();
            for (i, profile) in p.iter().enumerate() {
                let Profile::Constant(c) = profile else {
                    return None;
                };
                v[i] = *c;
            }
            Some(v)
        };
        let uniform = constant(&stiffness).zip(constant(&intrinsic_curvature));
        Ok(LinearElastic {
            stiffness,
            intrinsic_curvature,
            uniform,
        })
    }

    /// A prismatic rod with constant stiffness B (positive) and intrinsic
    /// curvature κ⁰; refused as in [`LinearElastic::new`].
    pub fn uniform(b: [f64; 3], kappa0: [f64; 3]) -> Result<Self, ModelError> {
        LinearElastic::new(b.map(Profile::Constant), kappa0.map(Profile::Constant))
    }

    /// The stiffness profiles B1, B2, B3 (N·m²).
    pub fn stiffness_profiles(&self) -> &[Profile; 3] {
        &self.stiffness
    }

    /// The intrinsic curvature profiles κ⁰1, κ⁰2, κ⁰3 (1/m).
    pub fn intrinsic_curvature(&self) -> &[Profile; 3] {
        &self.intrinsic_curvature
    }

    fn b(&self, s: f64) -> Vector3<f64> {
        if let Some((b, _)) = self.uniform {
            return b;
        }
        Vector3::from_fn(|i, _| self.stiffness[i].value(s))
    }

    fn b_rate(&self, s: f64) -> Vector3<f64> {
        Vector3::from_fn(|i, _| self.stiffness[i].derivative(s))
    }

    /// κ⁰(s).
    pub fn kappa0(&self, s: f64) -> Vector3<f64> {
        if let Some((_, k0)) = self.uniform {
            return k0;
        }
        Vector3::from_fn(|i, _| self.intrinsic_curvature[i].value(s))
    }

    fn kappa0_rate(&self, s: f64) -> Vector3<f64> {
        Vector3::from_fn(|i, _| self.intrinsic_curvature[i].derivative(s))
    }

    /// A prismatic rod with constant κ⁰: W has no explicit s-dependence,
    /// so its s-derivatives vanish without evaluating six profiles (a fast
    /// path: they sit in the innermost loop of every integration).
    fn is_uniform(&self) -> bool {
        self.uniform.is_some()
    }
}

impl StoredEnergy for LinearElastic {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        let e = kappa - self.kappa0(s);
        0.5 * self.b(s).component_mul(&e).dot(&e)
    }

    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        self.b(s).component_mul(&(kappa - self.kappa0(s)))
    }

    fn stiffness(&self, s: f64, _kappa: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.b(s))
    }

    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        if self.is_uniform() {
            return Vector3::zeros();
        }
        self.b_rate(s).component_mul(&(kappa - self.kappa0(s)))
            - self.b(s).component_mul(&self.kappa0_rate(s))
    }

    fn stiffness_rate(&self, s: f64, _kappa: &Vector3<f64>) -> Matrix3<f64> {
        if self.is_uniform() {
            return Matrix3::zeros();
        }
        Matrix3::from_diagonal(&self.b_rate(s))
    }

    fn stiffness_derivative(&self, _: f64, _: &Vector3<f64>, _: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::zeros()
    }

    fn admits_planar_bending(&self) -> bool {
        self.intrinsic_curvature[0].is_zero() && self.intrinsic_curvature[2].is_zero()
    }

    /// ½ Σ B_i u_i² is even in each u_i.
    fn even_components(&self) -> [bool; 3] {
        [true; 3]
    }

    fn name(&self) -> &'static str {
        "linear"
    }

    fn is_quadratic(&self) -> bool {
        true
    }

    fn derivatives_trusted(&self) -> bool {
        true
    }

    fn is_uniform(&self) -> bool {
        LinearElastic::is_uniform(self)
    }

    /// Every breakpoint of the six profiles.
    fn breaks(&self, length: f64) -> Vec<f64> {
        let mut s: Vec<f64> = self
            .stiffness
            .iter()
            .chain(&self.intrinsic_curvature)
            .flat_map(|p| p.breaks(length))
            .collect();
        s.sort_by(f64::total_cmp);
        s.dedup();
        s
    }

    fn profile_edits(&self) -> Option<&dyn ProfileEdits> {
        Some(self)
    }
}

impl ProfileEdits for LinearElastic {
    fn intrinsic_profiles(&self) -> &[Profile; 3] {
        &self.intrinsic_curvature
    }

    fn with_intrinsic_towards(
        &self,
        target: &dyn StoredEnergy,
        p: f64,
    ) -> Option<std::sync::Arc<dyn StoredEnergy>> {
        let to = intrinsic_profiles(target)?;
        let [a, b, c] = &self.intrinsic_curvature;
        let blended = [
            a.blend(&to[0], p)?,
            b.blend(&to[1], p)?,
            c.blend(&to[2], p)?,
        ];
        Some(std::sync::Arc::new(
            LinearElastic::new(self.stiffness.clone(), blended).ok()?,
        ))
    }

    fn with_intrinsic_scaled(&self, factor: f64) -> Option<std::sync::Arc<dyn StoredEnergy>> {
        let scaled = self.intrinsic_curvature.clone().map(|p| p.scaled(factor));
        Some(std::sync::Arc::new(
            LinearElastic::new(self.stiffness.clone(), scaled).ok()?,
        ))
    }

    fn with_constant(
        &self,
        profile: ProfileKind,
        i: usize,
        value: f64,
    ) -> Option<std::sync::Arc<dyn StoredEnergy>> {
        let (mut stiffness, mut kappa0) =
            (self.stiffness.clone(), self.intrinsic_curvature.clone());
        let slot = match profile {
            ProfileKind::Stiffness => stiffness.get_mut(i)?,
            ProfileKind::IntrinsicCurvature => kappa0.get_mut(i)?,
        };
        if !matches!(slot, Profile::Constant(_)) {
            return None;
        }
        *slot = Profile::Constant(value);
        Some(std::sync::Arc::new(
            LinearElastic::new(stiffness, kappa0).ok()?,
        ))
    }
}

/// The quartic energy's κ⁰ is read (continuation towards it, the
/// derivative checker); its profiles are not edited (no lens needs them).
impl ProfileEdits for QuarticStiffening {
    fn intrinsic_profiles(&self) -> &[Profile; 3] {
        self.linear.intrinsic_curvature()
    }

    fn with_intrinsic_scaled(&self, _factor: f64) -> Option<std::sync::Arc<dyn StoredEnergy>> {
        None
    }

    fn with_constant(
        &self,
        _profile: ProfileKind,
        _i: usize,
        _value: f64,
    ) -> Option<std::sync::Arc<dyn StoredEnergy>> {
        None
    }

    fn with_intrinsic_towards(
        &self,
        _target: &dyn StoredEnergy,
        _p: f64,
    ) -> Option<std::sync::Arc<dyn StoredEnergy>> {
        None
    }
}

/// A material that stiffens with curvature: the linear energy plus a quartic
/// term in the magnitude of the curvature change,
/// W = ½ Σ B_i (κ_i − κ⁰_i)² + ¼ C |κ − κ⁰|⁴.
///
/// The quartic term couples the three components (H is not diagonal) and has
/// a non-zero third derivative, so the equations exercise every method of
/// [`StoredEnergy`]. Built by the checked [`QuarticStiffening::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct QuarticStiffening {
    linear: LinearElastic,
    quartic: f64,
}

impl QuarticStiffening {
    /// The linear energy `linear` stiffened by C = `quartic` (N·m⁴);
    /// refused with [`ModelError::Coefficient`] unless C is finite and
    /// C ≥ 0 (a negative C makes H indefinite at large curvature).
    pub fn new(linear: LinearElastic, quartic: f64) -> Result<Self, ModelError> {
        if quartic.is_finite() && quartic >= 0.0 {
            Ok(QuarticStiffening { linear, quartic })
        } else {
            Err(ModelError::Coefficient {
                what: "quartic coefficient C",
                range: "finite and ≥ 0",
                value: quartic,
            })
        }
    }

    /// The quadratic part.
    pub fn linear(&self) -> &LinearElastic {
        &self.linear
    }

    /// The stiffening coefficient C (N·m⁴), C ≥ 0.
    pub fn quartic(&self) -> f64 {
        self.quartic
    }

    /// With u = κ − κ⁰ and S = |u|²: ∇ = C S u, H = C (S I + 2 u uᵀ).
    fn quartic_parts(&self, u: &Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
        let c = self.quartic;
        let sq = u.norm_squared();
        (
            c * sq * u,
            c * (Matrix3::identity() * sq + 2.0 * u * u.transpose()),
        )
    }
}

impl StoredEnergy for QuarticStiffening {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        let u = kappa - self.linear.kappa0(s);
        self.linear.density(s, kappa) + 0.25 * self.quartic * u.norm_squared().powi(2)
    }

    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        let u = kappa - self.linear.kappa0(s);
        self.linear.moment(s, kappa) + self.quartic_parts(&u).0
    }

    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        let u = kappa - self.linear.kappa0(s);
        self.linear.stiffness(s, kappa) + self.quartic_parts(&u).1
    }

    /// κ⁰(s) enters through u = κ − κ⁰(s): ∂s∇W₄ = −H₄ κ⁰'.
    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        let u = kappa - self.linear.kappa0(s);
        self.linear.moment_rate(s, kappa) - self.quartic_parts(&u).1 * self.linear.kappa0_rate(s)
    }

    /// ∂sH₄ = −T(κ⁰') with T the third derivative below.
    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        let rate = self.linear.kappa0_rate(s);
        self.linear.stiffness_rate(s, kappa) - self.stiffness_derivative(s, kappa, &rate)
    }

    /// H₄ v = C (S v + 2 u (u·v)), so ∂(H₄ v)/∂u = 2C (v uᵀ + (u·v) I + u vᵀ).
    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        let u = kappa - self.linear.kappa0(s);
        2.0 * self.quartic
            * (v * u.transpose() + Matrix3::identity() * u.dot(v) + u * v.transpose())
    }

    fn admits_planar_bending(&self) -> bool {
        self.linear.admits_planar_bending()
    }

    /// Both parts depend on each u_i through u_i² only.
    fn even_components(&self) -> [bool; 3] {
        [true; 3]
    }

    fn profile_edits(&self) -> Option<&dyn ProfileEdits> {
        Some(self)
    }

    fn name(&self) -> &'static str {
        "quartic"
    }

    fn derivatives_trusted(&self) -> bool {
        true
    }

    fn is_uniform(&self) -> bool {
        self.linear.is_uniform()
    }

    fn breaks(&self, length: f64) -> Vec<f64> {
        self.linear.breaks(length)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn energies() -> Vec<Box<dyn StoredEnergy>> {
        let tapered = LinearElastic::new(
            [
                Profile::Polynomial(vec![2.0, -0.5]),
                Profile::Polynomial(vec![1.0, 0.3, 0.2]),
                Profile::Constant(1.5),
            ],
            [
                Profile::Polynomial(vec![0.1, 0.4]),
                Profile::Polynomial(vec![-0.3, 0.0, 1.0]),
                Profile::Constant(0.7),
            ],
        )
        .unwrap();
        vec![
            Box::new(tapered.clone()),
            Box::new(QuarticStiffening::new(tapered, 0.8).unwrap()),
        ]
    }

    #[test]
    fn checked_constructors_refuse_and_round_trip() {
        let e = LinearElastic::uniform([1.0, 2.0, 3.0], [0.5, 0.0, -0.5]).unwrap();
        assert_eq!(e.stiffness_profiles()[1], Profile::Constant(2.0));
        assert_eq!(e.intrinsic_curvature()[2], Profile::Constant(-0.5));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                LinearElastic::uniform([1.0, 1.0, bad], [0.0; 3]),
                Err(ModelError::Stiffness { index: 2, .. })
            ));
        }
        assert!(matches!(
            LinearElastic::uniform([1.0; 3], [0.0, f64::NAN, 0.0]),
            Err(ModelError::IntrinsicCurvature { index: 1 })
        ));
        let q = QuarticStiffening::new(e.clone(), 0.25).unwrap();
        assert_eq!((q.linear(), q.quartic()), (&e, 0.25));
        for bad in [-1e-3, f64::NAN] {
            assert!(matches!(
                QuarticStiffening::new(e.clone(), bad),
                Err(ModelError::Coefficient { .. })
            ));
        }
        // A refused value through with_constant is None, never a rod.
        assert!(ProfileEdits::with_constant(&e, ProfileKind::Stiffness, 0, -1.0).is_none());
        assert!(ProfileEdits::with_constant(&e, ProfileKind::Stiffness, 0, 4.0).is_some());
    }

    const H: f64 = 1e-6;

    fn fd_vec(f: impl Fn(f64) -> Vector3<f64>) -> Vector3<f64> {
        (f(H) - f(-H)) / (2.0 * H)
    }

    fn fd_mat(f: impl Fn(f64) -> Matrix3<f64>) -> Matrix3<f64> {
        (f(H) - f(-H)) / (2.0 * H)
    }

    #[test]
    fn derivatives_match_central_differences() {
        let s = 0.37;
        let kappa = Vector3::new(0.4, -1.2, 0.9);
        let v = Vector3::new(-0.3, 0.8, 0.5);
        for e in energies() {
            let grad = e.moment(s, &kappa);
            let hess = e.stiffness(s, &kappa);
            for i in 0..3 {
                let ei = Vector3::ith(i, 1.0);
                let dw =
                    (e.density(s, &(kappa + H * ei)) - e.density(s, &(kappa - H * ei))) / (2.0 * H);
                assert!((dw - grad[i]).abs() < 1e-8, "{}: ∂W/∂κ{i}", e.name());
                let dm = fd_vec(|h| e.moment(s, &(kappa + h * ei)));
                assert!(
                    (dm - hess.column(i)).norm() < 1e-8,
                    "{}: H col {i}",
                    e.name()
                );
            }
            let dms = fd_vec(|h| e.moment(s + h, &kappa));
            assert!(
                (dms - e.moment_rate(s, &kappa)).norm() < 1e-8,
                "{}",
                e.name()
            );
            let dhs = fd_mat(|h| e.stiffness(s + h, &kappa));
            assert!(
                (dhs - e.stiffness_rate(s, &kappa)).norm() < 1e-7,
                "{}",
                e.name()
            );
            let t = e.stiffness_derivative(s, &kappa, &v);
            for i in 0..3 {
                let ei = Vector3::ith(i, 1.0);
                let dhv = fd_vec(|h| e.stiffness(s, &(kappa + h * ei)) * v);
                assert!((dhv - t.column(i)).norm() < 1e-7, "{}: T col {i}", e.name());
            }
        }
    }

    #[test]
    fn hessian_is_symmetric_positive_definite() {
        for e in energies() {
            let h = e.stiffness(0.2, &Vector3::new(1.0, 2.0, -0.5));
            assert!((h - h.transpose()).norm() < 1e-14);
            assert!(h.cholesky().is_some());
        }
    }
}
