//! `cosserat solve problems/point_couple.toml`: a cantilever bent by a dead
//! couple C e2 at s₀ alone is a circular arc of curvature C/B2 up to s₀ and
//! straight beyond (the moment on [0, s) from (s, L] holds the couples
//! beyond s); its tip in closed form against the printed one, the
//! stability's refusal said, and collocation refused by the couple's key.
mod common;

use common::problems::shipped;
use common::run::{run, scratch, stderr};

/// The printed tip position's three components.
fn printed_tip(stdout: &str) -> [f64; 3] {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("tip") && l.contains("position"))
        .unwrap_or_else(|| panic!("no tip line: {stdout}"));
    let inside = line.split('[').nth(1).unwrap().split(']').next().unwrap();
    let v: Vec<f64> = inside
        .split(',')
        .map(|x| x.trim().parse().unwrap())
        .collect();
    [v[0], v[1], v[2]]
}

#[test]
fn the_point_couple_problem_solves_to_the_arc_then_straight_tip() {
    let dir = scratch("point_couple", "solve");
    let out = dir.join("solve.h5");
    let o = run(&[
        "solve",
        &shipped("point_couple"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    // L = 1, B2 = 1, C = 1.2, s₀ = 0.6 (the file's values).
    let (kappa, s0) = (1.2_f64, 0.6_f64);
    let theta = kappa * s0;
    let x = (1.0 - theta.cos()) / kappa + (1.0 - s0) * theta.sin();
    let z = theta.sin() / kappa + (1.0 - s0) * theta.cos();
    let tip = printed_tip(&stdout);
    // Printed to 13 significant digits.
    let error = (tip[0] - x).abs().max(tip[1].abs()).max((tip[2] - z).abs());
    assert!(error <= 1e-11, "tip {tip:?} against ({x}, 0, {z})");
    assert!(
        stdout.contains("stability not decided") && stdout.contains("point couple"),
        "{stdout}"
    );
}

#[test]
fn collocation_is_refused_by_the_couples_key() {
    let o = run(&[
        "solve",
        &shipped("point_couple"),
        "--set",
        "solver.method=\"collocation\"",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("loads.point[0].couple"),
        "{}",
        stderr(&o)
    );
}
