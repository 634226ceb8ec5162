//! ∂F/∂p of a continued family is exact: the sensitivity equations
//! (z' = f_y z + ∂f/∂p with the clamp's, the tip residual's and the units'
//! explicit p-dependence) against a reference computed independently —
//! central differences of the residual F(x, p ± h) alone, Richardson
//! extrapolated from h, h/2, h/4 (error O(h⁶)), which never touches the
//! tangent, the energy rates or the sensitivity column. Every native
//! parameter kind on the planar, Kirchhoff and Cosserat levels, on single
//! and multiple shooting and on the Gauss collocation continuation uses.
//!
//! The agreement asked is 1e-10 of max |F_p| (measured: ≤ 3e-12). The
//! collocation residual is a smooth function of p (a fixed mesh, Newton on
//! the stages to rounding); shooting integrates adaptively at a 1e-13
//! tolerance, whose step selection could only add jumps of that order to
//! the reference's differences (divided by h = 1e-2). The old central
//! difference (h = 1e-4) carries ~1e-8 truncation error and would not
//! pass.

mod support;

use std::sync::Arc;

use cosserat::continuation::{DerivativeMethod, Family, Parameter};
use cosserat::model::{
    Clamp, DeadLoads, Frame, Freedom, LinearElastic, ModelLevel, Rod, Shearable, TipSupport,
};
use cosserat::numerics::integrator::Tolerances;
use nalgebra::{DVector, Vector3};
use support::parameter_derivative::richardson_parameter_derivative;

const TIGHT: Tolerances = Tolerances {
    rtol: 1e-13,
    atol: 1e-13,
    max_steps: 200_000,
};

/// A rod loaded in the plane of d1(0), d3(0) (the paper's clamp), bent
/// about d2 only, with a uniform intrinsic curvature κ⁰2.
fn planar_rod() -> Rod {
    Rod::new(
        1.3,
        Arc::new(LinearElastic::uniform([1.1, 1.4, 0.9], [0.0, 0.35, 0.0]).unwrap()),
        Clamp::paper(),
        DeadLoads {
            tip_force: Vector3::new(0.6, 0.0, -1.1),
            tip_couple: Vector3::new(0.0, 0.3, 0.0),
            distributed_force: Vector3::new(0.4, 0.0, -0.2),
            point_loads: Vec::new(),
        },
        None,
    )
    .unwrap()
}

/// A rod loaded out of every plane, curved about every axis.
fn spatial_rod() -> Rod {
    Rod::new(
        1.2,
        Arc::new(LinearElastic::uniform([1.2, 0.8, 0.6], [0.2, -0.3, 0.4]).unwrap()),
        Clamp::paper(),
        DeadLoads {
            tip_force: Vector3::new(0.5, -0.4, -0.9),
            tip_couple: Vector3::new(0.1, 0.2, -0.15),
            distributed_force: Vector3::new(0.3, 0.2, -0.1),
            point_loads: Vec::new(),
        },
        None,
    )
    .unwrap()
}

/// [`spatial_rod`] with shear and extension.
fn cosserat_rod() -> Rod {
    let rod = spatial_rod();
    let energy = Shearable::new(rod.energy().clone(), Vector3::new(40.0, 30.0, 60.0)).unwrap();
    rod.with_energy(Arc::new(energy))
}

/// `rod` held at its tip as `translation`, `rotation` say: at a point
/// off the unloaded tip, in a frame turned about d2 by 0.3 rad.
fn supported(rod: Rod, translation: Freedom, rotation: Freedom) -> Rod {
    let support = TipSupport {
        position: Vector3::new(0.25, 0.0, 0.9 * rod.length()),
        frame: Frame::identity().turned(1, 0.3).unwrap(),
        translation,
        rotation,
    };
    rod.with_support(Some(support)).unwrap()
}

/// The base rod's own value of the parameter.
fn value(rod: &Rod, parameter: Parameter) -> f64 {
    let loads = rod.loads();
    let zero = Vector3::zeros();
    match parameter {
        Parameter::LoadScale | Parameter::ControlScale => 1.0,
        Parameter::TipForce(i) => loads.tip_force[i],
        Parameter::TipCouple(i) => loads.tip_couple[i],
        Parameter::DistributedForce(i) => loads.distributed_force[i],
        Parameter::Length => rod.length(),
        Parameter::Stiffness(i) => rod.energy().stiffness(0.0, &zero)[(i, i)],
        Parameter::IntrinsicCurvature(i) => {
            let b = rod.energy().stiffness(0.0, &zero)[(i, i)];
            -rod.energy().moment(0.0, &zero)[i] / b
        }
        Parameter::ClampAngle => 0.0,
        Parameter::CurvatureTowards => unreachable!("not a kind tested here"),
    }
}

