//! Equilibria against closed forms: the elastica cantilever (elliptic
//! integrals), the roll-up under an end couple, the unloaded helix, and the
//! agreement of models and methods where they overlap.
mod support;

use std::f64::consts::TAU;
use std::sync::Arc;

use cosserat::bvp::{solve, Method, SolverOptions, Strategy};
use cosserat::model::{
    Clamp, DeadLoads, LinearElastic, ModelChoice, ModelLevel, QuarticStiffening, Rod,
};
use cosserat::references::CantileverTip;
use nalgebra::{Matrix3, Vector3};
use support::methods::{solve_with, EVERY_METHOD, UNSHEARABLE_LEVELS};
use support::quadrature::simpson;
use support::rods::cantilever;

#[test]
fn cantilever_tip_matches_elliptic_integrals() {
    for k in [0.5, 1.0, 3.0, 10.0] {
        let reference = CantileverTip::at(k);
        let rod = cantilever(k);
        assert_eq!(ModelChoice::for_rod(&rod).level, ModelLevel::Planar);
        for level in UNSHEARABLE_LEVELS {
            for method in EVERY_METHOD {
                let eq = solve_with(&rod, level, method);
                let tip = eq.tip();
                let d3 = tip.directors[2];
                let angle = d3[0].atan2(d3[2]);
                let errors = [
                    (tip.position[0] - reference.x).abs(),
                    (tip.position[2] - reference.z).abs(),
                    tip.position[1].abs(),
                    (angle - reference.angle).abs(),
                ];
                let worst = errors.iter().copied().fold(0.0, f64::max);
                assert!(
                    worst <= 1e-9,
                    "k = {k}, {level:?}, {method:?}: errors {errors:?}"
                );
            }
        }
    }
}

#[test]
fn planar_and_spatial_models_agree_on_planar_scenes() {
    for k in [0.5, 3.0, 10.0] {
        let rod = cantilever(k);
        let planar = solve_with(&rod, ModelLevel::Planar, Method::Shooting);
        let spatial = solve_with(&rod, ModelLevel::Kirchhoff, Method::Shooting);
        for (a, b) in planar.samples.iter().zip(&spatial.samples) {
            assert!(
                (a.position - b.position).norm() <= 1e-10,
                "k = {k}, s = {}",
                a.s
            );
            assert!(
                (a.curvature - b.curvature).norm() <= 1e-10,
                "k = {k}, s = {}",
                a.s
            );
        }
    }
}

#[test]
fn end_couple_rolls_the_rod_into_a_circle() {
    let b2 = 1.0;
    let rod = cantilever(0.0);
    let mut loads = rod.loads().clone();
    loads.tip_couple = Vector3::new(0.0, TAU * b2 / rod.length(), 0.0);
    let rod = rod.with_loads(loads).unwrap();
    for level in UNSHEARABLE_LEVELS {
        for method in EVERY_METHOD {
            let eq = solve_with(&rod, level, method);
            let tip = eq.tip();
            assert!(
                tip.position.norm() <= 1e-9,
                "{level:?} {method:?}: tip {}",
                tip.position
            );
            assert!((tip.directors[2] - Vector3::z()).norm() <= 1e-9);
            // A circle of radius L/2π through the clamp, centre at x = L/2π.
            let r = rod.length() / TAU;
            for p in &eq.samples {
                let c = Vector3::new(r, 0.0, 0.0);
                assert!(((p.position - c).norm() - r).abs() <= 1e-9, "s = {}", p.s);
            }
        }
    }
}

/// r(s) = R0 [s I + (1 − cos ωs)/ω² K + (ωs − sin ωs)/ω³ K²] e3 with
/// K = [κ⁰]× and ω = |κ⁰|: the frame is R0 exp(sK) for a constant body
/// Darboux vector.
fn helix_position(kappa0: Vector3<f64>, s: f64) -> Vector3<f64> {
    let w = kappa0.norm();
    let k = kappa0.cross_matrix();
    let m = Matrix3::identity() * s
        + k * ((1.0 - (w * s).cos()) / (w * w))
        + k * k * ((w * s - (w * s).sin()) / (w * w * w));
    m * Vector3::z()
}

