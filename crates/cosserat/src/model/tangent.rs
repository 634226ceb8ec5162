//! How a rod moves with a continuation parameter p: the rates d(data)/dp
//! of the numbers a parameter can change, from which the equations build
//! the exact ∂F/∂p of a continued family (no finite differences).
//!
//! A [`RodTangent`] holds dP/dp, dC/dp, df/dp of the dead loads, dL/dp,
//! the rates dB/dp and dκ⁰/dp of constant bending stiffnesses and
//! intrinsic curvatures of a quadratic energy W = ½ Σ B_i (κ_i − κ⁰_i)²,
//! the clamp's spin ω (d d_i(0)/dp = ω × d_i(0)), the rate dX/dp of a tip
//! support's held position and the spin Ω of its held frame. Derivatives are taken
//! at a fixed fraction σ = s/L of the rod, so a length rate moves every
//! point of the rod with it.

use nalgebra::{Matrix3, Vector3};

use super::rod::finite;
use super::{DeadLoads, ModelError, ResidualScales, Rod, StoredEnergy};

/// d(rod data)/dp along a one-parameter family of rods; zero in every part
/// p does not change.
#[derive(Debug, Clone, PartialEq)]
pub struct RodTangent {
    loads: DeadLoads,
    length: f64,
    stiffness: Vector3<f64>,
    intrinsic_curvature: Vector3<f64>,
    clamp_spin: Vector3<f64>,
    support_shift: Vector3<f64>,
    support_spin: Vector3<f64>,
}

/// The rates of the energy's moment M = ∂W/∂κ, stiffness H = ∂²W/∂κ² and
/// explicit moment rate ∂sM at fixed (s, κ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyRate {
    /// dM/dp.
    pub moment: Vector3<f64>,
    /// dH/dp.
    pub stiffness: Matrix3<f64>,
    /// d(∂sM)/dp.
    pub moment_rate: Vector3<f64>,
}

impl Default for RodTangent {
    fn default() -> Self {
        RodTangent::zero()
    }
}

impl RodTangent {
    /// The rod does not move.
    pub fn zero() -> Self {
        RodTangent {
            loads: DeadLoads::default(),
            length: 0.0,
            stiffness: Vector3::zeros(),
            intrinsic_curvature: Vector3::zeros(),
            clamp_spin: Vector3::zeros(),
            support_shift: Vector3::zeros(),
            support_spin: Vector3::zeros(),
        }
    }

    /// With the load rates (dP/dp, dC/dp, df/dp); refused unless finite.
    pub fn with_loads(mut self, rates: DeadLoads) -> Result<Self, ModelError> {
        finite("tip force rate", &rates.tip_force)?;
        finite("tip couple rate", &rates.tip_couple)?;
        finite("distributed force rate", &rates.distributed_force)?;
        for p in &rates.point_loads {
            finite("point force rate", &p.force)?;
            finite("point couple rate", &p.couple)?;
        }
        self.loads = rates;
        Ok(self)
    }

    /// With the length rate dL/dp; refused unless finite.
    pub fn with_length(mut self, rate: f64) -> Result<Self, ModelError> {
        if !rate.is_finite() {
            return Err(ModelError::Length(rate));
        }
        self.length = rate;
        Ok(self)
    }

    /// With the rates dB/dp of constant bending stiffnesses.
    pub fn with_stiffness(mut self, rates: Vector3<f64>) -> Result<Self, ModelError> {
        finite("stiffness rate", &rates)?;
        self.stiffness = rates;
        Ok(self)
    }

    /// With the rates dκ⁰/dp of constant intrinsic curvatures.
    pub fn with_intrinsic_curvature(mut self, rates: Vector3<f64>) -> Result<Self, ModelError> {
        finite("intrinsic curvature rate", &rates)?;
        self.intrinsic_curvature = rates;
        Ok(self)
    }

    /// With the clamp's spin ω (global): d d_i(0)/dp = ω × d_i(0).
    pub fn with_clamp_spin(mut self, spin: Vector3<f64>) -> Result<Self, ModelError> {
        finite("clamp spin", &spin)?;
        self.clamp_spin = spin;
        Ok(self)
    }

    /// With the rate dX/dp of the tip support's held position (global).
    pub fn with_support_shift(mut self, shift: Vector3<f64>) -> Result<Self, ModelError> {
        finite("support shift", &shift)?;
        self.support_shift = shift;
        Ok(self)
    }

    /// With the spin Ω of the tip support's held frame (global):
    /// d d̂_i/dp = Ω × d̂_i.
    pub fn with_support_spin(mut self, spin: Vector3<f64>) -> Result<Self, ModelError> {
        finite("support spin", &spin)?;
        self.support_spin = spin;
        Ok(self)
    }

