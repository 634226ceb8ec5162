//! Bifurcation diagrams against the AUTO-07p anchor of issue 5: the Euler
//! column (detect the branch point, switch, follow the buckled branch to a
//! tip angle of 170°) and the lateral-torsional cantilever (detect and
//! switch), from the shipped problem files.
//!
//! Run: `cargo bench --bench continuation` (median of 7 runs in one
//! process, one core).

use std::path::Path;
use std::time::Instant;

use cosserat::continuation::continuation;
use cosserat::input::Problem;

fn main() {
    for (name, overrides) in [
        ("euler_column", vec![]),
        (
            "lateral_torsional_buckling",
            // Detect and switch: stop the new branches after a few points.
            vec!["continuation.bounds=[0.0, 0.6]".to_string()],
        ),
    ] {
        let path = format!(
            "{}/problems/{name}.toml",
            concat!(env!("CARGO_MANIFEST_DIR"), "/../..")
        );
        let problem = Problem::from_path(Path::new(&path), &overrides).unwrap();
        let (family, opts) = problem.continuation.clone().unwrap();
        let mut times = vec![];
        let mut summary = String::new();
        for _ in 0..7 {
            let t = Instant::now();
            let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
            times.push(t.elapsed().as_secs_f64());
            let points: usize = d.branches.iter().map(|b| b.points.len()).sum();
            summary = format!(
                "{} branches, {points} points, {} special points (first at {:.12})",
                d.branches.len(),
                d.special_points.len(),
                d.special_points
                    .first()
                    .map_or(f64::NAN, |s| s.point.parameter)
            );
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{name:<28} {:>8.1} ms   {summary}",
            times[times.len() / 2] * 1e3
        );
    }
}
