//! The critical load of a fixed loaded shape (paper Sec. 2.5 and 3).
//!
//! Prescribe the loaded shape by its turning angle φ(s) in the plane of
//! d1(0), d3(0). For loads λ·(P, f) the moment M(s) = λ m(s) follows from
//! statics on that shape, and the intrinsic curvature that makes it an
//! equilibrium is κ⁰2 = φ' − λ m2/B2 (paper (43) integrated, (47)). With
//! the linear energy, H does not depend on λ, so the second variation is
//! K(λ) = K0 + λK1: K0 holds the H terms (positive definite), K1 the moment
//! and force terms. λ_crit is the smallest positive λ with K0 + λK1
//! singular, a generalized eigenvalue.

use nalgebra::{Matrix3, Vector3};

use super::eigen::smallest_positive_load_factor;
use super::factored;
use super::second_variation::{Block, FiniteElements, FormCoefficients};
use super::{StabilityError, StabilityOptions};
use crate::equations::RodSample;
use crate::model::{Profile, Rod};
use crate::numerics::integrator::{Dop853, Stops, Tolerances};

/// A loaded shape held fixed while the load varies.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedShape {
    /// The turning angle φ(s) (rad) from d3(0) towards d1(0).
    pub turning_angle: Profile,
}

/// The critical load of a fixed shape.
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalLoad {
    /// The smallest critical load factor over the blocks (multiplies the
    /// problem's loads); None when the shape is stable under any load.
    pub load_factor: Option<f64>,
    /// The dimensionless critical load γ = λ|P|L²/B2(0) (with a tip force;
    /// λ|f|L³/B2(0) with a distributed force only).
    pub gamma: Option<f64>,
    /// (block, λ_crit of that block, its null vector as nodal rotations).
    pub blocks: Vec<(Block, Option<f64>, Vec<Vector3<f64>>)>,
    /// Finite-element nodes.
    pub nodes: Vec<f64>,
}

impl FixedShape {
    /// The shape sampled at sorted points, with the load-per-unit-factor
    /// moment m(s) and force n(s) of `rod.loads`: curvature κ = (0, φ', 0),
    /// moment = body components of m, force = the internal force n. Fails
    /// when the shape's quadrature does (a length or shape so extreme that
    /// the integrator's step underflows).
    pub fn samples(&self, rod: &Rod, points: &[f64]) -> Result<Vec<RodSample>, StabilityError> {
        let c = &rod.clamp();
        let (ex, ez) = (c.director(0), c.director(2));
        let phi = &self.turning_angle;
        // y = (x, z, X, Z): position in the plane and its running integral,
        // for the moment of the distributed force.
        let rhs = |s: f64, y: &[f64], d: &mut [f64]| {
            let (sin, cos) = phi.value(s).sin_cos();
            d.copy_from_slice(&[sin, cos, y[0], y[1]]);
        };
        let mut stops = points.to_vec();
        stops.push(rod.length());
        let mut states = Vec::with_capacity(stops.len());
        let mut y = [0.0; 4];
        let tol = Tolerances::default();
        // The stops (every quadrature point) are read from the continuous
        // extension: the steps are those the tolerance needs however fine
        // the mesh (one step per stop once ran out of the step budget).
        Dop853::new(4)
            .integrate_serving(
                rhs,
                (0.0, rod.length(), 4),
                &mut y,
                &tol,
                &stops,
                Stops::Interpolated,
                |s, y| states.push((s, [y[0], y[1], y[2], y[3]])),
                |_| {},
            )
            .map_err(|e| {
                StabilityError::FixedShape(format!("the shape's quadrature failed: {e}"))
            })?;
        let (_, tip) = *states.last().expect("the tip is a stop");
        // In-plane vectors to global: (a, b) ↦ a ex + b ez.
        let global = |a: f64, b: f64| ex * a + ez * b;
        let loads = &rod.loads();
        Ok(states[..points.len()]
            .iter()
            .map(|(s, v)| {
                let (sin, cos) = phi.value(*s).sin_cos();
                let frame = Matrix3::from_columns(&[
                    ex * cos - ez * sin,
                    c.director(1),
                    ex * sin + ez * cos,
                ]);
                let to_tip = global(tip[0] - v[0], tip[1] - v[1]);
                // ∫_s^L (r(t) − r(s)) dt = Q(L) − Q(s) − (L − s) r(s), in plane.
                let rest = rod.length() - s;
                let lever = global(tip[2] - v[2] - rest * v[0], tip[3] - v[3] - rest * v[1]);
                let m = loads.tip_couple
                    + to_tip.cross(&loads.tip_force)
                    + lever.cross(&loads.distributed_force);
                RodSample {
                    s: *s,
                    position: c.position + global(v[0], v[1]),
                    directors: [
                        frame.column(0).into(),
                        frame.column(1).into(),
                        frame.column(2).into(),
                    ],
                    curvature: Vector3::new(0.0, phi.derivative(*s), 0.0),
                    moment: frame.transpose() * m,
                    force: loads.internal_force(*s, rod.length()),
                }
            })
            .collect())
    }
}

