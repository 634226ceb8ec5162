//! The rod: length, stored energy, clamp at s = 0 and dead loads.
//!
//! A [`Rod`] is built by the checked [`Rod::new`] and changed only by the
//! checked `with_*` modifiers, so that every rod the solvers see has a
//! positive finite length, finite loads and positions, unit support axes
//! and director frames that are rotations ([`Frame`]).

use std::sync::{Arc, OnceLock};

use nalgebra::Vector3;

use super::{DeadLoads, Frame, Freedom, ModelError, StoredEnergy, TipSupport};

/// The support at s = 0: position and the directors d1(0), d2(0), d3(0);
/// a clamp, or a hinge about d2(0).
#[derive(Debug, Clone, PartialEq)]
pub struct Clamp {
    /// r(0) (m).
    pub position: Vector3<f64>,
    /// The director frame [d1 d2 d3] at s = 0, as columns (a rotation,
    /// checked by [`Frame`]); for a hinge, the frame the turning angle is
    /// measured from.
    pub frame: Frame,
    /// A hinge about d2(0) instead of a clamp: the frame may turn about
    /// d2(0) (its angle is an unknown) and the moment about d2(0) vanishes
    /// there (planar scenes: the pinned end of a column).
    pub hinge: bool,
}

impl Clamp {
    /// A clamp at `position` from d1(0) and d3(0); d2 = d3 × d1 completes a
    /// right-handed frame ([`Frame::from_directors`]). Refused when d1, d3
    /// are not orthonormal ([`ModelError::Frame`]) or the position is not
    /// finite ([`ModelError::NotFinite`]).
    pub fn new(
        position: Vector3<f64>,
        d1: Vector3<f64>,
        d3: Vector3<f64>,
    ) -> Result<Self, ModelError> {
        finite("clamp position", &position)?;
        Ok(Clamp {
            position,
            frame: Frame::from_directors(d1, d3)?,
            hinge: false,
        })
    }

    /// The paper's clamp: origin, d1 = e1 (vertical, down), d3 = e3.
    pub fn paper() -> Self {
        Clamp {
            position: Vector3::zeros(),
            frame: Frame::identity(),
            hinge: false,
        }
    }

    /// d_i(0), i = 0, 1, 2.
    pub fn director(&self, i: usize) -> Vector3<f64> {
        self.frame.column(i).into_owned()
    }

    /// The frame turned by `angle` (rad) about d2(0), d3 towards d1:
    /// R [d1 d2 d3] with R d3 = d3 cos θ + d1 sin θ (the clamp angle of the
    /// paper's Fig. 2; a negative angle turns back).
    ///
    /// Refused ([`ModelError::Angle`]) for a non-finite angle.
    pub fn turned_frame(&self, angle: f64) -> Result<Frame, ModelError> {
        self.frame.turned(1, angle)
    }
}

/// The units in which tip residuals are measured ([`Rod::residual_scales`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualScales {
    /// Moment about each body axis d_i (N·m).
    pub moment: Vector3<f64>,
    /// Force (N).
    pub force: f64,
    /// Length (m).
    pub length: f64,
}

/// A rod clamped at s = 0 under dead loads, free at s = L or held there by
/// a [`TipSupport`]. Its parts are read through accessors and changed
/// through the checked `with_*` modifiers, so that no rod holds a value
/// [`Rod::new`] refuses.
#[derive(Debug, Clone)]
pub struct Rod {
    length: f64,
    energy: Arc<dyn StoredEnergy>,
    clamp: Clamp,
    loads: DeadLoads,
    support: Option<TipSupport>,
    /// [`Rod::intrinsic_moment`] once computed: it reads only the energy
    /// and the length, so the rod's clones (a load ramp's scaled rods,
    /// another clamp or support) share it, and [`Rod::with_length`] and
    /// [`Rod::with_energy`] start a new one. Without it every set of
    /// equations made 65 energy calls for its residual units.
    intrinsic: Arc<OnceLock<Vector3<f64>>>,
}

