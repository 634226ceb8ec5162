//! Interior point couples (`[[loads.point]]` with a `couple`) against
//! closed forms. A cantilever loaded by a dead couple C at s₀ alone carries
//! the moment m = C on [0, s₀) and none beyond (the moment on [0, s) from
//! (s, L] includes every couple beyond s, as M(L) = C at the tip): the
//! curvature solves ∇W(κ) = C·d_i before s₀ and vanishes after — a
//! circular arc, then a straight piece. Its tip follows in closed form, on
//! the planar and the spatial models and with a nonlinear energy (the
//! curvature by Cardano's formula); the shooting Jacobian across the jump
//! is checked against central differences of the residual; hostile values
//! and the paths that do not carry a couple are refused by name.
mod support;

use std::sync::Arc;

use cosserat::bvp::newton::NonlinearSystem;
use cosserat::bvp::{equations, solve, Method, ShootingSystem};
use cosserat::input::{Problem, ProblemError};
use cosserat::model::{
    Clamp, DeadLoads, LinearElastic, ModelChoice, ModelError, ModelLevel, PointLoad,
    QuarticStiffening, Rod,
};
use cosserat::numerics::integrator::Tolerances;
use nalgebra::{DMatrix, DVector, Vector3};
use support::methods::options;

/// The shooting methods that carry a point couple; 8 segments put a node
/// exactly on s₀ = 0.625 (node states are right limits).
const SHOOTING: [Method; 2] = [Method::Shooting, Method::MultipleShooting { segments: 8 }];

/// A rod of length 1, clamped as in the paper (d1 = e1, d2 = e2, d3 = e3),
/// with `energy`, a couple `couple` at s₀ and nothing else.
fn couple_at(s0: f64, couple: Vector3<f64>, energy: LinearElastic) -> Rod {
    let loads = DeadLoads {
        point_loads: vec![PointLoad {
            s: s0,
            force: Vector3::zeros(),
            couple,
        }],
        ..Default::default()
    };
    Rod::new(1.0, Arc::new(energy), Clamp::paper(), loads, None).unwrap()
}

/// The tip of a rod of length 1 bent to curvature κ about the body axis
/// `bend` (e1 or e2, the clamp's d1 or d2) on [0, s₀] and straight after:
/// the arc turns d3 = e3 towards e3 × ... by θ = κ s₀; returns the tip
/// position and d3 at the tip.
fn arc_then_straight(kappa: f64, s0: f64, toward: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let theta = kappa * s0;
    let at_load = toward * ((1.0 - theta.cos()) / kappa) + Vector3::z() * (theta.sin() / kappa);
    let d3 = toward * theta.sin() + Vector3::z() * theta.cos();
    (at_load + d3 * (1.0 - s0), d3)
}

#[test]
fn a_couple_inside_bends_an_arc_then_leaves_the_rod_straight() {
    let b2 = 1.0;
    let c = 1.2;
    for s0 in [0.6, 0.625] {
        let rod = couple_at(
            s0,
            Vector3::new(0.0, c, 0.0),
            LinearElastic::uniform([10.0, b2, 10.0], [0.0; 3]).unwrap(),
        );
        assert_eq!(ModelChoice::for_rod(&rod).level, ModelLevel::Planar);
        // d3' = κ2 d2 × d3 = κ2 d1 = κ2 e1: the arc turns towards e1.
        let (tip, d3) = arc_then_straight(c / b2, s0, Vector3::x());
        for level in [ModelLevel::Planar, ModelLevel::Kirchhoff] {
            for method in SHOOTING {
                let choice = ModelChoice::forced(&rod, level).unwrap();
                let eq = solve(&rod, &choice, &options(method)).unwrap();
                let samples = eq
                    .resample(&rod, &options(method), &[0.0, s0 - 0.01, s0, 1.0])
                    .unwrap();
                let errors = [
                    (samples[3].position - tip).norm(),
                    (samples[3].directors[2] - d3).norm(),
                    (samples[0].curvature - Vector3::new(0.0, c / b2, 0.0)).norm(),
                    (samples[1].curvature - Vector3::new(0.0, c / b2, 0.0)).norm(),
                    samples[2].curvature.norm(),
                    samples[3].curvature.norm(),
                ];
                let worst = errors.iter().copied().fold(0.0, f64::max);
                assert!(
                    worst <= 1e-9,
                    "s0 = {s0}, {level:?}, {method:?}: errors {errors:?}"
                );
            }
        }
    }
}