/// K0 (stiffness terms) and K1 (terms per unit load factor) coefficients.
pub(super) fn split_coefficients(
    rod: &Rod,
    samples: &[RodSample],
) -> (Vec<FormCoefficients>, Vec<FormCoefficients>) {
    let zero = Vector3::zeros();
    samples
        .iter()
        .map(|p| {
            let frame = Matrix3::from_columns(&p.directors);
            let force = frame.transpose() * p.force;
            let h = rod.energy().stiffness(p.s, &p.curvature);
            (
                FormCoefficients::at(&h, &p.curvature, &zero, &zero),
                FormCoefficients::at(&Matrix3::zeros(), &p.curvature, &p.moment, &force),
            )
        })
        .unzip()
}

/// The critical load of `shape` under `rod.loads` scaled by λ.
pub fn critical_load(
    rod: &Rod,
    shape: &FixedShape,
    opts: &StabilityOptions,
) -> Result<CriticalLoad, StabilityError> {
    check_scene(rod)?;
    let fe = FiniteElements::new(rod.length(), opts.elements, opts.order);
    let samples = shape.samples(rod, &fe.quadrature_points())?;
    let (c0, c1) = split_coefficients(rod, &samples);
    let mut blocks = Vec::new();
    for block in [Block::InPlane, Block::OutOfPlane] {
        let (k0, k1) = (fe.stiffness(&c0, block), fe.stiffness(&c1, block));
        let found = smallest_positive_load_factor(&k0, &k1)?;
        let (lambda, mode) = match found {
            Some((l, v)) => (
                Some(factored::load_factor(&fe, (&c0, &c1), block, &v).unwrap_or(l)),
                fe.nodal_rotations(block, &v),
            ),
            None => (None, vec![]),
        };
        blocks.push((block, lambda, mode));
    }
    let load_factor = blocks.iter().filter_map(|b| b.1).reduce(f64::min);
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
        blocks,
        nodes: fe.nodes(),
    })
}

/// Refuses a rod that is not a fixed-shape scene: a quadratic energy (H
/// independent of the load), forces only, a clamped free-tipped Kirchhoff
/// cantilever with its loads in the plane of the shape.
pub(super) fn check_scene(rod: &Rod) -> Result<(), StabilityError> {
    check_cantilever(rod)?;
    let normal = rod.clamp().director(1);
    let off_plane =
        rod.loads().tip_force.dot(&normal).abs() + rod.loads().distributed_force.dot(&normal).abs();
    if off_plane > 0.0 {
        return Err(StabilityError::FixedShape(
            "the loads must lie in the plane of d1(0), d3(0)".into(),
        ));
    }
    Ok(())
}

/// The scene checks a planar and a spatial fixed shape share: the linear
/// energy (H independent of the load), forces only, a clamped
/// free-tipped Kirchhoff cantilever (no shear or extension).
pub(super) fn check_cantilever(rod: &Rod) -> Result<(), StabilityError> {
    if !rod.energy().is_quadratic() {
        return Err(StabilityError::FixedShape(format!(
            "the {} energy's Hessian depends on the load through κ − κ⁰, so K(λ) is not linear in λ; \
             use the linear energy",
            rod.energy().name()
        )));
    }
    if rod.loads().tip_couple.norm() > 0.0 {
        return Err(StabilityError::NonConservative(
            "a fixed-shape scene takes forces only".into(),
        ));
    }
    let strained =
        rod.energy().strain_energy().is_some() || rod.energy().shear_stiffness(0.0).is_some();
    if rod.clamp().hinge || rod.support().is_some() || strained {
        return Err(StabilityError::FixedShape(
            "a fixed shape is a clamped, free-tipped Kirchhoff cantilever (paper Sec. 3); \
             remove clamp.hinge, [support] and energy.shear"
                .into(),
        ));
    }
    Ok(())
}