/// Refuses a vector with a non-finite component.
pub(super) fn finite(what: &'static str, v: &Vector3<f64>) -> Result<(), ModelError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ModelError::NotFinite {
            what,
            value: [v.x, v.y, v.z],
        })
    }
}

fn check_length(length: f64) -> Result<(), ModelError> {
    if length.is_finite() && length > 0.0 {
        Ok(())
    } else {
        Err(ModelError::Length(length))
    }
}

fn check_clamp(clamp: &Clamp) -> Result<(), ModelError> {
    finite("clamp position", &clamp.position)
}

fn check_loads(loads: &DeadLoads) -> Result<(), ModelError> {
    finite("tip force", &loads.tip_force)?;
    finite("tip couple", &loads.tip_couple)?;
    finite("distributed force", &loads.distributed_force)
}

/// Point loads act at interior points 0 < s_k < L with finite forces and
/// couples: at an end the load is a tip load or a reaction, and n(s), m(s)
/// would have no interior jump to integrate across.
fn check_point_loads(loads: &DeadLoads, length: f64) -> Result<(), ModelError> {
    for (index, p) in loads.point_loads.iter().enumerate() {
        let inside = p.s.is_finite() && p.s > 0.0 && p.s < length;
        let finite = p.force.iter().chain(p.couple.iter()).all(|x| x.is_finite());
        if !inside || !finite {
            return Err(ModelError::PointLoad {
                index,
                s: p.s,
                force: [p.force.x, p.force.y, p.force.z],
                couple: [p.couple.x, p.couple.y, p.couple.z],
                length,
            });
        }
    }
    Ok(())
}

/// A support's position is finite and its axes are unit vectors (to
/// [`Frame::TOLERANCE`]); its frame is a [`Frame`] already.
fn check_support(support: Option<&TipSupport>) -> Result<(), ModelError> {
    let Some(s) = support else {
        return Ok(());
    };
    finite("support position", &s.position)?;
    for freedom in [s.translation, s.rotation] {
        if let Freedom::Axial(a) = freedom {
            finite("support axis", &a)?;
            if (a.norm() - 1.0).abs() > Frame::TOLERANCE {
                return Err(ModelError::Axis { norm: a.norm() });
            }
        }
    }
    Ok(())
}

impl Rod {
    /// A rod of reference length `length` (m) with stored energy `energy`,
    /// clamped by `clamp` at s = 0, under dead `loads`, free at s = L
    /// (`support` None) or held there. Refused with the named
    /// [`ModelError`] when the length is not positive and finite, a load or
    /// a position is not finite, a point load is not at an interior point, or a support axis is not a unit vector
    /// (frames are [`Frame`]s, checked when built). The energy is the
    /// caller's: its Hessian is checked along the rod when a solve starts.
    pub fn new(
        length: f64,
        energy: Arc<dyn StoredEnergy>,
        clamp: Clamp,
        loads: DeadLoads,
        support: Option<TipSupport>,
    ) -> Result<Rod, ModelError> {
        check_length(length)?;
        check_clamp(&clamp)?;
        check_loads(&loads)?;
        check_point_loads(&loads, length)?;
        check_support(support.as_ref())?;
        Ok(Rod {
            length,
            energy,
            clamp,
            loads,
            support,
            intrinsic: Arc::default(),
        })
    }

    /// Reference length L (m).
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The stored energy density W(s, κ).
    pub fn energy(&self) -> &Arc<dyn StoredEnergy> {
        &self.energy
    }

    /// The clamp at s = 0.
    pub fn clamp(&self) -> &Clamp {
        &self.clamp
    }

    /// Dead loads.
    pub fn loads(&self) -> &DeadLoads {
        &self.loads
    }

    /// The support at s = L; None for a free tip (a cantilever).
    pub fn support(&self) -> Option<&TipSupport> {
        self.support.as_ref()
    }

    /// The same rod with another length, checked as in [`Rod::new`].
    pub fn with_length(mut self, length: f64) -> Result<Rod, ModelError> {
        check_length(length)?;
        check_point_loads(&self.loads, length)?;
        self.length = length;
        self.intrinsic = Arc::default();
        Ok(self)
    }