/// A couple about d1 = e1 takes the scene out of its plane: the spatial
/// model, the arc in the plane of e2 and e3 (d3' = κ1 d1 × d3 = −κ1 e2).
#[test]
fn a_couple_about_an_in_plane_axis_bends_the_same_arc_in_space() {
    let (b1, c, s0) = (10.0, 6.0, 0.4);
    let rod = couple_at(
        s0,
        Vector3::new(c, 0.0, 0.0),
        LinearElastic::uniform([b1, 1.0, 10.0], [0.0; 3]).unwrap(),
    );
    let choice = ModelChoice::for_rod(&rod);
    assert_ne!(choice.level, ModelLevel::Planar, "{}", choice.reason);
    let (tip, d3) = arc_then_straight(c / b1, s0, -Vector3::y());
    for method in SHOOTING {
        let eq = solve(&rod, &choice, &options(method)).unwrap();
        let end = eq.resample(&rod, &options(method), &[1.0]).unwrap();
        let errors = [
            (end[0].position - tip).norm(),
            (end[0].directors[2] - d3).norm(),
        ];
        assert!(errors[0].max(errors[1]) <= 1e-9, "{method:?}: {errors:?}");
    }
}

/// W = ½ B |κ|² + ¼ q |κ|⁴ under a couple C e2 at s₀: B κ + q κ³ = C,
/// whose one real root is Cardano's; the jump's Newton finds it.
#[test]
fn a_stiffening_energy_takes_the_curvature_of_cardanos_root() {
    let (b, q, c, s0): (f64, f64, f64, f64) = (1.0, 0.5, 2.0, 0.5);
    let (p, r) = (b / q, c / q);
    let root = (r * r / 4.0 + p * p * p / 27.0).sqrt();
    let kappa = (r / 2.0 + root).cbrt() + (r / 2.0 - root).cbrt();
    assert!((b * kappa + q * kappa.powi(3) - c).abs() <= 1e-13 * c);
    let linear = LinearElastic::uniform([b, b, b], [0.0; 3]).unwrap();
    let energy = QuarticStiffening::new(linear, q).unwrap();
    let loads = DeadLoads {
        point_loads: vec![PointLoad {
            s: s0,
            force: Vector3::zeros(),
            couple: Vector3::new(0.0, c, 0.0),
        }],
        ..Default::default()
    };
    let rod = Rod::new(1.0, Arc::new(energy), Clamp::paper(), loads, None).unwrap();
    let (tip, _) = arc_then_straight(kappa, s0, Vector3::x());
    for level in [ModelLevel::Planar, ModelLevel::Kirchhoff] {
        for method in SHOOTING {
            let choice = ModelChoice::forced(&rod, level).unwrap();
            let eq = solve(&rod, &choice, &options(method)).unwrap();
            let end = eq.resample(&rod, &options(method), &[1.0]).unwrap();
            let error = (end[0].position - tip).norm();
            assert!(error <= 1e-9, "{level:?}, {method:?}: {error:e}");
        }
    }
}

