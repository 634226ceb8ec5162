//! Speed of the stability analysis.
//!
//! Run: `cargo bench -p cosserat --bench stability`. Times what "the
//! lowest 4 eigenvalues of each block on N elements" costs from a solved
//! equilibrium: [`analyze`] of `problems/cantilever_tip_load.toml` (order
//! 2, both blocks of the planar rod) on one mesh of N = 10², 10³, 10⁴, 10⁵
//! elements — sampling the equilibrium at the quadrature points, the
//! coefficients, K and G, the shift (from a mesh 64 times coarser where N
//! ≥ 2048), shift-invert Lanczos, the factored Rayleigh quotients and the
//! Morse index. Per mesh: the median and minimum wall time and the
//! minimum CPU time of this thread (from /proc/thread-self/schedstat,
//! steadier than wall time on a shared machine; NaN where that file does
//! not exist) per analysis, over 5 batches of runs of at least 0.2 s of
//! CPU each; then the log–log slope of the CPU time against N fitted over
//! the four meshes and between neighbours. Last, the time of a
//! fixed-shape critical load (the generalized eigenproblem K0 + λK1) at
//! 100 elements.

#[path = "../tests/support/mod.rs"]
mod support;

use std::path::Path;
use std::time::Instant;

use cosserat::bvp::solve;
use cosserat::input::Problem;
use cosserat::model::Profile;
use cosserat::stability::{analyze, critical_load, FixedShape, StabilityOptions};
use support::rods::{tip_force, uniform};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time(repeats: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..repeats)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

/// This thread's CPU time (s): the first field of
/// /proc/thread-self/schedstat, nanoseconds on a core.
fn cpu_time() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// The least-squares slope of y against x.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>()
}

fn main() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../problems/cantilever_tip_load.toml");
    let problem = Problem::from_path(&path, &[]).expect("the shipped cantilever");
    let eq = solve(&problem.rod, &problem.model, &problem.options).expect("its equilibrium");
    println!("analyze: the lowest 4 eigenvalues of both blocks, problems/cantilever_tip_load.toml (order 2)");
    println!(
        "{:>8} {:>10} {:>10} {:>10} {:>6}  {:>18} {:>18}",
        "elements", "wall med", "wall min", "cpu min", "runs", "in-plane λ1", "out-of-plane λ1"
    );
    let mut points = vec![];
    for elements in [100, 1_000, 10_000, 100_000] {
        let opts = problem.stability.with_elements(elements).expect("elements");
        let run = || analyze(&problem.rod, &eq, &problem.options, &opts).expect("analyzed");
        let first = run();
        let (t, c) = (Instant::now(), cpu_time());
        run();
        let once = (cpu_time() - c)
            .max(t.elapsed().as_secs_f64() * 0.5)
            .max(1e-6);
        let runs = ((0.2 / once).ceil() as usize).max(1);
        let (mut walls, mut cpu) = (Vec::new(), f64::INFINITY);
        for _ in 0..5 {
            let c = cpu_time();
            for _ in 0..runs {
                let t = Instant::now();
                std::hint::black_box(run());
                walls.push(t.elapsed().as_secs_f64());
            }
            cpu = cpu.min((cpu_time() - c) / runs as f64);
        }
        let lowest = |b: usize| first.blocks[b].eigenvalues[0];
        println!(
            "{:>8} {:>8.3}ms {:>8.3}ms {:>8.3}ms {:>6}  {:>18.12} {:>18.12}",
            elements,
            median(walls.clone()) * 1e3,
            walls.iter().copied().fold(f64::INFINITY, f64::min) * 1e3,
            cpu * 1e3,
            5 * runs,
            lowest(0),
            lowest(1)
        );
        points.push(((elements as f64).ln(), cpu.ln()));
    }
    println!(
        "log-log slope of CPU time against elements: {:.3} (fit over 10²–10⁵); between neighbours {}",
        slope(&points),
        points
            .windows(2)
            .map(|w| format!("{:.3}", slope(w)))
            .collect::<Vec<_>>()
            .join(", ")
    );

    let straight = uniform(1.0, [1.0, 1.0, 1.0], tip_force(1.0, 0.0, 0.0));
    let shape = FixedShape {
        turning_angle: Profile::Constant(0.0),
    };
    for order in [1, 2] {
        let so = StabilityOptions::new(100, order, 1).unwrap();
        let t = time(51, || {
            std::hint::black_box(critical_load(&straight, &shape, &so).unwrap());
        });
        let gamma = critical_load(&straight, &shape, &so)
            .unwrap()
            .gamma
            .unwrap();
        println!(
            "fixed-shape critical load, 100 elements of order {order}: {:.3} ms (γ = {gamma:.10})",
            t * 1e3
        );
    }
}
