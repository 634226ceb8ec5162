//! Gauss–Legendre collocation against the elastica cantilever (elliptic
//! integrals): convergence order on uniform meshes, adaptive accuracy on the
//! planar and spatial models, a load where single shooting fails, and a
//! tolerance that cannot be met being reported.
mod support;

use std::time::Instant;

use cosserat::bvp::newton::NewtonOptions;
use cosserat::bvp::{
    equations, solve_collocation, CollocationError, CollocationOptions, CollocationSolution,
};
use cosserat::equations::RodEquations;
use cosserat::input::Problem;
use cosserat::model::ModelLevel;
use cosserat::references::CantileverTip;
use nalgebra::Vector3;
use support::rods::cantilever;

/// Largest error of the tip position (x, z; y must vanish) against the
/// elliptic-integral reference.
fn tip_error(eq: &dyn RodEquations, sol: &CollocationSolution, k: f64) -> f64 {
    let reference = CantileverTip::at(k);
    let samples = sol.samples(eq);
    let tip = samples.last().unwrap().position;
    [
        (tip[0] - reference.x).abs(),
        (tip[2] - reference.z).abs(),
        tip[1].abs(),
    ]
    .into_iter()
    .fold(0.0, f64::max)
}

fn adaptive(tolerance: f64) -> CollocationOptions {
    CollocationOptions {
        stages: 3,
        intervals: 8,
        tolerance,
        max_intervals: 4096,
        adapt: true,
    }
}

/// Least-squares slope of log(error) against log(N).
fn log_log_slope(ns: &[usize], errors: &[f64]) -> f64 {
    let xs: Vec<f64> = ns.iter().map(|&n| (n as f64).ln()).collect();
    let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let (mx, my) = (
        xs.iter().sum::<f64>() / xs.len() as f64,
        ys.iter().sum::<f64>() / ys.len() as f64,
    );
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    sxy / sxx
}

#[test]
fn uniform_meshes_converge_with_order_two_m() {
    let k = 3.0;
    let eq = equations(&cantilever(k), ModelLevel::Planar);
    let ns = [4, 8, 16, 32];
    for stages in [2, 3] {
        let errors: Vec<f64> = ns
            .iter()
            .map(|&intervals| {
                let opts = CollocationOptions {
                    stages,
                    intervals,
                    adapt: false,
                    ..adaptive(1e-10)
                };
                let sol = solve_collocation(eq.as_ref(), &opts, &NewtonOptions::default(), None)
                    .unwrap_or_else(|e| panic!("m = {stages}, N = {intervals}: {e}"));
                tip_error(eq.as_ref(), &sol, k)
            })
            .collect();
        let slope = -log_log_slope(&ns, &errors);
        eprintln!("m = {stages}: errors {errors:?}, order {slope:.3}");
        assert!(
            (slope - 2.0 * stages as f64).abs() <= 0.3,
            "m = {stages}: errors {errors:?}, observed order {slope}"
        );
    }
}

#[test]
fn adaptive_collocation_matches_elliptic_integrals() {
    for level in [ModelLevel::Planar, ModelLevel::Kirchhoff] {
        for k in [0.5, 3.0, 10.0] {
            let eq = equations(&cantilever(k), level);
            let start = Instant::now();
            let sol = solve_collocation(
                eq.as_ref(),
                &adaptive(1e-10),
                &NewtonOptions::default(),
                None,
            )
            .unwrap_or_else(|e| panic!("{level:?} k = {k}: {e}"));
            let err = tip_error(eq.as_ref(), &sol, k);
            eprintln!(
                "{level:?} k = {k}: N = {}, tip error {err:.2e}, estimate {:.2e}, drift {:.2e}, \
                 {} Newton steps, residual {:.1e}, {:.1} ms",
                sol.mesh.len() - 1,
                sol.error_estimate,
                sol.director_drift,
                sol.iterations,
                sol.residual,
                start.elapsed().as_secs_f64() * 1e3
            );
            assert!(err <= 1e-9, "{level:?} k = {k}: tip error {err:e}");
            assert!(sol.error_estimate <= 1e-10);
            if level == ModelLevel::Kirchhoff {
                assert!(
                    sol.director_drift <= 1e-12,
                    "k = {k}: drift {:e}",
                    sol.director_drift
                );
            }
        }
    }
}

/// k = 100, where single shooting fails. A cold start from the straight rod
/// fails here too (the damped Newton stalls at a scaled residual ≈ 13 on the
/// starting 8-interval mesh), so k is stepped up from 10, each solve warm
/// started from the last (its adapted mesh and polynomial interpolated).
#[test]
fn large_load_where_single_shooting_fails() {
    let start = Instant::now();
    let mut previous: Option<CollocationSolution> = None;
    for k in [10.0, 20.0, 40.0, 70.0, 100.0] {
        let eq = equations(&cantilever(k), ModelLevel::Planar);
        let sol = solve_collocation(
            eq.as_ref(),
            &adaptive(1e-10),
            &NewtonOptions::default(),
            previous.as_ref(),
        )
        .unwrap_or_else(|e| panic!("k = {k}: {e}"));
        let err = tip_error(eq.as_ref(), &sol, k);
        eprintln!(
            "k = {k}: N = {}, tip error {err:.2e}, {} Newton steps, {:.1} ms so far",
            sol.mesh.len() - 1,
            sol.iterations,
            start.elapsed().as_secs_f64() * 1e3
        );
        if k == 100.0 {
            assert!(err <= 1e-8, "tip error {err:e}");
        }
        previous = Some(sol);
    }
}

