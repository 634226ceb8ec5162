//! Time per equilibrium and tip error against the closed form, for each
//! model level and method, on the planar cantilever (k = 0.5, 3, 10).
//!
//! Run: `cargo bench --bench solve` (median of repeated solves in one
//! process; integrator tolerance swept from 1e-8 to 1e-12). "RHS" counts
//! the right-hand side evaluations of one solve (ramp, Newton, sampling):
//! the cost that does not depend on the machine's load.

#[path = "../tests/support/mod.rs"]
mod support;

use std::time::Instant;

use cosserat::bvp::integrator::Tolerances;
use cosserat::bvp::{solve, Method, SolverOptions};
use cosserat::model::{ModelChoice, ModelLevel};
use support::rods::cantilever;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn main() {
    println!(
        "{:>5} {:>10} {:>18} {:>8} {:>10} {:>12} {:>6} {:>8}",
        "k", "model", "method", "rtol", "tip error", "time [µs]", "ramp", "RHS"
    );
    for k in [0.5, 3.0, 10.0] {
        let reference = cosserat::references::CantileverTip::at(k);
        let rod = cantilever(k);
        for level in [ModelLevel::Planar, ModelLevel::Kirchhoff] {
            let choice = ModelChoice::forced(&rod, level).unwrap();
            for method in [Method::Shooting, Method::MultipleShooting { segments: 8 }] {
                for rtol in [1e-8, 1e-10, 1e-12] {
                    let opts = SolverOptions {
                        method,
                        integration: Tolerances {
                            rtol,
                            atol: rtol,
                            ..Default::default()
                        },
                        output_points: 2,
                        ..Default::default()
                    };
                    let mut times = vec![];
                    let mut last = None;
                    for _ in 0..21 {
                        let t = Instant::now();
                        let eq = solve(&rod, &choice, &opts).expect("converges");
                        times.push(t.elapsed().as_secs_f64());
                        last = Some(eq);
                    }
                    let eq = last.unwrap();
                    let tip = eq.tip().position;
                    let err = (tip[0] - reference.x)
                        .abs()
                        .max((tip[2] - reference.z).abs());
                    println!(
                        "{:>5} {:>10} {:>18} {:>8.0e} {:>10.1e} {:>12.1} {:>6} {:>8}",
                        k,
                        level.name(),
                        method.name(),
                        rtol,
                        err,
                        median(times) * 1e6,
                        eq.load_steps,
                        eq.integration.evaluations
                    );
                }
            }
        }
    }
}
