//! Collocation on a fixed uniform mesh of N intervals: the time per Newton
//! step (a warm re-solve divided by its steps, median of 5) and the
//! process's peak resident memory (VmHWM of /proc/self/status), so that
//! memory per interval is the difference of two runs over the difference
//! of their N:
//!
//!     cargo run --release -p cosserat --example collocation_scaling -- \
//!         problems/cantilever_tip_load.toml 3 100000
//!
//! (arguments: the problem, the Gauss points per interval, N). One N per
//! process, since the peak of a process never goes down.

use std::path::Path;
use std::time::Instant;

use cosserat::bvp::newton::NewtonOptions;
use cosserat::bvp::{equations, solve_collocation, CollocationOptions};
use cosserat::input::Problem;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let problem = Problem::from_path(Path::new(&args[0]), &[]).expect("a problem file");
    let stages: usize = args[1].parse().expect("stages");
    let n: usize = args[2].parse().expect("N");
    let eq = equations(&problem.rod, problem.model.level);
    let opts = CollocationOptions {
        stages,
        intervals: n,
        adapt: false,
        tolerance: f64::INFINITY,
        max_intervals: n,
    };
    let newton = NewtonOptions::default();
    let cold = Instant::now();
    let sol = solve_collocation(eq.as_ref(), &opts, &newton, None).expect("a solution");
    let cold = cold.elapsed().as_secs_f64();
    let steps = sol.newton_steps;
    // A start one Newton step away: the converged solution's warm re-solve
    // takes 0 steps, so time the cold solve's steps instead, best of 3.
    let mut per_step = (0..3)
        .map(|_| {
            let t = Instant::now();
            let s = solve_collocation(eq.as_ref(), &opts, &newton, None).expect("a solution");
            t.elapsed().as_secs_f64() / s.newton_steps.max(1) as f64
        })
        .collect::<Vec<_>>();
    per_step.sort_by(f64::total_cmp);
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let hwm_kb: f64 = status
        .lines()
        .find(|l| l.starts_with("VmHWM"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        .unwrap_or(f64::NAN);
    println!(
        "m {stages} N {n} steps {steps} cold_s {cold:.4} step_us {:.1} step_us_per_interval {:.3} peak_kib {hwm_kb:.0} tip {:?}",
        per_step[0] * 1e6,
        per_step[0] * 1e6 / n as f64,
        sol.states[n].iter().take(3).collect::<Vec<_>>()
    );
}
