//! The search-convergence check of the tapered arm (docs/extensions.md,
//! "Tapered arms"): the joint ascent of shape and section from four
//! starts — the search's own (the prismatic optimum with its strongest
//! section), the prismatic shape with A ≡ 1, the design of the former block
//! coordinate ascent, and the optimum moved by ±0.05 in every variable —
//! each with its R̂, projected gradient and distance from the optimum.
//!
//!   cargo run --release -p cosserat --example tapered_starts [-- KEY=VALUE ...]
//!
//! (`KEY=VALUE` as `--set` of the command line, e.g.
//! `arm.taper={knots=6, min_section=0.2}`.)

use std::path::Path;

use cosserat::input::Problem;
use cosserat::study::arm::taper::Section;
use cosserat::study::arm::TaperedArm;

/// The block coordinate ascent's design of the shipped problem (R̂ =
/// 4.8519, as it printed it to four digits): c2..c8 and the 11 knot values.
const BLOCK_ASCENT: ([f64; 7], [f64; 11]) = (
    [2.3254, -0.8905, 0.2914, 0.4382, 0.5, 0.5, 0.5],
    [
        1.5443, 1.6435, 1.6452, 1.5578, 1.3953, 1.1555, 0.8735, 0.4571, 0.2, 0.2, 0.2,
    ],
);

fn main() {
    let set: Vec<String> = std::env::args().skip(1).collect();
    let file =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../problems/longest_arm_tapered.toml");
    let problem = Problem::from_path(&file, &set).expect("the shipped problem");
    let (arm, search, _) = problem.arm.clone().expect("an [arm] table");
    let taper = problem.arm_taper.expect("an [arm] taper");
    let tapered = TaperedArm::new(arm.clone(), taper);
    let o = tapered
        .optimize(&search, &|| false)
        .expect("a search")
        .expect("an optimum");
    let m = arm.bounds.len();
    let mut best = o.design.shape_coefficients[1..].to_vec();
    best.extend_from_slice(o.section.values());
    println!(
        "search's start:           R̂ = {:.12}, projected gradient {:.1e}, {} iterations, {}",
        o.design.reach,
        o.ascent.projected_gradient,
        o.ascent.iterations,
        o.ascent.end.name()
    );
    let feasible = tapered.feasible();
    let run = |name: &str, x: &[f64]| {
        let x = feasible.project(x);
        let section = Section::new(x[m..].to_vec(), taper.min_section()).expect("a section");
        let r = tapered.ascend_on(&x[..m], &section, &arm.stability, &|| false);
        let (y, reach) = r.best.expect("a design");
        let distance = y
            .iter()
            .zip(&best)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{name:<25} R̂ = {reach:.12}, projected gradient {:.1e}, {} iterations, {}; \
             max |x − x*| = {distance:.1e}",
            r.projected_gradient,
            r.iterations,
            r.end.name()
        );
    };
    let mut x = o.prismatic.shape_coefficients[1..].to_vec();
    x.extend_from_slice(Section::prismatic(taper.knots()).values());
    run("prismatic shape, A ≡ 1:", &x);
    if m == BLOCK_ASCENT.0.len() && taper.knots() == BLOCK_ASCENT.1.len() {
        let mut x = BLOCK_ASCENT.0.to_vec();
        x.extend_from_slice(&BLOCK_ASCENT.1);
        run("block-ascent design:", &x);
    }
    let moved: Vec<f64> = best
        .iter()
        .enumerate()
        .map(|(i, v)| v + if i % 2 == 0 { 0.05 } else { -0.05 })
        .collect();
    run("optimum moved by ±0.05:", &moved);
}