/// Unknowns off the solution: the straight-rod guess integrated on the
/// rod at a nearby value p + δ, so that every matching residual and the
/// tip residuals, and hence their units' rates, enter F_p at p. The
/// directors stay orthonormal, as at every point of a branch (the held
/// frame's tip Jacobian is exact there).
fn unknowns(family: &Family, p: f64) -> Vec<f64> {
    family
        .initial_unknowns(p + 0.05 * p.abs().max(1.0))
        .unwrap()
}

fn check(rod: &Rod, level: ModelLevel, parameters: &[Parameter]) {
    for &parameter in parameters {
        let p = value(rod, parameter);
        let h = 1e-2 * p.abs().max(1.0);
        let families = [
            (
                "single shooting",
                Family::new(rod.clone(), parameter, level, 1, TIGHT),
            ),
            (
                "multiple shooting",
                Family::new(rod.clone(), parameter, level, 4, TIGHT),
            ),
            (
                "collocation",
                Family::collocation(rod.clone(), parameter, level, 12, 3, TIGHT),
            ),
        ];
        for (method, family) in families {
            assert_eq!(
                family.derivative_method(p).unwrap(),
                DerivativeMethod::Exact,
                "{parameter} on {level:?}"
            );
            let x = unknowns(&family, p);
            let exact = family.parameter_derivative(&x, p).unwrap();
            let fd = richardson_parameter_derivative(&family, &x, p, h);
            let err = (&exact - &fd).amax();
            // F_p carried by the integration of F and F_x at (x, p).
            let n = x.len();
            let (mut r, mut fx) = (DVector::zeros(n), nalgebra::DMatrix::zeros(n, n));
            family.residual(&x, p, &mut r, &mut fx).unwrap();
            let carried = family.parameter_derivative(&x, p).unwrap();
            let err = err.max((&carried - &fd).amax());
            assert!(
                err <= 1e-10 * fd.amax(),
                "{parameter}, {level:?}, {method}: |F_p − reference| = {err:e}, \
                 |F_p| = {:e}\nexact {exact}\nreference {fd}",
                fd.amax()
            );
        }
    }
}

#[test]
fn planar_parameters() {
    use Parameter::*;
    check(
        &planar_rod(),
        ModelLevel::Planar,
        &[
            LoadScale,
            ControlScale,
            TipForce(0),
            TipForce(2),
            TipCouple(1),
            DistributedForce(0),
            DistributedForce(2),
            Length,
            Stiffness(1),
            IntrinsicCurvature(1),
            ClampAngle,
        ],
    );
}

const SPATIAL: [Parameter; 17] = [
    Parameter::LoadScale,
    Parameter::ControlScale,
    Parameter::TipForce(0),
    Parameter::TipForce(1),
    Parameter::TipForce(2),
    Parameter::TipCouple(0),
    Parameter::TipCouple(1),
    Parameter::TipCouple(2),
    Parameter::DistributedForce(0),
    Parameter::DistributedForce(1),
    Parameter::DistributedForce(2),
    Parameter::Length,
    Parameter::Stiffness(0),
    Parameter::Stiffness(2),
    Parameter::IntrinsicCurvature(0),
    Parameter::IntrinsicCurvature(2),
    Parameter::ClampAngle,
];

/// A pinned tip and a sliding clamp in the plane.
#[test]
fn planar_parameters_with_a_supported_tip() {
    use Parameter::*;
    let kinds = [
        LoadScale,
        TipForce(0),
        TipCouple(1),
        DistributedForce(2),
        Length,
        Stiffness(1),
        IntrinsicCurvature(1),
        ClampAngle,
    ];
    let pinned = supported(planar_rod(), Freedom::Fixed, Freedom::Free);
    check(&pinned, ModelLevel::Planar, &kinds);
    let sliding = supported(planar_rod(), Freedom::Axial(Vector3::z()), Freedom::Fixed);
    check(&sliding, ModelLevel::Planar, &kinds);
}