    /// The same rod with another stored energy (nothing to check here: see
    /// [`Rod::new`]).
    #[must_use]
    pub fn with_energy(mut self, energy: Arc<dyn StoredEnergy>) -> Rod {
        self.energy = energy;
        self.intrinsic = Arc::default();
        self
    }

    /// The same rod with another clamp, checked as in [`Rod::new`].
    pub fn with_clamp(mut self, clamp: Clamp) -> Result<Rod, ModelError> {
        check_clamp(&clamp)?;
        self.clamp = clamp;
        Ok(self)
    }

    /// The same rod under other loads, checked as in [`Rod::new`].
    pub fn with_loads(mut self, loads: DeadLoads) -> Result<Rod, ModelError> {
        check_loads(&loads)?;
        check_point_loads(&loads, self.length)?;
        self.loads = loads;
        Ok(self)
    }

    /// The same rod with another tip support, checked as in [`Rod::new`].
    pub fn with_support(mut self, support: Option<TipSupport>) -> Result<Rod, ModelError> {
        check_support(support.as_ref())?;
        self.support = support;
        Ok(self)
    }

    /// A characteristic moment (N·m) of the whole rod: the larger of the
    /// largest bending moment B/L that curves the rod by one radian and the
    /// moments of the loads. Only for order-of-magnitude checks; residuals
    /// are scaled per equation by [`Rod::residual_scales`].
    pub fn moment_scale(&self) -> f64 {
        let b = self.energy.stiffness(0.0, &Vector3::zeros());
        let stiff = b.diagonal().max() / self.length;
        stiff.max(self.loads.moment_scale(self.length))
    }

    /// The scale of each kind of tip residual, one per equation so that no
    /// stiffness ratio can hide an unmet condition: the body moment about
    /// d_i is measured in H_ii(L)/L (an error of one unit is a curvature
    /// error of 1/L in that component), or in the loads' moment or the
    /// intrinsic moment |M_i(s, κ = 0)| of that component where those are
    /// larger (the integrated curvature is only as accurate as the
    /// integrator's relative tolerance times its size, and so is a moment
    /// residual measured in anything smaller); forces in the smallest of
    /// these over L or the loads' force; positions in L; angles are already
    /// dimensionless.
    pub fn residual_scales(&self) -> ResidualScales {
        let l = self.length;
        let h = self.energy.stiffness(l, &Vector3::zeros()).diagonal();
        let loads = self.loads.moment_scale(l);
        let largest = h.max();
        let intrinsic = self.intrinsic_moment();
        let moment = Vector3::from_fn(|i, _| {
            let bend = if h[i] > 0.0 { h[i] } else { largest };
            (bend / l)
                .max(loads)
                .max(intrinsic[i])
                .max(f64::MIN_POSITIVE)
        });
        let load_force = self.loads.tip_force.norm() + self.loads.distributed_force.norm() * l;
        ResidualScales {
            moment,
            force: (moment.min() / l).max(load_force),
            length: l,
        }
    }

    /// max over s of |M_i(s, κ = 0)|: the moment an intrinsically curved rod
    /// carries when straightened (B_i |κ⁰_i| for the linear energy), on 65
    /// points along the rod; computed once per energy and length.
    fn intrinsic_moment(&self) -> Vector3<f64> {
        *self
            .intrinsic
            .get_or_init(|| Self::sampled_intrinsic_moment(&*self.energy, self.length))
    }

    /// [`Rod::intrinsic_moment`] sampled from the energy.
    fn sampled_intrinsic_moment(energy: &dyn StoredEnergy, length: f64) -> Vector3<f64> {
        (0..=64)
            .map(|j| {
                let s = length * f64::from(j) / 64.0;
                energy.moment(s, &Vector3::zeros()).abs()
            })
            .fold(Vector3::zeros(), |a, m| a.sup(&m))
    }

    /// The interior points where the equations' right-hand side is not
    /// smooth, sorted and without repeats: the point forces' points
    /// ([`DeadLoads::jumps`], where n jumps) and the energy's breakpoints
    /// ([`StoredEnergy::breaks`], where a profile is kinked). Every solver
    /// stops there ([`crate::equations::RodEquations::jumps`]).
    pub fn breaks(&self) -> Vec<f64> {
        let mut s = self.loads.jumps();
        s.extend(self.energy.breaks(self.length));
        s.sort_by(f64::total_cmp);
        s.dedup();
        s
    }