    /// self + factor·other: the tangent of a parameter that moves several
    /// numbers at once (linked keys, each at the rate `factor`), the rates
    /// being linear in the motion (spins add as ω × d_i does). Point-force
    /// rates are concatenated: n's rate sums over them.
    #[must_use]
    pub fn plus(mut self, other: &RodTangent, factor: f64) -> RodTangent {
        let l = &other.loads;
        self.loads.tip_force += l.tip_force * factor;
        self.loads.tip_couple += l.tip_couple * factor;
        self.loads.distributed_force += l.distributed_force * factor;
        self.loads
            .point_loads
            .extend(l.point_loads.iter().map(|p| crate::model::PointLoad {
                s: p.s,
                force: p.force * factor,
                couple: p.couple * factor,
            }));
        self.length += other.length * factor;
        self.stiffness += other.stiffness * factor;
        self.intrinsic_curvature += other.intrinsic_curvature * factor;
        self.clamp_spin += other.clamp_spin * factor;
        self.support_shift += other.support_shift * factor;
        self.support_spin += other.support_spin * factor;
        self
    }

    /// The spin Ω of the support's held frame.
    pub fn support_spin(&self) -> &Vector3<f64> {
        &self.support_spin
    }

    /// dX/dp of the support's held position.
    pub fn support_shift(&self) -> &Vector3<f64> {
        &self.support_shift
    }

    /// The load rates.
    pub fn loads(&self) -> &DeadLoads {
        &self.loads
    }

    /// dL/dp.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The clamp's spin ω.
    pub fn clamp_spin(&self) -> &Vector3<f64> {
        &self.clamp_spin
    }

    /// Whether the energy rates are exact for `rod`: an energy change needs
    /// a quadratic energy (H independent of κ and diagonal, the linear
    /// energy of [`EnergyRate`]'s formulas); a length change needs an energy
    /// without explicit s-dependence (else its profiles would move under
    /// the rod's points in a way the tangent does not describe).
    pub fn fits(&self, rod: &Rod) -> bool {
        let e = rod.energy();
        let energy_moves =
            self.stiffness != Vector3::zeros() || self.intrinsic_curvature != Vector3::zeros();
        let diagonal = {
            let h = e.stiffness(0.0, &Vector3::zeros());
            h == Matrix3::from_diagonal(&h.diagonal())
        };
        // A point force stays at its s_k while a length rate moves every
        // point at fixed σ = s/L: the jump would move in σ, a term the
        // sensitivity equations do not carry.
        let points_stay = self.length == 0.0 || rod.loads().point_loads.is_empty();
        // The curvature after a point couple solves ∇W(κ⁺) = M⁻ − C·d_i:
        // its p-derivative (the couple's rate, the energy's) is not built
        // into the jump's linearization, which maps the state's
        // sensitivities only (a central difference then, said so).
        let couples_stay = !rod.loads().has_point_couples() && !self.loads.has_point_couples();
        (!energy_moves || (e.is_quadratic() && diagonal))
            && (self.length == 0.0 || e.is_uniform())
            && points_stay
            && couples_stay
    }

    /// dn/dp at a fixed σ = s/L of the internal force n = P + f (L − s) +
    /// Σ_{s_k > s} F_k ([`DeadLoads::internal_force`]): dP + df (L − s) +
    /// f L' (1 − s/L) + Σ_{s_k > s} dF_k (the rates' point forces at the
    /// rod's own points s_k; a length rate with point forces is not
    /// [`RodTangent::fits`]).
    pub fn internal_force_rate(&self, rod: &Rod, s: f64) -> Vector3<f64> {
        let l = rod.length();
        let f = rod.loads().distributed_force;
        let mut rate = self.loads.tip_force
            + self.loads.distributed_force * (l - s)
            + f * (self.length * (1.0 - s / l));
        for p in self.loads.point_loads.iter().filter(|p| p.s > s) {
            rate += p.force;
        }
        rate
    }

