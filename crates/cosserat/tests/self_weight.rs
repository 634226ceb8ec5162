//! A cantilever under its own weight (a uniform distributed dead load q):
//! the small-deflection closed form of beam theory, and at large deflection
//! a mesh-convergence study of fixed-mesh collocation whose measured order
//! is the method's, with every method agreeing on the converged tip.
mod support;
use support::methods::methods;

use cosserat::bvp::{solve, CollocationOptions, Equilibrium, Method, SolverOptions};
use cosserat::model::{DeadLoads, ModelChoice, Rod};
use nalgebra::Vector3;

/// L = 1, B2 = 1, clamp tangent e3, weight q per length along e1.
fn hanging(q: f64) -> Rod {
    let loads = DeadLoads {
        distributed_force: Vector3::new(q, 0.0, 0.0),
        ..Default::default()
    };
    support::rods::uniform(1.0, [10.0, 1.0, 10.0], loads)
}

fn solve_with(rod: &Rod, opts: &SolverOptions) -> Equilibrium {
    solve(rod, &ModelChoice::for_rod(rod), opts).unwrap()
}

/// Euler–Bernoulli: tip deflection q L⁴/(8B), tip rotation q L³/(6B),
/// up to relative O(q²).
#[test]
fn small_deflection_matches_beam_theory() {
    let q = 1e-4;
    let rod = hanging(q);
    for method in methods(4) {
        let opts = SolverOptions {
            method,
            ..Default::default()
        };
        let tip = solve_with(&rod, &opts).tip().clone();
        let deflection = tip.position[0];
        let rotation = tip.directors[2][0].atan2(tip.directors[2][2]);
        assert!(
            (deflection / (q / 8.0) - 1.0).abs() < 1e-6,
            "{method:?}: {deflection}"
        );
        assert!(
            (rotation / (q / 6.0) - 1.0).abs() < 1e-6,
            "{method:?}: {rotation}"
        );
    }
}

/// q L³/B = 10: fixed meshes of 4-th order collocation converge at a
/// measured order of 4, and shooting, multiple shooting and adaptive
/// collocation of order 6 agree with the finest mesh.
#[test]
fn large_deflection_converges_at_the_method_order() {
    let rod = hanging(10.0);
    let tip_x = |n: usize| {
        let opts = SolverOptions {
            method: Method::Collocation { stages: 2 },
            collocation: CollocationOptions {
                stages: 2,
                intervals: n,
                adapt: false,
                tolerance: 1.0,
                ..Default::default()
            },
            ..Default::default()
        };
        solve_with(&rod, &opts).tip().position[0]
    };
    let meshes = [4, 8, 16, 32, 64];
    let x: Vec<f64> = meshes.iter().map(|&n| tip_x(n)).collect();
    let diffs: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    for d in diffs.windows(2).skip(1) {
        let order = (d[0] / d[1]).log2();
        assert!((order - 4.0).abs() < 0.15, "order {order}: {x:?}");
    }
    let converged = x[4];
    for method in methods(8) {
        let opts = SolverOptions {
            method,
            ..Default::default()
        };
        let other = solve_with(&rod, &opts).tip().position[0];
        assert!(
            (other - converged).abs() < 1e-8,
            "{method:?}: {other} vs {converged}"
        );
    }
    // Large indeed: the tip has swung well past a third of the length.
    assert!(converged > 0.5, "{converged}");
}
