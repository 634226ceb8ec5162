//! The cost of a continuation step against the mesh (issue 16, items 4
//! and 9): the Euler column (problems/euler_column.toml) on Gauss
//! collocation in the Kirchhoff model — its branch point at π²/4 is
//! double, so the diagram runs the bordered test of multiplicity 2 and
//! switches along a two-dimensional kernel — from 32 to 4096 intervals.
//! For each mesh: the whole diagram (detect, locate, switch both ways on
//! both kernel directions, follow to p = 3) per point, one corrector step
//! alone (median of 5, from the diagram's last point of the first switched
//! branch) per evaluation of F, F_x, F_p (iterations + 1 of them), the
//! located branch point against π²/4, and the log–log slopes of both
//! costs. Every algebra is O(N): band LU of the staircase F_x for
//! the steps, det F_x from its pivots, the bordered test and the switching
//! kernel by inverse iteration on the band LU (`continuation/kernel.rs`).
//!
//! Times are the thread's CPU time (`/proc/thread-self/schedstat`, ns;
//! wall time where that file is missing), so a machine shared with other
//! builds compares meshes fairly.
//!
//! Run: `cargo run --release -p cosserat --example continuation_scaling
//! [MAX_INTERVALS]` (default 4096; minutes at 4096 on one core).

use std::path::Path;
use std::time::Instant;

use cosserat::continuation::engine::step;
use cosserat::continuation::{continuation, SpecialKind};
use cosserat::input::Problem;

/// Seconds of this thread's CPU time since `start` (wall time where the
/// scheduler's statistics are not readable).
struct Clock {
    wall: Instant,
    cpu: Option<u64>,
}

impl Clock {
    fn start() -> Self {
        Clock {
            wall: Instant::now(),
            cpu: cpu_ns(),
        }
    }

    fn seconds(&self) -> f64 {
        match (self.cpu, cpu_ns()) {
            (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
            _ => self.wall.elapsed().as_secs_f64(),
        }
    }
}

/// The thread's time on a CPU in ns (the first field of schedstat).
fn cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn main() {
    let max: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(4096);
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../problems/euler_column.toml"
    );
    let reference = std::f64::consts::PI.powi(2) / 4.0;
    println!(
        "{:>9} {:>7} {:>7} {:>12} {:>12} {:>12} {:>10}",
        "intervals", "N", "points", "diagram ms", "ms/point", "ms/eval", "|p − π²/4|"
    );
    let mut rows: Vec<(f64, f64, f64)> = vec![];
    let mut k = 32;
    while k <= max {
        let set = vec![
            "solver.method=\"collocation\"".to_string(),
            "solver.model=\"kirchhoff\"".to_string(),
            format!("continuation.intervals={k}"),
            "continuation.bounds=[0.0, 3.0]".to_string(),
            // The stored points' memory is linear in the mesh too, and
            // the default 400 per branch passes the 4 GiB budget at 4096.
            "continuation.max_points=100".to_string(),
        ];
        let problem = Problem::from_path(Path::new(path), &set).expect("the shipped problem");
        let (family, opts) = problem.continuation.clone().expect("[continuation]");
        let t = Clock::start();
        let d = continuation(&family, &opts, &mut |_, _| true).expect("a diagram");
        let diagram = t.seconds();
        let points: usize = d.branches.iter().map(|b| b.points.len()).sum();
        let bp = d
            .special_points
            .iter()
            .find(|s| s.kind == SpecialKind::BranchPoint)
            .map_or(f64::NAN, |s| s.point.parameter);
        let switched = d.branches.len() - 1;
        // One corrector step from the last point of the first switched
        // branch (or the loading branch), along its tangent.
        let branch = d.branches.get(1).unwrap_or(&d.branches[0]);
        let from = branch.points.last().expect("a point");
        let mut steps = vec![];
        let mut iterations = 0;
        for _ in 0..5 {
            let t = Clock::start();
            let stepped = step(
                &family,
                &from.unknowns,
                from.parameter,
                &from.tangent,
                -0.05,
                opts.tolerance,
            );
            steps.push(t.seconds());
            match stepped {
                Ok(Some((_, _, _, i))) => iterations = i,
                _ => panic!("the step converges"),
            }
        }
        steps.sort_by(f64::total_cmp);
        // A step of i corrector iterations evaluates F, F_x, F_p i + 1
        // times (the last at the converged point, for the tangent).
        let per_evaluation = steps[2] / (iterations + 1) as f64;
        let per_point = diagram / points as f64;
        println!(
            "{k:>9} {:>7} {points:>7} {:>12.1} {:>12.3} {:>12.3} {:>10.1e}   ({switched} switched branches, {iterations} corrector iterations a step)",
            family.size(),
            diagram * 1e3,
            per_point * 1e3,
            per_evaluation * 1e3,
            (bp - reference).abs()
        );
        rows.push((k as f64, per_point, per_evaluation));
        k *= 2;
    }
    if rows.len() >= 2 {
        let slope = |f: &dyn Fn(&(f64, f64, f64)) -> f64| {
            let n = rows.len() as f64;
            let (sx, sy) = rows
                .iter()
                .fold((0.0, 0.0), |(a, b), r| (a + r.0.ln(), b + f(r).ln()));
            let (mx, my) = (sx / n, sy / n);
            let (num, den) = rows.iter().fold((0.0, 0.0), |(a, b), r| {
                let dx = r.0.ln() - mx;
                (a + dx * (f(r).ln() - my), b + dx * dx)
            });
            num / den
        };
        println!(
            "log–log slope (least squares, {} meshes): per point {:.3}, per corrector evaluation {:.3}",
            rows.len(),
            slope(&|r| r.1),
            slope(&|r| r.2)
        );
    }
}