#[test]
fn unloaded_rod_with_constant_intrinsic_curvature_is_a_helix() {
    let kappa0 = Vector3::new(1.3, -0.7, 2.1);
    let rod = Rod::new(
        3.0,
        Arc::new(LinearElastic::uniform([1.0, 2.0, 0.8], kappa0.into()).unwrap()),
        Clamp::new(Vector3::zeros(), Vector3::x(), Vector3::z()).unwrap(),
        DeadLoads::default(),
        None,
    )
    .unwrap();
    let choice = ModelChoice::for_rod(&rod);
    assert_eq!(choice.level, ModelLevel::Kirchhoff, "{}", choice.reason);
    for method in EVERY_METHOD {
        let eq = solve_with(&rod, ModelLevel::Kirchhoff, method);
        for p in &eq.samples {
            let exact = helix_position(kappa0, p.s);
            assert!(
                (p.position - exact).norm() <= 1e-9,
                "{method:?} s = {}",
                p.s
            );
        }
        // Shooting projects the directors back to orthonormal after every
        // step; collocation does not (d1·d2 and |d1|² − |d2|² are not
        // quadratic invariants of the 9-ODE system), so its drift is
        // discretization error, measured and bounded by its tolerance.
        let bound = match method {
            Method::Collocation { .. } => SolverOptions::default().collocation.tolerance,
            _ => 1e-12,
        };
        assert!(
            eq.director_drift <= bound,
            "{method:?}: drift {}",
            eq.director_drift
        );
    }
}

/// A spatial scene (helix under a tip load, quartic energy): single and
/// multiple shooting find the same equilibrium.
#[test]
fn single_and_multiple_shooting_agree() {
    let linear = LinearElastic::uniform([1.0, 1.5, 0.7], [0.8, 0.3, 1.2]).unwrap();
    let energies: Vec<Arc<dyn cosserat::model::StoredEnergy>> = vec![
        Arc::new(linear.clone()),
        Arc::new(QuarticStiffening::new(linear, 0.5).unwrap()),
    ];
    for energy in energies {
        let rod = Rod::new(
            2.0,
            energy,
            Clamp::paper(),
            DeadLoads {
                tip_force: Vector3::new(0.6, 0.2, -0.1),
                tip_couple: Vector3::new(0.0, 0.1, 0.2),
                distributed_force: Vector3::new(0.3, 0.0, 0.0),
                point_loads: Vec::new(),
            },
            None,
        )
        .unwrap();
        let single = solve_with(&rod, ModelLevel::Kirchhoff, Method::Shooting);
        let multi = solve_with(&rod, ModelLevel::Kirchhoff, EVERY_METHOD[1]);
        for (a, b) in single.samples.iter().zip(&multi.samples) {
            assert!((a.position - b.position).norm() <= 1e-9, "s = {}", a.s);
        }
    }
}

/// Large loads: the ramp from the unloaded rod follows the loading branch
/// (a direct start at k = 30 can converge to a looped equilibrium).
#[test]
fn large_load_follows_the_loading_branch() {
    ramps_to_the_closed_form(30.0, &EVERY_METHOD);
}

/// The planar cantilever at load k, solved by each of `methods`, ramps the
/// load and ends on the loading branch: the tip within 1e-9 of the
/// elliptic-integral closed form.
fn ramps_to_the_closed_form(k: f64, methods: &[Method]) {
    let reference = CantileverTip::at(k);
    for &method in methods {
        let eq = solve_with(&cantilever(k), ModelLevel::Planar, method);
        assert!(eq.load_steps > 0, "{method:?} should ramp at k = {k}");
        let tip = eq.tip().position;
        assert!(
            (tip[0] - reference.x).abs() <= 1e-9,
            "{method:?}: x {}",
            tip[0]
        );
        assert!(
            (tip[2] - reference.z).abs() <= 1e-9,
            "{method:?}: z {}",
            tip[2]
        );
    }
}

