//! Where each method fails, and what solves the same case instead.
//!
//! Every case asserts (a) that the failing method returns a typed error
//! whose message names the method and the cause — no panic, no result
//! passed off as converged — and (b) that multiple shooting or adaptive
//! collocation solves the same case to its tolerance against an independent
//! reference (the elliptic-integral cantilever of Bisshopp & Drucker, or the
//! closed-form intrinsic circle). `Strategy::Direct` exposes the raw
//! failures (no load ramp to hide them).
mod support;

use std::sync::Arc;

use cosserat::bvp::{
    solve, CollocationError, CollocationOptions, Discretization, Equilibrium, Method, SolveError,
    SolverOptions, Strategy,
};
use cosserat::model::{LinearElastic, ModelChoice, ModelLevel, Rod};
use cosserat::references::CantileverTip;
use nalgebra::Vector3;
use support::rods::{tip_force, uniform};

/// The paper's cantilever of length `length`, B2 = 1, tip force `force`
/// along d1(0) = e1: k = F L²/B2.
fn cantilever(length: f64, force: f64) -> Rod {
    uniform(length, [10.0, 1.0, 10.0], tip_force(force, 0.0, 0.0))
}

/// A planar rod with intrinsic curvature κ⁰2 = `kappa` (B2 = 1), unloaded
/// unless `force` ≠ 0.
fn spiral(kappa: f64, force: f64) -> Rod {
    cantilever(1.0, force).with_energy(Arc::new(
        LinearElastic::uniform([10.0, 1.0, 10.0], [0.0, kappa, 0.0]).unwrap(),
    ))
}

fn run(rod: &Rod, method: Method, strategy: Strategy) -> Result<Equilibrium, SolveError> {
    let choice = ModelChoice::forced(rod, ModelLevel::Planar).unwrap();
    let opts = SolverOptions {
        method,
        strategy,
        output_points: 11,
        ..Default::default()
    };
    solve(rod, &choice, &opts)
}

/// The failure is an error naming the method and a cause.
fn assert_clear_failure(result: Result<Equilibrium, SolveError>, method: &str) -> String {
    let err = match result {
        Ok(eq) => panic!(
            "{method} should fail here, returned a result with residual {:e}",
            eq.residual
        ),
        Err(e) => e,
    };
    let message = err.to_string();
    eprintln!("{method}: {message}");
    assert!(message.contains(method), "{message}");
    assert!(
        [
            "did not converge",
            "stalled",
            "singular",
            "exceeds",
            "not reached"
        ]
        .iter()
        .any(|c| message.contains(c)),
        "{message}"
    );
    message
}

/// Largest tip-position error against the elliptic-integral reference of
/// a cantilever of length L with k = F L²/B (lengths scale with L).
fn cantilever_error(eq: &Equilibrium, length: f64, force: f64) -> f64 {
    let reference = CantileverTip::at(force * length * length);
    let tip = eq.tip().position;
    [
        (tip[0] - length * reference.x).abs(),
        (tip[2] - length * reference.z).abs(),
        tip[1].abs(),
    ]
    .into_iter()
    .fold(0.0, f64::max)
        / length
}

/// k = 100 on the unit cantilever: single shooting's sensitivities grow
/// like e^{√k} ≈ 2·10⁴ and its direct solve fails; multiple shooting and
/// adaptive collocation (both orders, with the load ramp) reach 1e-9.
#[test]
fn large_load_single_shooting_fails_others_recover() {
    let rod = cantilever(1.0, 100.0);
    assert_clear_failure(run(&rod, Method::Shooting, Strategy::Direct), "shooting");
    for method in [
        Method::MultipleShooting { segments: 8 },
        Method::Collocation { stages: 2 },
        Method::Collocation { stages: 3 },
    ] {
        let eq = run(&rod, method, Strategy::Auto).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        let err = cantilever_error(&eq, 1.0, 100.0);
        eprintln!(
            "{method:?}: tip error {err:.2e}, {} ramp steps",
            eq.load_steps
        );
        assert!(err <= 1e-9, "{method:?}: tip error {err:e}");
    }
}