/// Every spatial support kind: clamped, pinned, a sliding pin, a clamp
/// free to spin, on the Kirchhoff and the Cosserat level.
#[test]
fn spatial_parameters_with_a_supported_tip() {
    let axis = Vector3::new(0.2, 0.1, 1.0).normalize();
    let supports = [
        (Freedom::Fixed, Freedom::Fixed),
        (Freedom::Fixed, Freedom::Free),
        (Freedom::Axial(axis), Freedom::Free),
        (Freedom::Fixed, Freedom::Axial(axis)),
    ];
    for (translation, rotation) in supports {
        for (rod, level) in [
            (spatial_rod(), ModelLevel::Kirchhoff),
            (cosserat_rod(), ModelLevel::Cosserat),
        ] {
            check(&supported(rod, translation, rotation), level, &SPATIAL);
        }
    }
}

#[test]
fn kirchhoff_parameters() {
    check(&spatial_rod(), ModelLevel::Kirchhoff, &SPATIAL);
}

#[test]
fn cosserat_parameters() {
    check(&cosserat_rod(), ModelLevel::Cosserat, &SPATIAL);
}

/// The reference discriminates: the central difference F_p of before
/// (h = 1e-4, the fallback) misses it by far more than the exact one.
#[test]
fn the_central_difference_misses_the_reference() {
    let rod = spatial_rod();
    let family = Family::collocation(rod, Parameter::Length, ModelLevel::Kirchhoff, 12, 3, TIGHT);
    let p = 1.2;
    let x = unknowns(&family, p);
    let fd = richardson_parameter_derivative(&family, &x, p, 1e-2 * p);
    let exact = (&family.parameter_derivative(&x, p).unwrap() - &fd).amax();
    let central = (&family.central_difference(&x, p).unwrap() - &fd).amax();
    assert!(central > 1e-10 * fd.amax(), "{central:e}");
    assert!(exact < 1e-2 * central, "{exact:e} vs {central:e}");
}

/// A problem-file key (the problem reread with the key set) is exact
/// where it names a number the tangent covers — the held tip position,
/// the held frame's turn, a load of a supported rod, the clamp's turn —
/// and a central difference, said so, elsewhere (the support's axis).
#[test]
fn file_keys_are_exact_where_the_tangent_covers_them() {
    // A held tip whose frame defaults to the clamp's: the reread problem
    // keeps it at its start value (it used to turn with the clamp, so the
    // exact F_p disagreed with the residual's own difference).
    let twisted_at_clamp = include_str!("../../../problems/twisted_rod.toml").replace(
        "d3 = [0.0, 0.0, 1.0]\n",
        "d3 = [0.0, 0.0, 1.0]\nturn = { axis = [0.0, 0.0, 1.0], angle = 0.0 }\n",
    );
    let cases = [
        (twisted_at_clamp.as_str(), "clamp.turn.angle"),
        (
            include_str!("../../../problems/clamped_elastica_displacement.toml"),
            "support.position[2]",
        ),
        (
            include_str!("../../../problems/twisted_rod.toml"),
            "support.turn.angle",
        ),
        (
            include_str!("../../../problems/greenhill.toml"),
            "loads.tip_force[2]",
        ),
        (
            include_str!("../../../problems/twisted_rod.toml"),
            "clamp.angle",
        ),
    ];
    for (text, key) in cases {
        let set = [format!("continuation.parameter={key}")];
        let problem = cosserat::input::Problem::from_str_with(text, &set).unwrap();
        let (family, opts) = problem.continuation.clone().unwrap();
        let p = opts.start;
        assert_eq!(
            family.derivative_method(p).unwrap(),
            DerivativeMethod::Exact,
            "{key}"
        );
        // These problems shoot once: the unknowns are the clamp's free
        // values (κ(0), the reaction), moved off the straight rod's balance.
        let mut x = unknowns(&family, p);
        for (i, v) in x.iter_mut().enumerate() {
            *v += 0.3 * (1.0 + i as f64).sin();
        }
        let exact = family.parameter_derivative(&x, p).unwrap();
        let fd = richardson_parameter_derivative(&family, &x, p, 1e-2 * p.abs().max(1.0));
        let err = (&exact - &fd).amax();
        assert!(
            err <= 1e-10 * fd.amax(),
            "{key}: |F_p − reference| = {err:e}, |F_p| = {:e}",
            fd.amax()
        );
    }
    let text = include_str!("../../../problems/greenhill.toml");
    let set = [
        "continuation.parameter=support.axis[2]".to_string(),
        "continuation.start=-1.0".to_string(),
        "continuation.bounds=[-1.5, -0.5]".to_string(),
    ];
    let problem = cosserat::input::Problem::from_str_with(text, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    assert_eq!(
        family.derivative_method(opts.start).unwrap(),
        DerivativeMethod::CentralDifference
    );
}
