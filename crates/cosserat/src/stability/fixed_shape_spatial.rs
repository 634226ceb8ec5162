//! The critical load of a fixed spatial loaded shape: the 3-D
//! generalization of [`super::FixedShape`] (Sipos & Várkonyi 2019 leave
//! spatial shapes open, Sec. 4.3 and 5).
//!
//! The loaded shape is prescribed by its curvature–twist profiles
//! κ(s) = (κ1, κ2, κ3)(s) (body components). The frame follows from
//! R' = R [κ]×, R(0) the clamp's frame, the centreline from r' = R e3,
//! r(0) the clamp's position. For loads λ·(P, f) fixed in space (dead, as
//! gravity), statics on the fixed shape gives per unit load factor
//! n(s) = P + (L − s) f and m(s) = (r(L) − r(s)) × P + (∫_s^L (r(t) − r(s)) dt) × f,
//! body moment M = Rᵀm. The intrinsic curvature that makes the shape an
//! equilibrium at λ is κ⁰ = κ − λ H⁻¹ M (linear energy, H = diag(B1, B2, B3);
//! [`SpatialShape::intrinsic_curvature`]). κ is fixed and M, N scale with λ,
//! so the second variation of the full 3-D form (no block split: a spatial
//! shape couples bending and twist) is K(λ) = K0 + λK1 and λ_crit is the
//! smallest positive generalized eigenvalue, as in the planar case.
//!
//! For κ1 = κ3 = 0 the shape is the planar one with φ' = κ2, and the
//! single 3-D block is the direct sum of the planar in-plane and
//! out-of-plane blocks, so the critical loads agree (tested to 1e-10 in
//! crates/cosserat/tests/spatial_arm.rs).

use nalgebra::{Matrix3, Vector3};

use super::eigen::smallest_positive_load_factor;
use super::fixed_shape::split_coefficients;
use super::second_variation::{Block, FiniteElements};
use super::{CriticalLoad, StabilityError, StabilityOptions};
use crate::equations::RodSample;
use crate::model::{Profile, Rod};
use crate::numerics::integrator::{Dop853, Stops, Tolerances};

/// A spatial loaded shape held fixed while the load varies: its curvature
/// and twist as functions of the arc length.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialShape {
    /// κ1(s), κ2(s), κ3(s) (1/m), body components: bending about d1 and d2,
    /// and the twist.
    pub curvature: [Profile; 3],
}

/// The state integrated along the shape: r, the directors d1, d2, d3, and
/// Q = ∫_0^s r (for the moment of a distributed force).
const STATE: usize = 15;

impl SpatialShape {
    /// κ at `s` (body components).
    pub fn curvature_at(&self, s: f64) -> Vector3<f64> {
        Vector3::new(
            self.curvature[0].value(s),
            self.curvature[1].value(s),
            self.curvature[2].value(s),
        )
    }