/// A long rod: L = 16 under F = 1 (k = 256). Single shooting with the load
/// ramp reaches the loading branch (to its conditioning) or says why not.
/// Its direct solve is the hazard: it converges,
/// but to a looped equilibrium, not the loading branch (asserted here so the
/// hazard stays documented; use the ramp, multiple shooting or
/// collocation). 16-segment multiple shooting and adaptive collocation
/// reach the loading branch to 1e-9.
#[test]
fn long_rod_single_shooting_fails_others_recover() {
    let (length, force) = (16.0, 1.0);
    let rod = cantilever(length, force);
    // The ramp's intermediate steps at warm-start accuracy carry single
    // shooting through where the tight steps stalled: a result then has to
    // be the loading branch (the looped equilibrium lies 1e-2 away), to the
    // accuracy single shooting's conditioning allows: its sensitivities
    // grow like e^{L√(F/B)} = e^16 ≈ 9·10⁶, so integrator rtol 1e-12 bounds
    // the tip error by about 10⁻⁵ — the bound asserted, three decades below
    // the looped equilibrium's 1e-2, so it still tells the branches apart
    // (measured 9.0e-9 on this machine; the other methods 1e-9).
    match run(&rod, Method::Shooting, Strategy::Auto) {
        Ok(eq) => {
            let err = cantilever_error(&eq, length, force);
            eprintln!(
                "ramped single shooting: relative tip error {err:.2e}, {} steps",
                eq.load_steps
            );
            assert!(err <= 1e-5, "{err:e}");
        }
        Err(e) => {
            assert_clear_failure(Err(e), "shooting");
        }
    }
    if let Ok(eq) = run(&rod, Method::Shooting, Strategy::Direct) {
        let err = cantilever_error(&eq, length, force);
        eprintln!("direct single shooting: another equilibrium, relative tip distance {err:.2e}");
        assert!(err > 1e-2, "{err:e}");
        // The framework notices: that equilibrium is unstable (what
        // `cosserat solve` reports with a warning).
        let st = cosserat::stability::analyze(
            &rod,
            &eq,
            &SolverOptions::default(),
            &cosserat::stability::StabilityOptions::default(),
        )
        .unwrap();
        assert!(
            !st.stable,
            "the looped equilibrium should be flagged unstable"
        );
    }
    for method in [
        Method::MultipleShooting { segments: 16 },
        Method::Collocation { stages: 3 },
    ] {
        let eq = run(&rod, method, Strategy::Auto).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        let err = cantilever_error(&eq, length, force);
        eprintln!("{method:?}: relative tip error {err:.2e}");
        assert!(err <= 1e-9, "{method:?}: tip error {err:e}");
    }
}

