//! Speed of the stability analysis.
//!
//! Run: `cargo bench --bench stability`. Prints the time for the lowest four
//! eigenvalues of the in-plane block of K (assembly + Sturm shift + Lanczos)
//! on meshes of 10² to 10⁴ elements with the fitted log-log slope, and the
//! time of a fixed-shape critical load (the generalized eigenproblem
//! K0 + λK1) at 100 elements.

#[path = "../tests/support/mod.rs"]
mod support;

use std::time::Instant;

use cosserat::bvp::{solve, SolverOptions};
use cosserat::model::{ModelChoice, Profile};
use cosserat::stability::eigen::lowest_eigenpairs;
use cosserat::stability::{
    coefficients, critical_load, Block, FiniteElements, FixedShape, StabilityOptions,
};
use support::rods::{cantilever, tip_force, uniform};

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

fn main() {
    let rod = cantilever(3.0);
    let opts = SolverOptions::default();
    let eq = solve(&rod, &ModelChoice::for_rod(&rod), &opts).unwrap();
    println!("lowest 4 eigenvalues of the in-plane block (order 2), cantilever k = 3");
    println!(
        "{:>8} {:>8} {:>14} {:>14}",
        "elements", "size", "K, G [ms]", "eigen [ms]"
    );
    let mut points = vec![];
    for elements in [100, 300, 1000, 3000, 10000] {
        let fe = FiniteElements::new(1.0, elements, 2);
        let samples = eq.resample(&rod, &opts, &fe.quadrature_points()).unwrap();
        let c = coefficients(&rod, &samples);
        let repeats = if elements > 3000 { 3 } else { 9 };
        let assemble = time(repeats, || {
            std::hint::black_box((fe.stiffness(&c, Block::InPlane), fe.mass(Block::InPlane)));
        });
        let (k, g) = (fe.stiffness(&c, Block::InPlane), fe.mass(Block::InPlane));
        let eigen = time(repeats, || {
            std::hint::black_box(lowest_eigenpairs(&k, &g, 4).unwrap());
        });
        println!(
            "{:>8} {:>8} {:>14.3} {:>14.3}",
            elements,
            k.size(),
            assemble * 1e3,
            eigen * 1e3
        );
        points.push(((elements as f64).ln(), (eigen + assemble).ln()));
    }
    let n = points.len() as f64;
    let (mx, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    println!("log-log slope of time against elements: {slope:.2}");

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
