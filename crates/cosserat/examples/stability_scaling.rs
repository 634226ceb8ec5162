//! Wall time of one stability analysis against the number of elements,
//! split into sampling the equilibrium at the quadrature points and the
//! eigen solve (assembly, Lanczos and the Sturm count), minimum of 3 runs,
//! and the eigen solve's CPU time (the thread's time on a core, from
//! /proc/thread-self/schedstat: steadier than wall time on a machine
//! shared with other jobs; NaN where that file does not exist):
//!
//!     cargo run --release -p cosserat --example stability_scaling -- \
//!         problems/cantilever_tip_load.toml 100 1000 10000 100000
//!
//! A problem with a `[shape]` table times the fixed shape's critical load
//! (sampling and eigen solve together) and prints γ_cr.

use std::path::Path;
use std::time::Instant;

use cosserat::bvp::solve;
use cosserat::input::Problem;
use cosserat::model::ModelLevel;
use cosserat::stability::{
    block_spectrum, coefficients, critical_load, support_constraints, Block, FiniteElements,
    FixedShape,
};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let problem = Problem::from_path(Path::new(&args[0]), &[]).expect("a problem file");
    let meshes: Vec<usize> = args[1..].iter().map(|a| a.parse().expect("N")).collect();
    println!("elements  sampling_s  eigen_s  total_s  eigen_cpu_s  lowest");
    for n in meshes {
        let best = (0..3)
            .map(|_| {
                if let Some(shape) = &problem.shape {
                    fixed_shape_run(&problem, shape, n)
                } else {
                    equilibrium_run(&problem, n)
                }
            })
            .reduce(|a, b| {
                let cpu = a.3.min(b.3);
                let mut best = if a.0 + a.1 <= b.0 + b.1 { a } else { b };
                best.3 = cpu;
                best
            })
            .expect("three runs");
        println!(
            "{n:>8}  {:>10.4}  {:>7.4}  {:>7.4}  {:>11.4}  {:.12e}",
            best.0,
            best.1,
            best.0 + best.1,
            best.3,
            best.2
        );
    }
}

/// This thread's CPU time (s): the first field of
/// /proc/thread-self/schedstat, nanoseconds on a core.
fn cpu_time() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// The fixed shape's critical load on `n` elements: (0, its time, γ_cr,
/// its CPU time) — its sampling is a quadrature of the shape, timed with
/// the solve.
fn fixed_shape_run(problem: &Problem, shape: &FixedShape, n: usize) -> (f64, f64, f64, f64) {
    let opts = problem.stability.with_elements(n).expect("elements");
    let (t, cpu) = (Instant::now(), cpu_time());
    let c = critical_load(&problem.rod, shape, &opts).expect("critical load");
    (
        0.0,
        t.elapsed().as_secs_f64(),
        c.gamma.unwrap_or(f64::NAN),
        cpu_time() - cpu,
    )
}

/// One analysis of the problem's equilibrium on `n` elements: (sampling
/// time, eigen-solve time, lowest eigenvalue over the blocks, eigen-solve
/// CPU time).
fn equilibrium_run(problem: &Problem, n: usize) -> (f64, f64, f64, f64) {
    let opts = problem.stability.with_elements(n).expect("elements");
    let eq = solve(&problem.rod, &problem.model, &problem.options).expect("solve");
    let fe = FiniteElements::new(problem.rod.length(), n, opts.order())
        .with_hinged_base(problem.rod.clamp().hinge);
    let t = Instant::now();
    let mut points = fe.quadrature_points();
    points.push(problem.rod.length());
    let mut samples = eq
        .resample(&problem.rod, &problem.options, &points)
        .expect("samples");
    let tip = samples.pop().expect("tip");
    let sampled = t.elapsed().as_secs_f64();
    let (t, cpu) = (Instant::now(), cpu_time());
    let coeffs = coefficients(&problem.rod, &samples);
    let blocks = match eq.model.level {
        ModelLevel::Planar => vec![Block::InPlane, Block::OutOfPlane],
        _ => vec![Block::Full],
    };
    let lowest = blocks
        .into_iter()
        .map(|b| {
            let c = support_constraints(&problem.rod, &fe, b, &samples, &tip).expect("constraints");
            block_spectrum(&fe, &coeffs, b, opts.eigenvalues(), &c)
                .expect("spectrum")
                .eigenvalues[0]
        })
        .fold(f64::INFINITY, f64::min);
    (sampled, t.elapsed().as_secs_f64(), lowest, cpu_time() - cpu)
}