/// At k = 100 the shooting sensitivities grow like exp(√k s) ≈ e¹⁰: a
/// direct single-shooting start must fail with a clear error; the load
/// ramp (intermediate steps at warm-start accuracy, secant predictor)
/// reaches the loading branch, and so does multiple shooting, both to the
/// closed form within 1e-9.
#[test]
fn single_shooting_fails_clearly_where_multiple_shooting_recovers() {
    let k = 100.0;
    let rod = cantilever(k);
    let choice = ModelChoice::forced(&rod, ModelLevel::Planar).unwrap();
    let direct = SolverOptions {
        strategy: Strategy::Direct,
        ..Default::default()
    };
    let err = solve(&rod, &choice, &direct).unwrap_err();
    let message = err.to_string();
    assert!(message.contains("shooting"), "{message}");
    assert!(message.contains("did not converge"), "{message}");
    ramps_to_the_closed_form(k, &[Method::Shooting, EVERY_METHOD[1]]);
}

/// [`Strategy::Auto`] below the ramp threshold (k = 0.5): a direct start
/// from a wrong guess (κ(0) = 1e5 against 0.49: more turns than 400
/// integrator steps can follow) fails, and the load ramp,
/// which starts from the unloaded rod, rescues it — the closed form to
/// 1e-9, the ramp's steps reported.
#[test]
fn failed_direct_start_is_rescued_by_the_ramp() {
    let k = 0.5;
    let rod = cantilever(k);
    let choice = ModelChoice::forced(&rod, ModelLevel::Planar).unwrap();
    let opts = SolverOptions {
        initial_guess: Some(vec![0.0, 1e5, 0.0]),
        integration: cosserat::bvp::integrator::Tolerances {
            max_steps: 400,
            ..Default::default()
        },
        ..Default::default()
    };
    let direct = SolverOptions {
        strategy: Strategy::Direct,
        ..opts.clone()
    };
    assert!(
        solve(&rod, &choice, &direct).is_err(),
        "the direct start must fail"
    );
    let eq = solve(&rod, &choice, &opts).expect("the ramp rescues it");
    assert!(eq.load_steps > 0);
    let (tip, reference) = (eq.tip().position, CantileverTip::at(k));
    assert!((tip[0] - reference.x).abs() <= 1e-9, "x {}", tip[0]);
    assert!((tip[2] - reference.z).abs() <= 1e-9, "z {}", tip[2]);
}

/// Both the direct start and the ramp fail (an integrator budget of 3
/// steps cannot cross the rod): the named error of the ramp, carrying the
/// last failure, never a result.
#[test]
fn direct_and_ramp_failing_is_a_named_error() {
    let rod = cantilever(0.5);
    let choice = ModelChoice::forced(&rod, ModelLevel::Planar).unwrap();
    let opts = SolverOptions {
        integration: cosserat::bvp::integrator::Tolerances {
            max_steps: 3,
            ..Default::default()
        },
        ..Default::default()
    };
    let err = solve(&rod, &choice, &opts).unwrap_err();
    assert!(
        matches!(err, cosserat::bvp::SolveError::RampStalled { .. }),
        "{err}"
    );
    assert!(err.to_string().contains("steps before"), "{err}");
}

/// A tapered cantilever, B2(s) = 2 − s (polynomial profile), under a small
/// tip force: linear beam theory (unit-load method) gives the deflection
/// δ = F ∫₀¹ (1 − s)²/(2 − s) ds = F (ln 2 − ½); the nonlinear correction
/// is O(F²) relative.
#[test]
fn tapered_cantilever_matches_linear_beam_theory() {
    use cosserat::model::Profile;
    let force = 1e-4;
    let energy = LinearElastic::new(
        [
            Profile::Constant(10.0),
            Profile::Polynomial(vec![2.0, -1.0]),
            Profile::Constant(10.0),
        ],
        Default::default(),
    )
    .unwrap();
    let rod = cantilever(force).with_energy(Arc::new(energy));
    let mut opts = SolverOptions::default();
    opts.newton.tolerance = 1e-14;
    let eq = solve(&rod, &ModelChoice::for_rod(&rod), &opts).unwrap();
    let exact = force * (2f64.ln() - 0.5);
    let rel = (eq.tip().position[0] - exact).abs() / exact;
    assert!(rel <= 1e-6, "relative error {rel}");
}

