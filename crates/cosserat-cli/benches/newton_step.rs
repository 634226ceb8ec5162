//! Collocation's cost per Newton step against the number of intervals N
//! (10² to 10⁵, uniform meshes, no adaptation), with the fitted log-log
//! slope (O(N) solve: slope ≈ 1), and the time per equilibrium at tip
//! error ≤ 1e-8 on the planar cantilever k = 3 for every method.
//!
//! Run: `cargo bench --bench newton_step`. A "step" here is the whole
//! collocation solve on a fixed mesh divided by its Newton steps: each
//! step's linearization, condensation and banded solve, plus its share of
//! the residuals of the line search and of the O(N) error estimate. The
//! warm-started solve is already converged, so it takes 0 steps and is
//! counted as one: the figure is then the whole solve (one polishing
//! linearization, residuals, error estimate).

use std::time::Instant;

use cosserat::bvp::newton::NewtonOptions;
use cosserat::bvp::{
    equations, solve, solve_collocation, CollocationOptions, Discretization, Method, SolverOptions,
};
use cosserat::model::{ModelChoice, ModelLevel};
use cosserat_cli::bench::{scenes, Scene};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let scene = &scenes()[0];
    let choice = ModelChoice::forced(&scene.rod, ModelLevel::Planar).unwrap();
    time_per_equilibrium(scene, &choice);
    println!();
    time_per_newton_step(scene);
}

/// Every method's time per equilibrium at its loosest setting that
/// reaches tip error 1e-8.
fn time_per_equilibrium(scene: &Scene, choice: &ModelChoice) {
    println!("time per equilibrium at tip error <= 1e-8, planar cantilever k = 3");
    let runs: Vec<(&str, SolverOptions)> = vec![
        ("shooting", Method::Shooting),
        (
            "multiple shooting (8)",
            Method::MultipleShooting { segments: 8 },
        ),
        ("collocation order 4", Method::Collocation { stages: 2 }),
        ("collocation order 6", Method::Collocation { stages: 3 }),
    ]
    .into_iter()
    .map(|(name, method)| {
        (
            name,
            SolverOptions {
                method,
                output_points: 2,
                ..Default::default()
            },
        )
    })
    .collect();
    for (name, base) in runs {
        // The loosest setting of the sweep that reaches 1e-8.
        let candidates: Vec<SolverOptions> = match base.method {
            Method::Collocation { .. } => (0..12)
                .map(|e| SolverOptions {
                    collocation: CollocationOptions {
                        tolerance: 10f64.powi(-e),
                        intervals: 4,
                        ..Default::default()
                    },
                    ..base.clone()
                })
                .collect(),
            _ => (3..13)
                .map(|e| {
                    let mut o = base.clone();
                    o.integration.rtol = 10f64.powi(-e);
                    o.integration.atol = 10f64.powi(-e);
                    o
                })
                .collect(),
        };
        for opts in candidates {
            let Ok(eq) = solve(&scene.rod, choice, &opts) else {
                continue;
            };
            let err = (eq.tip().position - scene.tip).amax();
            if err > 1e-8 {
                continue;
            }
            let times: Vec<f64> = (0..51)
                .map(|_| {
                    let t = Instant::now();
                    let _ = solve(&scene.rod, choice, &opts);
                    t.elapsed().as_secs_f64()
                })
                .collect();
            let mesh = match &eq.discretization {
                Discretization::Collocation(s) => format!("{} intervals", s.intervals()),
                Discretization::Shooting => format!("rtol {:.0e}", opts.integration.rtol),
            };
            println!(
                "{name:<22} {:>9.1} µs  tip error {err:.1e}  ({mesh})",
                median(times) * 1e6
            );
            break;
        }
    }
}

/// Collocation's time per Newton step against N, with the fitted log-log
/// slope.
fn time_per_newton_step(scene: &Scene) {
    println!("collocation time per Newton step against N (planar cantilever k = 3, warm start)");
    for stages in [2, 3] {
        let eq = equations(&scene.rod, ModelLevel::Planar);
        let (mut xs, mut ys) = (vec![], vec![]);
        for n in [100usize, 316, 1000, 3162, 10000, 31623, 100000] {
            let opts = CollocationOptions {
                stages,
                intervals: n,
                adapt: false,
                tolerance: f64::INFINITY,
                max_intervals: n,
            };
            let newton = NewtonOptions::default();
            // Warm start from the converged solution: a few steps on the mesh.
            let warm = solve_collocation(eq.as_ref(), &opts, &newton, None).unwrap();
            let reps = (2_000_000 / n).clamp(3, 25);
            let (mut per_step, mut steps) = (vec![], 0);
            for _ in 0..reps {
                let t = Instant::now();
                let sol = solve_collocation(eq.as_ref(), &opts, &newton, Some(&warm)).unwrap();
                per_step.push(t.elapsed().as_secs_f64() / sol.newton_steps.max(1) as f64);
                steps = sol.newton_steps;
            }
            let t = median(per_step);
            println!(
                "m = {stages}  N = {n:>6}  {:>10.1} µs per step  {:>6.2} µs per interval  ({steps} Newton steps)",
                t * 1e6,
                t * 1e6 / n as f64
            );
            xs.push((n as f64).ln());
            ys.push(t.ln());
        }
        let (mx, my) = (
            xs.iter().sum::<f64>() / xs.len() as f64,
            ys.iter().sum::<f64>() / ys.len() as f64,
        );
        let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
        println!("m = {stages}  fitted log-log slope {:.3}", sxy / sxx);
    }
}