    /// dM, dH and d(∂sM) at fixed (s, κ) for W = ½ Σ B_i (κ_i − κ⁰_i)²
    /// with constant rates B'_i, κ⁰'_i: M_i = B_i (κ_i − κ⁰_i) gives
    /// dM_i = B'_i M_i / H_ii − H_ii κ⁰'_i, dH = diag(B'), and
    /// ∂sM = ∂sB∘(κ − κ⁰) − B∘∂sκ⁰ gives d(∂sM)_i = B'_i (∂sM)_i / H_ii −
    /// (∂sH)_ii κ⁰'_i (∂sB_i = 0 where B_i moves, being constant). Only
    /// meaningful where [`RodTangent::fits`] the rod.
    pub fn energy_rate(&self, e: &dyn StoredEnergy, s: f64, kappa: &Vector3<f64>) -> EnergyRate {
        let zero = EnergyRate {
            moment: Vector3::zeros(),
            stiffness: Matrix3::zeros(),
            moment_rate: Vector3::zeros(),
        };
        if self.stiffness == Vector3::zeros() && self.intrinsic_curvature == Vector3::zeros() {
            return zero;
        }
        let h = e.stiffness(s, kappa).diagonal();
        let hs = e.stiffness_rate(s, kappa).diagonal();
        let (m, ms) = (e.moment(s, kappa), e.moment_rate(s, kappa));
        let (b, k0) = (&self.stiffness, &self.intrinsic_curvature);
        EnergyRate {
            moment: Vector3::from_fn(|i, _| b[i] * m[i] / h[i] - h[i] * k0[i]),
            stiffness: Matrix3::from_diagonal(b),
            moment_rate: Vector3::from_fn(|i, _| b[i] * ms[i] / h[i] - hs[i] * k0[i]),
        }
    }

    /// d/dp of [`Rod::residual_scales`]: the derivative of the branch of
    /// each max that is active (a scale is piecewise smooth in p; at a tie
    /// the first branch in the order of that function is taken).
    pub fn residual_scales_rate(&self, rod: &Rod) -> ResidualScales {
        let l = rod.length();
        let dl = self.length;
        let e = rod.energy();
        let zero = Vector3::zeros();
        let h = e.stiffness(l, &zero).diagonal();
        let dh = self.energy_rate(e.as_ref(), l, &zero).stiffness.diagonal();
        let loads = rod.loads();
        let norm_rate = |v: &Vector3<f64>, dv: &Vector3<f64>| {
            let n = v.norm();
            Slope::new(n, if n > 0.0 { v.dot(dv) / n } else { 0.0 })
        };
        let (p, c, f) = (
            norm_rate(&loads.tip_force, &self.loads.tip_force),
            norm_rate(&loads.tip_couple, &self.loads.tip_couple),
            norm_rate(&loads.distributed_force, &self.loads.distributed_force),
        );
        let length = Slope::new(l, dl);
        let load_moment = p.times(length).max(c).max(f.times(length).times(length));
        let largest = (0..3)
            .map(|i| Slope::new(h[i], dh[i]))
            .reduce(Slope::max)
            .unwrap_or(Slope::new(0.0, 0.0));
        let intrinsic = self.intrinsic_moment_rate(rod);
        let moment: [Slope; 3] = std::array::from_fn(|i| {
            let bend = if h[i] > 0.0 {
                Slope::new(h[i], dh[i])
            } else {
                largest
            };
            bend.over(length)
                .max(load_moment)
                .max(intrinsic[i])
                .max(Slope::new(f64::MIN_POSITIVE, 0.0))
        });
        let smallest = moment.into_iter().reduce(Slope::min).unwrap_or(moment[0]);
        let load_force = Slope::new(p.value + f.value * l, p.rate + f.rate * l + f.value * dl);
        ResidualScales {
            moment: Vector3::from_fn(|i, _| moment[i].rate),
            force: smallest.over(length).max(load_force).rate,
            length: dl,
        }
    }

    /// max over the 65 points of |M_i(s, κ = 0)| with its rate, as in the
    /// rod's own scales (the points move with L at fixed σ).
    fn intrinsic_moment_rate(&self, rod: &Rod) -> [Slope; 3] {
        let e = rod.energy();
        let zero = Vector3::zeros();
        let mut best = [Slope::new(0.0, 0.0); 3];
        for j in 0..=64 {
            let s = rod.length() * f64::from(j) / 64.0;
            let m = e.moment(s, &zero);
            let dm = self.energy_rate(e.as_ref(), s, &zero).moment;
            for i in 0..3 {
                let here = Slope::new(m[i].abs(), m[i].signum() * dm[i]);
                if here.value > best[i].value {
                    best[i] = here;
                }
            }
        }
        best
    }
}

/// A value with its rate in p, for the derivative of a max of branches.
#[derive(Debug, Clone, Copy)]
struct Slope {
    value: f64,
    rate: f64,
}

impl Slope {
    fn new(value: f64, rate: f64) -> Self {
        Slope { value, rate }
    }

    fn max(self, other: Slope) -> Slope {
        if other.value > self.value {
            other
        } else {
            self
        }
    }

    fn min(self, other: Slope) -> Slope {
        if other.value < self.value {
            other
        } else {
            self
        }
    }

    fn times(self, other: Slope) -> Slope {
        Slope::new(
            self.value * other.value,
            self.rate * other.value + self.value * other.rate,
        )
    }

    fn over(self, other: Slope) -> Slope {
        Slope::new(
            self.value / other.value,
            (self.rate - self.value * other.rate / other.value) / other.value,
        )
    }
}