/// Strongly spiralling intrinsic curvature, κ⁰2 = 40/L: the unloaded rod is
/// a circle of radius L/40 traversed 40/2π ≈ 6.4 times, tip exactly
/// ((1 − cos 40)/40, 0, sin 40/40). Every method reaches it (the shooting
/// guess is the intrinsic shape itself); collocation needs the adapted mesh.
#[test]
fn spiralling_intrinsic_curvature_unloaded() {
    let kappa = 40.0;
    let rod = spiral(kappa, 0.0);
    let exact = Vector3::new((1.0 - kappa.cos()) / kappa, 0.0, kappa.sin() / kappa);
    for method in [
        Method::Shooting,
        Method::MultipleShooting { segments: 8 },
        Method::Collocation { stages: 2 },
        Method::Collocation { stages: 3 },
    ] {
        let eq = run(&rod, method, Strategy::Direct).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        let err = (eq.tip().position - exact).norm();
        let mesh = match &eq.discretization {
            Discretization::Collocation(sol) => sol.intervals(),
            Discretization::Shooting => 0,
        };
        eprintln!("{method:?}: tip error {err:.2e}, mesh {mesh}");
        assert!(err <= 1e-9, "{method:?}: tip error {err:e}");
    }
    // One turn every 2π/40 ≈ 0.157 L: a mesh of 8 intervals puts 5 rad in
    // each; collocation without adaptation refuses it.
    let coarse = SolverOptions {
        method: Method::Collocation { stages: 3 },
        strategy: Strategy::Direct,
        collocation: CollocationOptions {
            intervals: 8,
            adapt: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let choice = ModelChoice::forced(&rod, ModelLevel::Planar).unwrap();
    let message = assert_clear_failure(solve(&rod, &choice, &coarse), "collocation");
    assert!(
        message.contains("exceeds") || message.contains("did not converge"),
        "{message}"
    );
}

/// The same spiral under a tip load F = 5 (F L²/B = 5, but the rod winds
/// 6 times, so the load's moment arm changes sign along it). Multiple
/// shooting and both collocation orders agree to 1e-9 along the rod;
/// single shooting either agrees or says it failed.
#[test]
fn spiralling_intrinsic_curvature_loaded_methods_agree() {
    let rod = spiral(40.0, 5.0);
    let reference = run(
        &rod,
        Method::MultipleShooting { segments: 16 },
        Strategy::Auto,
    )
    .unwrap_or_else(|e| panic!("multiple shooting: {e}"));
    for method in [
        Method::Collocation { stages: 2 },
        Method::Collocation { stages: 3 },
    ] {
        let eq = run(&rod, method, Strategy::Auto).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        let worst = eq
            .samples
            .iter()
            .zip(&reference.samples)
            .map(|(a, b)| (a.position - b.position).norm())
            .fold(0.0, f64::max);
        eprintln!("{method:?}: largest distance to multiple shooting {worst:.2e}");
        assert!(worst <= 1e-9, "{method:?}: {worst:e}");
    }
    match run(&rod, Method::Shooting, Strategy::Auto) {
        Ok(eq) => {
            let d = (eq.tip().position - reference.tip().position).norm();
            eprintln!("single shooting converged, tip distance {d:.2e}");
            assert!(
                d <= 1e-9,
                "single shooting passed off a wrong answer: {d:e}"
            );
        }
        Err(e) => {
            assert_clear_failure(Err(e), "shooting");
        }
    }
}

/// A mesh too coarse for the tolerance without adaptation: `solve` says so
/// with the error estimate; the same start with adaptation meets the
/// tolerance against the elliptic integrals.
#[test]
fn coarse_mesh_without_adaptation_is_refused_adaptation_fixes_it() {
    let rod = cantilever(1.0, 10.0);
    let choice = ModelChoice::forced(&rod, ModelLevel::Planar).unwrap();
    for stages in [2, 3] {
        let fixed = SolverOptions {
            method: Method::Collocation { stages },
            strategy: Strategy::Direct,
            collocation: CollocationOptions {
                intervals: 4,
                adapt: false,
                ..Default::default()
            },
            ..Default::default()
        };
        match solve(&rod, &choice, &fixed) {
            Err(SolveError::Collocation {
                failure:
                    CollocationError::CoarseMesh {
                        estimate,
                        tolerance,
                        intervals,
                    },
                ..
            }) => {
                eprintln!("m = {stages}: estimate {estimate:.2e} on {intervals} intervals");
                assert!(estimate > tolerance && intervals == 4);
            }
            other => panic!("m = {stages}: expected CoarseMesh, got {other:?}"),
        }
        let adaptive = SolverOptions {
            collocation: CollocationOptions {
                adapt: true,
                ..fixed.collocation
            },
            ..fixed
        };
        let eq = solve(&rod, &choice, &adaptive).unwrap();
        let err = cantilever_error(&eq, 1.0, 10.0);
        eprintln!("m = {stages}: adapted, tip error {err:.2e}");
        assert!(err <= 1e-9, "m = {stages}: {err:e}");
    }
}

/// A tolerance no mesh within the budget meets is an error with the
/// estimate, not a result.
#[test]
fn interval_budget_too_small_is_an_error() {
    let rod = spiral(40.0, 0.0);
    let opts = SolverOptions {
        method: Method::Collocation { stages: 2 },
        collocation: CollocationOptions {
            max_intervals: 32,
            ..Default::default()
        },
        ..Default::default()
    };
    let choice = ModelChoice::forced(&rod, ModelLevel::Planar).unwrap();
    let message = assert_clear_failure(solve(&rod, &choice, &opts), "collocation");
    assert!(message.contains("within 32 intervals"), "{message}");
}

/// Continuation where single shooting fails: a long cantilever (L = 16,
/// so k = F L²/B reaches 256 at F = 1) followed in its load. Single
/// shooting cannot carry the branch to the end and says why (a stalled
/// step or a failing start), never returning points off the branch; on 16
/// segments of multiple shooting the same continuation reaches F = 1 with
/// every point on the Bisshopp–Drucker elastica.
#[test]
fn continuation_recovers_on_multiple_shooting_for_a_long_rod() {
    use cosserat::continuation::continuation;
    use cosserat::input::Problem;
    let text = |method: &str| {
        format!(
            "[rod]\nlength = 16.0\n[energy]\nstiffness = [10.0, 1.0, 10.0]\n\
             [loads]\ntip_force = [1.0, 0.0, 0.0]\n[solver]\nmethod = \"{method}\"\n\
             segments = 16\n[continuation]\nparameter = \"load_scale\"\nstart = 0.001\n\
             bounds = [0.0, 1.0]\nstep = 0.01\nmax_step = 0.05\nelements = 32\n\
             eigenvalues = 1\nswitch_depth = 0\n"
        )
    };
    let single = Problem::from_str_with(&text("shooting"), &[]).unwrap();
    let (family, opts) = single.continuation.clone().unwrap();
    match continuation(&family, &opts, &mut |_, _| true) {
        Err(e) => assert!(!e.to_string().is_empty()),
        Ok(d) => {
            let b = &d.branches[0];
            let last = b.points.last().unwrap().parameter;
            assert!(last < 1.0, "single shooting reached the end: {last}");
            assert!(
                !b.stop_reason.to_string().contains("bound"),
                "{}",
                b.stop_reason
            );
        }
    }
    let multiple = Problem::from_str_with(&text("multiple-shooting"), &[]).unwrap();
    let (family, opts) = multiple.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let b = &d.branches[0];
    assert!((b.points.last().unwrap().parameter - 1.0).abs() < 1e-12);
    for p in &b.points {
        let k = p.parameter * 256.0;
        let exact = CantileverTip::at(k);
        let tip = p.tip.position / 16.0;
        assert!(
            (tip[0] - exact.x).abs() < 1e-7 && (tip[2] - exact.z).abs() < 1e-7,
            "k = {k}: {tip:?} vs ({}, {})",
            exact.x,
            exact.z
        );
    }
}