    /// The same rod under loads scaled by `factor`; refused when the
    /// scaled loads are not finite (a non-finite factor, or an overflow).
    pub fn with_load_factor(&self, factor: f64) -> Result<Rod, ModelError> {
        self.clone().with_loads(self.loads.scaled(factor))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::LinearElastic;

    fn energy() -> Arc<dyn StoredEnergy> {
        Arc::new(LinearElastic::uniform([1.0, 1.0, 1.0], [0.0; 3]).unwrap())
    }

    fn loads() -> DeadLoads {
        DeadLoads {
            tip_force: Vector3::new(1.0, 0.0, 0.0),
            ..Default::default()
        }
    }

    #[test]
    fn a_valid_rod_round_trips() {
        let rod = Rod::new(2.0, energy(), Clamp::paper(), loads(), None).unwrap();
        assert_eq!(rod.length(), 2.0);
        assert_eq!(rod.clamp(), &Clamp::paper());
        assert_eq!(rod.loads(), &loads());
        assert!(rod.support().is_none());
        assert_eq!(rod.energy().name(), "linear");
        let rod = rod.with_length(3.0).unwrap();
        assert_eq!(rod.length(), 3.0);
        assert_eq!(rod.with_load_factor(2.0).unwrap().loads().tip_force.x, 2.0);
        let clamp = Clamp::new(Vector3::zeros(), Vector3::x(), Vector3::z()).unwrap();
        assert_eq!(clamp, Clamp::paper());
        let turned = Clamp {
            frame: clamp.turned_frame(0.3).unwrap(),
            ..clamp
        };
        let support = TipSupport {
            position: Vector3::new(0.1, 0.0, 0.9),
            frame: Frame::identity(),
            translation: Freedom::Axial(Vector3::z()),
            rotation: Freedom::Fixed,
        };
        let rod = rod
            .with_clamp(turned.clone())
            .unwrap()
            .with_support(Some(support.clone()))
            .unwrap();
        assert_eq!((rod.clamp(), rod.support()), (&turned, Some(&support)));
    }

    /// The residual units of a rod whose energy or length changed are
    /// those of the same rod built afresh: the intrinsic moment shared by
    /// clones is not carried across [`Rod::with_energy`] or
    /// [`Rod::with_length`], and a clone under other loads keeps it.
    #[test]
    fn residual_units_follow_the_energy_and_the_length() {
        let curved = |k: f64| -> Arc<dyn StoredEnergy> {
            Arc::new(LinearElastic::uniform([1.0, 2.0, 3.0], [0.0, k, 0.0]).unwrap())
        };
        let fresh = |l: f64, e: Arc<dyn StoredEnergy>| {
            Rod::new(l, e, Clamp::paper(), loads(), None)
                .unwrap()
                .residual_scales()
        };
        let rod = Rod::new(1.0, curved(5.0), Clamp::paper(), loads(), None).unwrap();
        assert_eq!(rod.residual_scales(), fresh(1.0, curved(5.0)));
        assert_eq!(rod.residual_scales().moment[1], 10.0);
        let other = rod.clone().with_energy(curved(7.0));
        assert_eq!(other.residual_scales(), fresh(1.0, curved(7.0)));
        let longer = rod.clone().with_length(0.1).unwrap();
        assert_eq!(longer.residual_scales(), fresh(0.1, curved(5.0)));
        assert_eq!(rod.residual_scales(), fresh(1.0, curved(5.0)));
        let scaled = rod.with_load_factor(40.0).unwrap();
        let expected = Rod::new(1.0, curved(5.0), Clamp::paper(), loads().scaled(40.0), None)
            .unwrap()
            .residual_scales();
        assert_eq!(scaled.residual_scales(), expected);
    }

    #[test]
    fn refused_values_give_named_errors() {
        for l in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                Rod::new(l, energy(), Clamp::paper(), loads(), None),
                Err(ModelError::Length(_))
            ));
        }
        let mut bad = loads();
        bad.tip_couple.y = f64::NAN;
        assert!(matches!(
            Rod::new(1.0, energy(), Clamp::paper(), bad, None),
            Err(ModelError::NotFinite {
                what: "tip couple",
                ..
            })
        ));
        let rod = Rod::new(1.0, energy(), Clamp::paper(), loads(), None).unwrap();
        assert!(matches!(
            rod.with_load_factor(f64::INFINITY),
            Err(ModelError::NotFinite { .. })
        ));
        assert!(matches!(
            Clamp::new(Vector3::zeros(), Vector3::x(), Vector3::new(0.0, 0.1, 1.0)),
            Err(ModelError::Frame { .. })
        ));
        let support = TipSupport {
            position: Vector3::z(),
            frame: Frame::identity(),
            translation: Freedom::Axial(Vector3::new(0.0, 0.0, 2.0)),
            rotation: Freedom::Free,
        };
        assert!(matches!(
            rod.clone().with_support(Some(support.clone())),
            Err(ModelError::Axis { .. })
        ));
        let nowhere = TipSupport {
            position: Vector3::new(f64::INFINITY, 0.0, 0.0),
            translation: Freedom::Fixed,
            ..support
        };
        assert!(matches!(
            rod.clone().with_support(Some(nowhere)),
            Err(ModelError::NotFinite {
                what: "support position",
                ..
            })
        ));
        let mut adrift = Clamp::paper();
        adrift.position.x = f64::NAN;
        assert!(matches!(
            rod.clone().with_clamp(adrift),
            Err(ModelError::NotFinite {
                what: "clamp position",
                ..
            })
        ));
        assert!(matches!(
            rod.with_length(-2.0),
            Err(ModelError::Length(l)) if l == -2.0
        ));
    }

    /// A stiffness kinked at s = 0.4 (B = 2 − 2.5s, then 1 + 2(s − 0.4)) is
    /// a break of the equations, where every solver stops; under a tip
    /// couple C about d2 the moment is C everywhere, so the rod turns by
    /// C ∫ 1/B = C (0.4 ln 2 + 0.5 ln 2.2) — met by shooting, multiple
    /// shooting (the break inside a segment) and collocation.
    #[test]
    fn a_kinked_stiffness_is_a_break_of_every_solver() {
        use crate::bvp::{equations, solve, Method, SolverOptions};
        use crate::model::{ModelChoice, ModelLevel, Profile};
        let bend =
            Profile::piecewise(vec![0.0, 0.4, 1.0], vec![vec![1.5, -0.5], vec![1.6, 0.6]]).unwrap();
        let energy = LinearElastic::new(
            [bend.scaled(2.0), bend.clone(), bend.scaled(1.5)],
            [0.0; 3].map(Profile::Constant),
        )
        .unwrap();
        let c = 0.5;
        let rod = Rod::new(
            1.0,
            Arc::new(energy),
            Clamp::paper(),
            DeadLoads {
                tip_couple: Vector3::new(0.0, c, 0.0),
                ..Default::default()
            },
            None,
        )
        .unwrap();
        assert_eq!(rod.breaks(), vec![0.4]);
        assert_eq!(equations(&rod, ModelLevel::Planar).jumps(), vec![0.4]);
        let turn = c * (0.4 * 2f64.ln() + 0.5 * 2.2f64.ln());
        let model = ModelChoice {
            level: ModelLevel::Planar,
            reason: String::new(),
        };
        for method in [
            Method::Shooting,
            Method::MultipleShooting { segments: 3 },
            Method::Collocation { stages: 3 },
        ] {
            let opts = SolverOptions {
                method,
                ..Default::default()
            };
            let eq = solve(&rod, &model, &opts).unwrap();
            let d3 = eq.tip().directors[2];
            let angle = d3.dot(&Clamp::paper().director(2)).clamp(-1.0, 1.0).acos();
            assert!((angle - turn).abs() < 1e-9, "{method:?}: {angle} vs {turn}");
        }
    }
}
