//! The cost of one continuation step on the collocation discretization
//! against the number of intervals K (issue 16: O(N) steps): the
//! lateral-torsional cantilever (problems/lateral_torsional_buckling.toml,
//! Gauss collocation of order 6) continued from load 0.05 below its first
//! branch point (bounds [0, 0.44], no special point, so only ordinary
//! steps are timed), K = 32, 64, …, 4096. A step is the time between two
//! points the monitor hears (predictor, corrector, tangent, eigenvalue
//! tracking, event tests); its median over the points of a run is fitted
//! on a log–log scale by least squares. The peak resident memory after
//! each run shows the memory linear in K (the dense bordered matrix of
//! 4096 intervals alone would take 8·49 161² bytes = 19 GB).
//!
//! Run: `cargo bench -p cosserat --bench collocation_scaling` (one core).

use std::time::Instant;

use cosserat::continuation::continuation;
use cosserat::input::Problem;

const LTB: &str = include_str!("../../../problems/lateral_torsional_buckling.toml");

/// The median step time (s), the number of points and the family's
/// unknowns on K intervals.
fn step_time(intervals: usize) -> (f64, usize, usize) {
    let set = [
        "solver.method=\"collocation\"".to_string(),
        format!("continuation.intervals={intervals}"),
        "continuation.bounds=[0.0, 0.44]".to_string(),
        "continuation.switch_depth=0".to_string(),
        "continuation.max_points=10".to_string(),
    ];
    let p = Problem::from_str_with(LTB, &set).unwrap();
    let (family, opts) = p.continuation.clone().unwrap();
    let mut stamps = vec![];
    let d = continuation(&family, &opts, &mut |_, _| {
        stamps.push(Instant::now());
        true
    })
    .unwrap();
    assert!(d.special_points.is_empty(), "only ordinary steps are timed");
    let mut steps: Vec<f64> = stamps
        .windows(2)
        .map(|w| (w[1] - w[0]).as_secs_f64())
        .collect();
    steps.sort_by(f64::total_cmp);
    (steps[steps.len() / 2], stamps.len(), family.size())
}

/// The peak resident set of this process (kB), from /proc (Linux).
fn peak_memory_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn main() {
    // The input reader's budget still counts a dense system for the
    // events' determinant at special points, which this run never meets.
    std::env::set_var("COSSERAT_MEMORY_BUDGET", "1T");
    let mut fit = vec![];
    println!(
        "{:>8} {:>8} {:>7} {:>12} {:>12}",
        "K", "N", "points", "step (ms)", "peak (MB)"
    );
    let mut k = 32;
    while k <= 4096 {
        let (t, points, n) = step_time(k);
        let peak = peak_memory_kb().map_or(f64::NAN, |kb| kb as f64 / 1024.0);
        println!("{k:>8} {n:>8} {points:>7} {:>12.3} {peak:>12.1}", t * 1e3);
        fit.push(((k as f64).ln(), t.ln()));
        k *= 2;
    }
    let m = fit.len() as f64;
    let (sx, sy) = fit.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / m, sy / m);
    let (sxy, sxx) = fit.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    println!("log–log slope of the step time against K: {:.3}", sxy / sxx);
}