/// The exact Jacobian of shooting across a couple (a skew couple with a
/// tip force, on the quartic energy: the jump's linearization maps the
/// directors' and the curvature's sensitivities) against central
/// differences of the residual, away from the solution: single and
/// multiple shooting, and segments that are single Gauss steps.
#[test]
fn the_shooting_jacobian_across_a_couple_matches_central_differences() {
    let linear = LinearElastic::uniform([2.0, 1.0, 1.5], [0.0; 3]).unwrap();
    let energy = QuarticStiffening::new(linear, 0.3).unwrap();
    let loads = DeadLoads {
        tip_force: Vector3::new(0.5, 0.2, -0.3),
        point_loads: vec![PointLoad {
            s: 0.35,
            force: Vector3::new(0.0, 0.3, 0.0),
            couple: Vector3::new(0.4, -0.7, 0.3),
        }],
        ..Default::default()
    };
    let rod = Rod::new(1.0, Arc::new(energy), Clamp::paper(), loads, None).unwrap();
    // (level, segments, Gauss stages): DOP853 segments, or single Gauss
    // steps split at the couple (the fixed-mesh collocation equations
    // continuation runs).
    for (level, segments, gauss) in [
        (ModelLevel::Kirchhoff, 1, None),
        (ModelLevel::Kirchhoff, 3, None),
        (ModelLevel::Planar, 3, None),
        (ModelLevel::Kirchhoff, 4, Some(3)),
        (ModelLevel::Planar, 4, Some(2)),
    ] {
        let eq = equations(&rod, level);
        let tol = Tolerances {
            rtol: 1e-13,
            atol: 1e-13,
            ..Tolerances::default()
        };
        let mut system = match gauss {
            None => ShootingSystem::new(eq.as_ref(), segments, tol),
            Some(stages) => {
                ShootingSystem::collocation(eq.as_ref(), segments, stages, tol).unwrap()
            }
        };
        let guess: Vec<f64> = eq.initial_guess().iter().map(|u| u + 0.3).collect();
        let x = system.initial_unknowns(&guess);
        let size = system.size();
        let (mut r, mut jac) = (DVector::zeros(size), DMatrix::zeros(size, size));
        system.evaluate(&x, &mut r, &mut jac).unwrap();
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for c in 0..size {
            let (mut up, mut down) = (x.clone(), x.clone());
            up[c] += h;
            down[c] -= h;
            let (mut ru, mut rd) = (DVector::zeros(size), DVector::zeros(size));
            system.residual(&up, &mut ru).unwrap();
            system.residual(&down, &mut rd).unwrap();
            let column = (ru - rd) / (2.0 * h);
            worst = worst.max((column - jac.column(c)).amax());
        }
        eprintln!(
            "{level:?}, K = {segments}, Gauss {gauss:?}: |J − FD| = {worst:e}, |J| = {:e}",
            jac.amax()
        );
        // Central differences: O(h²) ≈ 1e-12 plus the integration's
        // error over h; measured ≤ 4e-10 relative, where a jump without
        // its linearization (the directors' term, or the planar H⁻/H⁺) is
        // off by 1e-1.
        assert!(
            worst <= 1e-7 * jac.amax(),
            "{level:?}, K = {segments}, Gauss {gauss:?}: {worst:e} against |J| = {:e}",
            jac.amax()
        );
    }
}

#[test]
fn a_couple_that_is_not_finite_or_not_inside_is_refused_by_name() {
    let energy = || Arc::new(LinearElastic::uniform([1.0; 3], [0.0; 3]).unwrap());
    for (s, couple) in [
        (0.5, Vector3::new(f64::NAN, 0.0, 0.0)),
        (0.5, Vector3::new(0.0, f64::INFINITY, 0.0)),
        (0.0, Vector3::new(0.0, 1.0, 0.0)),
        (1.0, Vector3::new(0.0, 1.0, 0.0)),
    ] {
        let loads = DeadLoads {
            point_loads: vec![PointLoad {
                s,
                force: Vector3::zeros(),
                couple,
            }],
            ..Default::default()
        };
        let refused = Rod::new(1.0, energy(), Clamp::paper(), loads, None);
        assert!(
            matches!(refused, Err(ModelError::PointLoad { index: 0, .. })),
            "s = {s}, {couple:?}: {refused:?}"
        );
    }
}

const POINT_COUPLE: &str = include_str!("../../../problems/point_couple.toml");

fn refused_field(sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| (*s).to_string()).collect();
    match Problem::from_str_with(POINT_COUPLE, &sets) {
        Err(ProblemError::Invalid { field, .. }) => field,
        other => panic!("{sets:?}: expected a refusal, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn the_problem_file_refuses_what_does_not_carry_a_couple() {
    assert!(Problem::from_str_with(POINT_COUPLE, &[]).is_ok());
    assert_eq!(
        refused_field(&["solver.method=\"collocation\""]),
        "loads.point[0].couple"
    );
    let nan = refused_field(&["loads.point[0].couple=[0.0, nan, 0.0]"]);
    assert!(nan.starts_with("loads.point[0].couple"), "{nan}");
    assert_eq!(refused_field(&["loads.point[0].s=0.0"]), "loads.point[0].s");
}

/// Collocation and the stability analysis say why they do not take a
/// couple (the library's own refusals, beside the problem file's).
#[test]
fn collocation_and_stability_refuse_a_couple_with_the_reason() {
    let rod = couple_at(
        0.5,
        Vector3::new(0.0, 1.0, 0.0),
        LinearElastic::uniform([1.0; 3], [0.0; 3]).unwrap(),
    );
    let choice = ModelChoice::for_rod(&rod);
    let refused = solve(&rod, &choice, &options(Method::Collocation { stages: 3 }))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(refused.contains("point couple"), "{refused}");
    let solved = solve(&rod, &choice, &options(Method::Shooting)).unwrap();
    let stability = cosserat::stability::analyze(
        &rod,
        &solved,
        &options(Method::Shooting),
        &cosserat::stability::StabilityOptions::default(),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(stability.contains("point couple"), "{stability}");
}
