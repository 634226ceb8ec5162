//! Where an equilibrium's time goes: Newton iterations, ramp steps,
//! integrator steps and right-hand side evaluations of the planar
//! cantilever (k = 3, 10) solved by shooting, with the tip error against
//! Bisshopp–Drucker's closed form.
//!
//! Run: `cargo run --release -p cosserat --example equilibrium_profile [rtol] [k] [strategy] [reps]`.

use std::sync::Arc;
use std::time::Instant;

use cosserat::bvp::integrator::Tolerances;
use cosserat::bvp::{solve, Method, SolverOptions, Strategy};
use cosserat::model::{Clamp, DeadLoads, LinearElastic, ModelChoice, ModelLevel, Rod};
use nalgebra::Vector3;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rtol: f64 = args.get(1).map_or(1e-10, |a| a.parse().expect("rtol"));
    let k: f64 = args.get(2).map_or(3.0, |a| a.parse().expect("k"));
    let strategy = match args.get(3).map_or("auto", String::as_str) {
        "direct" => Strategy::Direct,
        "ramp" => Strategy::Ramp,
        _ => Strategy::Auto,
    };
    let reps: usize = args.get(4).map_or(2000, |a| a.parse().expect("reps"));
    let energy = LinearElastic::uniform([10.0, 1.0, 10.0], [0.0; 3]).expect("stiffness");
    let loads = DeadLoads {
        tip_force: Vector3::new(k, 0.0, 0.0),
        ..Default::default()
    };
    let rod = Rod::new(1.0, Arc::new(energy), Clamp::paper(), loads, None).expect("rod");
    let choice = ModelChoice::forced(&rod, ModelLevel::Planar).expect("planar");
    let opts = SolverOptions {
        method: Method::Shooting,
        integration: Tolerances {
            rtol,
            atol: rtol,
            ..Default::default()
        },
        output_points: 2,
        strategy,
        ..Default::default()
    };
    let reference = cosserat::references::CantileverTip::at(k);
    let eq = solve(&rod, &choice, &opts).expect("converges");
    let tip = eq.tip().position;
    let err = (tip[0] - reference.x)
        .abs()
        .max((tip[2] - reference.z).abs());
    let t = Instant::now();
    for _ in 0..reps {
        std::hint::black_box(solve(&rod, &choice, &opts).expect("converges"));
    }
    let per = t.elapsed().as_secs_f64() / reps as f64;
    println!(
        "k {k} rtol {rtol:.0e} {strategy:?}: {:.1} µs, tip error {err:.1e}, ramp steps {}, \
         Newton iterations (final) {}, steps {} accepted {} rejected, {} evaluations, residuals {:?}",
        per * 1e6,
        eq.load_steps,
        eq.iterations,
        eq.integration.accepted,
        eq.integration.rejected,
        eq.integration.evaluations,
        eq.residual_history
    );
}