/// An unloaded rod whose intrinsic curvature κ⁰2 is a piecewise-linear
/// table takes its intrinsic shape: φ = ∫κ⁰2 (piecewise quadratic, exact),
/// tip = ∫ (sin φ, cos φ) by composite Simpson with the knot as a panel
/// boundary.
#[test]
fn tabulated_intrinsic_curvature_gives_its_intrinsic_shape() {
    use cosserat::model::Profile;
    let (knots, values) = ([0.0, 0.4, 1.0], [0.0, 3.0, -1.0]);
    let energy = LinearElastic::new(
        [1.0, 1.0, 1.0].map(Profile::Constant),
        [
            Profile::Constant(0.0),
            Profile::table(knots.to_vec(), values.to_vec()).unwrap(),
            Profile::Constant(0.0),
        ],
    )
    .unwrap();
    let rod = cantilever(0.0).with_energy(Arc::new(energy));
    // φ(s) exactly: integral of the linear interpolant.
    let phi = |s: f64| {
        let mut acc = 0.0;
        for i in 0..2 {
            let (a, b) = (knots[i], knots[i + 1]);
            let t = s.clamp(a, b) - a;
            let slope = (values[i + 1] - values[i]) / (b - a);
            acc += values[i] * t + 0.5 * slope * t * t;
        }
        acc
    };
    let x = simpson(|s| phi(s).sin(), 0.0, 0.4) + simpson(|s| phi(s).sin(), 0.4, 1.0);
    let z = simpson(|s| phi(s).cos(), 0.0, 0.4) + simpson(|s| phi(s).cos(), 0.4, 1.0);
    for level in UNSHEARABLE_LEVELS {
        let eq = solve_with(&rod, level, Method::Shooting);
        let tip = eq.tip().position;
        assert!(
            (tip[0] - x).abs() <= 1e-9 && (tip[2] - z).abs() <= 1e-9,
            "{level:?}: {tip}"
        );
    }
}

/// A singular energy Hessian (a torsional stiffness B3 = 1 − 2s that
/// vanishes at s = L/2, built in code where the problem-file checks do not
/// apply) is a typed error naming the cause. A zero constant stiffness is
/// refused when the energy is built.
#[test]
fn singular_energy_hessian_is_a_typed_error() {
    assert!(matches!(
        LinearElastic::uniform([1.0, 1.0, 0.0], [0.0; 3]),
        Err(cosserat::model::ModelError::Stiffness { index: 2, .. })
    ));
    let vanishing = LinearElastic::new(
        [
            cosserat::model::Profile::Constant(1.0),
            cosserat::model::Profile::Constant(1.0),
            cosserat::model::Profile::Polynomial(vec![1.0, -2.0]),
        ],
        Default::default(),
    )
    .unwrap();
    let rod = cantilever(1.0).with_energy(Arc::new(vanishing));
    let err = solve(&rod, &ModelChoice::for_rod(&rod), &SolverOptions::default()).unwrap_err();
    assert!(matches!(err, cosserat::bvp::SolveError::Model(_)), "{err}");
    assert!(err.to_string().contains("not positive definite"), "{err}");
}

/// Loads so large that no method converges within its budget: a typed
/// error, never a result.
#[test]
fn hopeless_load_is_an_error() {
    let rod = cantilever(1e5);
    let opts = SolverOptions {
        method: Method::MultipleShooting { segments: 4 },
        integration: cosserat::bvp::integrator::Tolerances {
            max_steps: 2000,
            ..Default::default()
        },
        ..Default::default()
    };
    let err = solve(&rod, &ModelChoice::for_rod(&rod), &opts).unwrap_err();
    assert!(
        matches!(err, cosserat::bvp::SolveError::RampStalled { .. }),
        "{err}"
    );
}

/// The same input gives bit-identical output.
#[test]
fn solves_are_bit_reproducible() {
    let rod = cantilever(3.0);
    let run = || {
        solve_with(
            &rod,
            ModelLevel::Kirchhoff,
            Method::MultipleShooting { segments: 8 },
        )
    };
    let (a, b) = (run(), run());
    for (p, q) in a.samples.iter().zip(&b.samples) {
        assert_eq!(p, q);
    }
    assert_eq!(a.residual_history, b.residual_history);
}
