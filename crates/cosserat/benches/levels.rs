//! What each model level costs on the same scene: the planar cantilever
//! (k = F L²/B = 3) solved as planar (4 ODEs), Kirchhoff (12) and Cosserat
//! (12, shear and extension stiffnesses 10⁴ B/L²), by single shooting and
//! by collocation of order 6, and its stability analysis (100 elements of
//! order 2); and the spatial 45° bend as Kirchhoff and Cosserat. Tip
//! differences to the least level show what the extra model changes.
//!
//! Run: `cargo bench --bench levels` (median of 21 repetitions, one core).

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use cosserat::bvp::{solve, Method, SolverOptions};
use cosserat::input::Problem;
use cosserat::model::{
    Clamp, DeadLoads, LinearElastic, ModelChoice, ModelLevel, Rod, Shearable, StoredEnergy,
};
use cosserat::stability::{analyze, StabilityOptions};
use nalgebra::Vector3;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time<T>(mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..21 {
        let t = Instant::now();
        last = Some(f());
        times.push(t.elapsed().as_secs_f64());
    }
    (median(times), last.expect("ran"))
}

fn cantilever(shear: Option<f64>) -> Rod {
    let bending: Arc<dyn StoredEnergy> =
        Arc::new(LinearElastic::uniform([10.0, 1.0, 10.0], [0.0; 3]).unwrap());
    let energy = match shear {
        Some(s) => Arc::new(Shearable::new(bending, Vector3::new(s, s, s)).unwrap())
            as Arc<dyn StoredEnergy>,
        None => bending,
    };
    Rod::new(
        1.0,
        energy,
        Clamp::paper(),
        DeadLoads {
            tip_force: Vector3::new(3.0, 0.0, 0.0),
            ..Default::default()
        },
        None,
    )
    .unwrap()
}

fn row(scene: &str, rod: &Rod, choice: &ModelChoice, reference: Option<Vector3<f64>>) {
    for method in [Method::Shooting, Method::Collocation { stages: 3 }] {
        let opts = SolverOptions {
            method,
            output_points: 2,
            ..Default::default()
        };
        let (t_solve, eq) = time(|| solve(rod, choice, &opts).expect("converges"));
        let stability = StabilityOptions::default();
        let (t_stab, _) = time(|| analyze(rod, &eq, &opts, &stability).expect("analyzed"));
        let tip = eq.tip().position;
        let diff = reference.map_or(String::from("—"), |r| format!("{:.1e}", (tip - r).norm()));
        println!(
            "| {scene} | {} | {} | {} | {:.0} | {:.0} | {diff} |",
            choice.level.name(),
            dims(choice.level),
            method.name(),
            t_solve * 1e6,
            t_stab * 1e6,
        );
    }
}

fn dims(level: ModelLevel) -> usize {
    match level {
        ModelLevel::Planar => 4,
        ModelLevel::Kirchhoff | ModelLevel::Cosserat => 12,
    }
}

fn main() {
    println!(
        "| scene | level | ODEs | method | solve [µs] | stability [µs] | tip vs least level |"
    );
    println!("|---|---|---|---|---|---|---|");
    let plain = cantilever(None);
    let least = solve(
        &plain,
        &ModelChoice::for_rod(&plain),
        &SolverOptions::default(),
    )
    .unwrap()
    .tip()
    .position;
    for level in [ModelLevel::Planar, ModelLevel::Kirchhoff] {
        let choice = ModelChoice::forced(&plain, level).unwrap();
        row("cantilever k = 3", &plain, &choice, Some(least));
    }
    let sheared = cantilever(Some(1e4));
    row(
        "cantilever k = 3",
        &sheared,
        &ModelChoice::for_rod(&sheared),
        Some(least),
    );
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("problems/bathe_bolourchi_45.toml");
    let kirchhoff = Problem::from_path(&path, &["solver.model=\"kirchhoff\"".to_string()]).unwrap();
    let cosserat = Problem::from_path(&path, &[]).unwrap();
    let least = solve(&kirchhoff.rod, &kirchhoff.model, &kirchhoff.options)
        .unwrap()
        .tip()
        .position;
    for p in [&kirchhoff, &cosserat] {
        row("45° bend, P = 600", &p.rod, &p.model, Some(least));
    }
}