#[test]
fn unreachable_tolerance_is_reported() {
    let k = 3.0;
    let eq = equations(&cantilever(k), ModelLevel::Planar);
    let opts = CollocationOptions {
        stages: 2,
        intervals: 4,
        tolerance: 1e-12,
        max_intervals: 16,
        adapt: true,
    };
    let err = solve_collocation(eq.as_ref(), &opts, &NewtonOptions::default(), None).unwrap_err();
    eprintln!("{err}");
    match err {
        CollocationError::ToleranceNotReached {
            estimate,
            tolerance,
            intervals,
            ..
        } => {
            assert!(
                estimate > tolerance && intervals <= 16,
                "{estimate} {intervals}"
            );
        }
        other => panic!("expected ToleranceNotReached, got {other}"),
    }
}

/// Director drift on a genuinely spatial scene (tip force out of the clamp
/// plane and a tip couple). With d3 = d1 × d2 computed, not stored,
/// orthonormality is not a quadratic first integral of y' = f(y): only
/// |d1|² + |d2|² is (its derivative vanishes identically), and Gauss
/// collocation keeps that one to round-off; d1·d2 and |d1|² − |d2|² drift
/// by discretization error, which falls with the tolerance.
#[test]
fn spatial_director_drift_is_discretization_error() {
    let rod = cantilever(5.0);
    let mut loads = rod.loads().clone();
    loads.tip_force = Vector3::new(5.0, 3.0, 0.0);
    loads.tip_couple = Vector3::new(0.0, 0.0, 2.0);
    let rod = rod.with_loads(loads).unwrap();
    let eq = equations(&rod, ModelLevel::Kirchhoff);
    let mut drifts = Vec::new();
    for tol in [1e-6, 1e-8, 1e-10] {
        let sol = solve_collocation(eq.as_ref(), &adaptive(tol), &NewtonOptions::default(), None)
            .unwrap_or_else(|e| panic!("tol {tol:e}: {e}"));
        let invariant = sol
            .states
            .iter()
            .map(|y| (y[..6].iter().map(|v| v * v).sum::<f64>() - 2.0).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "tol {tol:e}: N = {}, estimate {:.2e}, drift {:.2e}, | |d1|²+|d2|² − 2 | {invariant:.1e}",
            sol.mesh.len() - 1,
            sol.error_estimate,
            sol.director_drift
        );
        assert!(invariant <= 1e-13, "tol {tol:e}: {invariant:e}");
        assert!(sol.director_drift <= sol.error_estimate, "tol {tol:e}");
        drifts.push(sol.director_drift);
    }
    assert!(drifts[2] < 1e-3 * drifts[0], "{drifts:?}");
}

/// The components each model declares as found by quadrature (the
/// position, `RodEquations::quadrature_components`, which collocation's
/// stage matrices leave out) never enter the right-hand side: f is the same
/// bit for bit at a state moved by a large translation, and ∂f/∂y has zero
/// columns there — planar, Kirchhoff and Cosserat, free and held tips
/// (reaction states), at states off the straight rod.
#[test]
fn quadrature_components_never_enter_the_rates() {
    let files = [
        "cantilever_tip_load.toml",
        "clamped_elastica_displacement.toml",
        "helix_tip_load.toml",
        "twisted_rod.toml",
        "bathe_bolourchi_45.toml",
        "extensible_column_displacement.toml",
    ];
    for file in files {
        let path = format!("{}/../../problems/{file}", env!("CARGO_MANIFEST_DIR"));
        let problem = Problem::from_path(std::path::Path::new(&path), &[]).unwrap();
        let eq = equations(&problem.rod, problem.model.level);
        let (n, range) = (eq.dim(), eq.quadrature_components());
        assert!(!range.is_empty() && range.end <= n, "{file}: {range:?}");
        let mut u = eq.initial_guess();
        u.iter_mut()
            .enumerate()
            .for_each(|(i, v)| *v += 0.3 + 0.1 * i as f64);
        let mut y = vec![0.0; n];
        eq.initial_state(&u, &mut y);
        let mut moved = y.clone();
        for k in range.clone() {
            moved[k] += 123.25 * (k as f64 + 1.0);
        }
        let s = 0.37 * eq.length();
        let (mut f, mut g) = (vec![0.0; n], vec![0.0; n]);
        eq.rhs(s, &y, &mut f);
        eq.rhs(s, &moved, &mut g);
        assert!(f.iter().all(|v| v.is_finite()), "{file}: {f:?}");
        assert_eq!(f, g, "{file}: f moved with the position");
        let ident = nalgebra::DMatrix::<f64>::identity(n, n);
        let mut jac = vec![0.0; n * n];
        eq.rhs_linearized(s, &moved, n, ident.as_slice(), &mut f, &mut jac);
        for k in range {
            let column = &jac[k * n..(k + 1) * n];
            assert!(
                column.iter().all(|&v| v == 0.0),
                "{file}: ∂f/∂y{k} = {column:?}"
            );
        }
    }
}
