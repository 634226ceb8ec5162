//! A continuation starts where the problem's `[solver]` says: its
//! strategy and initial curvature choose the start equilibrium, as they do
//! for `cosserat solve` (continuation used to solve its start with the
//! default solver, whatever the file said).

use std::f64::consts::PI;

use cosserat::continuation::continuation;
use cosserat::input::Problem;
use cosserat::references::ellip_f;

const EULER: &str = include_str!("../../../problems/euler_column.toml");

/// The first point of the Euler column's diagram started at load 4
/// (beyond the first critical load π²/4), with `extra` overrides.
fn start(extra: &[&str]) -> (f64, f64) {
    let mut set = vec![
        "continuation.start=4.0".to_string(),
        "continuation.switch_depth=0".to_string(),
        "continuation.max_points=2".to_string(),
    ];
    set.extend(extra.iter().map(ToString::to_string));
    let p = Problem::from_str_with(EULER, &set).unwrap();
    let (family, opts) = p.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let first = &d.branches[0].points[0];
    (first.parameter, first.tip_angle)
}

/// Without an initial curvature the start is the straight column (the
/// trivial solution exists at every load, and the automatic strategy ramps
/// the load from the unloaded rod); with one and the direct strategy,
/// Newton lands on the buckled elastica, whose load is K(sin(α/2))² for the tip angle α
/// (clamped–free column, load in units of B/L²).
#[test]
fn the_start_honours_the_initial_curvature() {
    let (p, straight) = start(&[]);
    assert_eq!(p, 4.0);
    assert!(straight < 1e-8, "the default start is straight: {straight}");
    let (p, alpha) = start(&[
        "solver.initial_curvature=[0.0, 2.0, 0.0]",
        "solver.strategy=\"direct\"",
    ]);
    assert!(alpha > 0.5, "the start is buckled: tip angle {alpha}");
    let exact = ellip_f(PI / 2.0, (alpha / 2.0).sin()).powi(2);
    assert!(
        (p - exact).abs() <= 1e-8 * exact,
        "tip angle {alpha}: load {p} against the elastica's {exact}"
    );
}

/// The start solve takes the problem's Newton settings: a budget of one
/// iteration cannot solve the buckled start from a rough guess, and the
/// run says so instead of quietly using its own settings.
#[test]
fn the_start_honours_the_newton_budget() {
    let set = [
        "continuation.start=4.0".to_string(),
        "solver.initial_curvature=[0.0, 2.0, 0.0]".to_string(),
        "solver.max_iterations=1".to_string(),
        "solver.strategy=\"direct\"".to_string(),
    ];
    let p = Problem::from_str_with(EULER, &set).unwrap();
    let (family, opts) = p.continuation.clone().unwrap();
    let e = continuation(&family, &opts, &mut |_, _| true).unwrap_err();
    assert!(e.to_string().contains("start"), "{e}");
}

/// The loads are checked for a potential at every point, not only at the
/// start: continuing the helix in a dead tip couple from zero (a couple
/// about d1 has no potential for spatial rotations), the branch ends at
/// its first point — the only one whose stability means something — and
/// says why, instead of reporting eigenvalues of a non-conservative
/// problem.
#[test]
fn a_branch_ends_where_the_loads_lose_their_potential() {
    const HELIX: &str = include_str!("../../../problems/helix_tip_load.toml");
    let text = format!(
        "{HELIX}\n[continuation]\nparameter = \"loads.tip_couple[0]\"\nstart = 0.0\n\
         bounds = [-1.0, 1.0]\nstep = 0.05\nelements = 16\neigenvalues = 2\n"
    );
    let p = Problem::from_str_with(&text, &[]).unwrap();
    let (family, opts) = p.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let b = &d.branches[0];
    assert_eq!(b.points.len(), 1, "{}", b.stop_reason);
    assert_eq!(b.points[0].parameter, 0.0);
    let reason = b.stop_reason.to_string();
    assert!(reason.contains("not conservative"), "{reason}");
}
