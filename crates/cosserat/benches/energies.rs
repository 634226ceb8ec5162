//! What an energy written as a formula costs against the hand-written
//! linear energy: the per-call cost of M and H (the right-hand side's
//! share) and whole solves of the same planar cantilever (k = 3) and of
//! the same spatial bend, on shooting and collocation.
//!
//! Run: `cargo bench --bench energies` (median of 21 repetitions, one core).

use std::hint::black_box;
use std::time::Instant;

use cosserat::bvp::solve;
use cosserat::input::Problem;
use nalgebra::Vector3;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time(mut f: impl FnMut()) -> f64 {
    let mut times = Vec::new();
    for _ in 0..21 {
        let t = Instant::now();
        f();
        times.push(t.elapsed().as_secs_f64());
    }
    median(times)
}

fn problem(kind: &str, tip: &str, method: &str) -> Problem {
    let text = format!(
        r#"
[rod]
length = 1.0
[energy]
{kind}
stiffness = [10.0, 1.0, 10.0]
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = {tip}
[solver]
method = "{method}"
"#
    );
    Problem::from_str_with(&text, &[]).expect("valid problem")
}

fn main() {
    let linear = r#"kind = "linear""#;
    let formula = "kind = \"formula\"\ndensity = \"0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2)\"";
    println!("scene                      method        linear       formula      factor");
    for (scene, tip) in [
        ("planar k = 3", "[3.0, 0.0, 0.0]"),
        ("spatial bend", "[1.0, 1.0, 0.5]"),
    ] {
        for method in ["shooting", "collocation"] {
            let t: Vec<f64> = [linear, formula]
                .iter()
                .map(|kind| {
                    let p = problem(kind, tip, method);
                    time(|| {
                        black_box(solve(&p.rod, &p.model, &p.options).expect("solves"));
                    })
                })
                .collect();
            println!(
                "{scene:<26} {method:<13} {:>9.1} µs {:>9.1} µs {:>6.2}×",
                t[0] * 1e6,
                t[1] * 1e6,
                t[1] / t[0]
            );
        }
    }
    let k = Vector3::new(0.1, 0.9, -0.3);
    for kind in [linear, formula] {
        let p = problem(kind, "[3.0, 0.0, 0.0]", "shooting");
        let e = p.rod.energy().clone();
        let per_call = time(|| {
            for i in 0..10_000 {
                let s = f64::from(i) * 1e-4;
                black_box(e.moment(s, &k));
                black_box(e.stiffness(s, &k));
            }
        }) / 1e4;
        println!(
            "M and H per call, {:<8} {:>8.1} ns",
            e.name(),
            per_call * 1e9
        );
    }
}
