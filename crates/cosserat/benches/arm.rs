//! The inner call of `cosserat optimize`: one evaluation of the objective
//! (a design's critical load and reach, `ArmProblem::design_in`) at the
//! first 64 samples of the search's box, on the shipped
//! problems/longest_arm.toml (M = 8, N = 100 linear elements).
//!
//! Run: `cargo bench -p cosserat --bench arm` (median and min per
//! evaluation over the samples, each evaluated 5 times in one process).

use std::path::Path;
use std::time::Instant;

use cosserat::input::Problem;

fn main() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../problems/longest_arm.toml"
    );
    let problem = Problem::from_path(Path::new(path), &[]).unwrap();
    let (arm, _, _) = problem.arm.clone().unwrap();
    let (scene, _) = problem.arm_scene.unwrap();
    let samples: Vec<Vec<f64>> = (1..=64).map(|i| arm.sample_point(i)).collect();
    let mut times = Vec::new();
    let mut feasible = 0;
    for _ in 0..5 {
        feasible = 0;
        for x in &samples {
            let t = Instant::now();
            let design = arm.design_in(&scene, x);
            times.push(t.elapsed().as_secs_f64());
            feasible += usize::from(design.is_some());
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "arm design evaluation (N = {}, M = {}): median {:.3} ms, min {:.3} ms over {} evaluations \
         ({feasible} of {} samples feasible)",
        arm.stability.elements(),
        arm.coefficients(),
        times[times.len() / 2] * 1e3,
        times[0] * 1e3,
        times.len(),
        samples.len()
    );
}