    /// The shape sampled at sorted `points` in [0, L], with the moment and
    /// force per unit load factor of `rod.loads`: position, directors,
    /// curvature κ, moment M = Rᵀm (body), force n (global). Fails when the
    /// frame's quadrature does (a shape so extreme that DOP853's step
    /// underflows).
    pub fn samples(&self, rod: &Rod, points: &[f64]) -> Result<Vec<RodSample>, StabilityError> {
        let clamp = rod.clamp();
        let mut y = [0.0; STATE];
        for i in 0..3 {
            y[3 + 3 * i..6 + 3 * i].copy_from_slice(clamp.director(i).as_slice());
        }
        let rhs = |s: f64, y: &[f64], d: &mut [f64]| {
            let k = self.curvature_at(s);
            let dir = |i: usize| Vector3::new(y[3 + 3 * i], y[4 + 3 * i], y[5 + 3 * i]);
            // Angular velocity in global components ω = Σ κ_i d_i; d_i' = ω × d_i.
            let omega = dir(0) * k[0] + dir(1) * k[1] + dir(2) * k[2];
            for i in 0..3 {
                let di = omega.cross(&dir(i));
                d[3 + 3 * i..6 + 3 * i].copy_from_slice(di.as_slice());
            }
            // r' = d3; Q' = r.
            d[0..3].copy_from_slice(dir(2).as_slice());
            d[12..15].copy_from_slice(&y[0..3]);
        };
        let length = rod.length();
        let mut stops = points.to_vec();
        stops.push(length);
        let mut states: Vec<(f64, [f64; STATE])> = Vec::with_capacity(stops.len());
        // Relative to a unit-length scale: the positions start at zero, so
        // the absolute tolerance holds them to the relative one.
        let tol = Tolerances::default();
        Dop853::new(STATE)
            .integrate_serving(
                rhs,
                (0.0, length, STATE),
                &mut y,
                &tol,
                &stops,
                Stops::Interpolated,
                |s, y| {
                    let mut v = [0.0; STATE];
                    v.copy_from_slice(y);
                    states.push((s, v));
                },
                |_| {},
            )
            .map_err(|e| {
                StabilityError::FixedShape(format!("the spatial shape's quadrature failed: {e}"))
            })?;
        let (_, tip) = *states.last().expect("the tip is a stop");
        let at = |v: &[f64; STATE], i: usize| Vector3::new(v[i], v[i + 1], v[i + 2]);
        let loads = rod.loads();
        Ok(states[..points.len()]
            .iter()
            .map(|(s, v)| {
                let r = at(v, 0);
                let frame = Matrix3::from_columns(&[at(v, 3), at(v, 6), at(v, 9)]);
                // ∫_s^L (r(t) − r(s)) dt = Q(L) − Q(s) − (L − s) r(s).
                let lever = at(&tip, 12) - at(v, 12) - r * (length - s);
                let m = loads.tip_couple
                    + (at(&tip, 0) - r).cross(&loads.tip_force)
                    + lever.cross(&loads.distributed_force);
                RodSample {
                    s: *s,
                    position: clamp.position + r,
                    directors: [at(v, 3), at(v, 6), at(v, 9)],
                    curvature: self.curvature_at(*s),
                    moment: frame.transpose() * m,
                    force: loads.internal_force(*s, length),
                }
            })
            .collect())
    }

    /// The tip position r(L) − r(0) (global), by the same quadrature.
    pub fn chord(&self, rod: &Rod) -> Result<Vector3<f64>, StabilityError> {
        let tip = self.samples(rod, &[rod.length()])?;
        Ok(tip[0].position - rod.clamp().position)
    }

    /// κ⁰ = κ − λ H⁻¹ M at the `samples` of this shape (M per unit load
    /// factor, as [`Self::samples`] gives it): the intrinsic curvature that
    /// makes the shape an equilibrium under λ times the loads (the balance
    /// of moments M = H(κ − κ⁰) of the linear energy). The energy's
    /// stiffness at the sample is used, so it must be quadratic.
    pub fn intrinsic_curvature(
        rod: &Rod,
        samples: &[RodSample],
        load_factor: f64,
    ) -> Vec<Vector3<f64>> {
        samples
            .iter()
            .map(|p| {
                let h = rod.energy().stiffness(p.s, &p.curvature);
                let hm = h
                    .try_inverse()
                    .expect("the linear energy's H is positive definite (checked constructor)")
                    * p.moment;
                p.curvature - hm * load_factor
            })
            .collect()
    }
}

/// The critical load of the spatial `shape` under `rod.loads` scaled by λ:
/// the smallest positive λ with K0 + λK1 singular on the single 3-D block
/// ([`Block::Full`]). `gamma` is λ|P|L²/B2(0) (λ|f|L³/B2(0) with a
/// distributed force only), as for the planar shape.
pub fn critical_load_spatial(
    rod: &Rod,
    shape: &SpatialShape,
    opts: &StabilityOptions,
) -> Result<CriticalLoad, StabilityError> {
    super::fixed_shape::check_cantilever(rod)?;
    let fe = FiniteElements::new(rod.length(), opts.elements(), opts.order());
    let samples = shape.samples(rod, &fe.quadrature_points())?;
    let (c0, c1) = split_coefficients(rod, &samples);
    let block = Block::Full;
    let (k0, k1) = (fe.stiffness(&c0, block), fe.stiffness(&c1, block));
    let (load_factor, mode) = match smallest_positive_load_factor(&k0, &k1)? {
        Some((l, v)) => (Some(l), fe.nodal_rotations(block, &v)),
        None => (None, vec![]),
    };
    let b2 = rod.energy().stiffness(0.0, &Vector3::zeros())[(1, 1)];
    let l = rod.length();
    let scale = if rod.loads().tip_force.norm() > 0.0 {
        rod.loads().tip_force.norm() * l * l / b2
    } else {
        rod.loads().distributed_force.norm() * l * l * l / b2
    };
    Ok(CriticalLoad {
        load_factor,
        gamma: load_factor.map(|f| f * scale),
        blocks: vec![(block, load_factor, mode)],
        nodes: fe.nodes(),
    })
}
