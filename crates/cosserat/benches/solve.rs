//! Time per equilibrium and tip error against the closed form, for each
//! model level and method, on the planar cantilever (k = 0.5, 3, 10).
//!
//! Run: `cargo bench --bench solve` (median of repeated solves in one
//! process; integrator tolerance swept from 1e-8 to 1e-12).

#[path = "../tests/support/mod.rs"]
mod support;

use std::sync::Arc;
use std::time::Instant;

use cosserat::bvp::integrator::Tolerances;
use cosserat::bvp::{solve, Method, SolverOptions};
use cosserat::model::{Clamp, DeadLoads, LinearElastic, ModelChoice, ModelLevel, Rod};
use nalgebra::Vector3;

fn cantilever(k: f64) -> Rod {
    Rod::new(
        1.0,
        Arc::new(LinearElastic::uniform([10.0, 1.0, 10.0], [0.0; 3]).unwrap()),
        Clamp::paper(),
        DeadLoads {
            tip_force: Vector3::new(k, 0.0, 0.0),
            ..Default::default()
        },
        None,
    )
    .unwrap()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn main() {
    println!(
        "{:>5} {:>10} {:>18} {:>8} {:>10} {:>12} {:>6}",
        "k", "model", "method", "rtol", "tip error", "time [µs]", "ramp"
    );
    for k in [0.5, 3.0, 10.0] {
        let reference = support::references::cantilever_tip(k);
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
                        "{:>5} {:>10} {:>18} {:>8.0e} {:>10.1e} {:>12.1} {:>6}",
                        k,
                        level.name(),
                        method.name(),
                        rtol,
                        err,
                        median(times) * 1e6,
                        eq.load_steps
                    );
                }
            }
        }
    }
}
