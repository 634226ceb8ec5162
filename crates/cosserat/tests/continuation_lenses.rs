//! Any number of the rod is a continuation parameter: the problem-file key
//! is a lens (the problem reread with the key set), so boundary data — the
//! held tip position, an end turned through any number of turns — and an
//! energy's own parameters are continued like a load. Each case against
//! its closed form.

use cosserat::continuation::{continuation, Diagram, SpecialKind};
use cosserat::input::Problem;
use cosserat::references::{clamped_elastica_load, twisted_clamped_moment};

const DISPLACEMENT: &str = include_str!("../../../problems/clamped_elastica_displacement.toml");
const TWISTED: &str = include_str!("../../../problems/twisted_rod.toml");

fn diagram(text: &str, set: &[&str]) -> (Problem, Diagram) {
    let set: Vec<String> = set.iter().map(ToString::to_string).collect();
    let problem = Problem::from_str_with(text, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    (problem, d)
}

/// Displacement control: along the whole branch (the ends 0.95 L apart
/// brought to 0.4 L, and back to nearly straight), the force the support
/// exerts is the clamped–clamped elastica's 16 K(k)² B/L² at the
/// shortening δ = 1 − p, to the shooting's accuracy.
#[test]
fn held_tip_position_follows_the_clamped_elastica() {
    let (_, d) = diagram(DISPLACEMENT, &[]);
    let mut checked = 0;
    for branch in &d.branches {
        for point in &branch.points {
            let delta = 1.0 - point.parameter;
            if delta < 1e-3 {
                continue; // the straight end: k → 0, the bisection's digits
            }
            let load = -point.tip.force[2];
            let exact = clamped_elastica_load(delta);
            assert!(
                (load - exact).abs() <= 1e-8 * exact,
                "δ = {delta}: support force {load}, elastica {exact}"
            );
            assert!(
                point.tip.force[0].abs() <= 1e-8 * exact,
                "no shear at the tip"
            );
            checked += 1;
        }
    }
    assert!(checked > 20, "{checked} points checked");
    let reached = d
        .branches
        .iter()
        .flat_map(|b| &b.points)
        .map(|p| p.parameter)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(reached, 0.4, "the branch lands on the bound");
}

/// An end turned through more than a full turn: the straight twisted rod
/// between two clamps loses stability at the end rotation θ = 2x₁ B/C
/// (tan x₁ = x₁), 1.43 turns at B = C; with C = B/2 the critical angle
/// doubles. The Morse index changes across it by two (the isotropic
/// bending pair), and the double branch point is located to 1e-10.
#[test]
fn end_rotation_runs_through_turns_to_the_twisted_rod_instability() {
    for (c, bound) in [(1.0, 12.6), (0.5, 20.0)] {
        let stiffness = format!("energy.stiffness=[1.0, 1.0, {c}]");
        let bounds = format!("continuation.bounds=[0.0, {bound}]");
        let (_, d) = diagram(
            TWISTED,
            &[&stiffness, &bounds, "continuation.switch_depth=0"],
        );
        let exact = twisted_clamped_moment() / c;
        assert!(exact > 2.0 * std::f64::consts::PI, "beyond one turn");
        let straight = &d.branches[0];
        let first_unstable = straight
            .points
            .iter()
            .position(|p| p.morse_index > 0)
            .expect("the twisted rod loses stability");
        let (before, after) = (
            straight.points[first_unstable - 1].parameter,
            straight.points[first_unstable].parameter,
        );
        assert!(
            before < exact && exact < after,
            "C = {c}: [{before}, {after}] ∌ {exact}"
        );
        let special = d
            .special_points
            .iter()
            .find(|s| s.kind == SpecialKind::BranchPoint && s.branch == 0)
            .expect("the branch point is reported");
        let located = special.point.parameter;
        assert!(
            (located - exact).abs() <= 1e-10 * exact,
            "C = {c}: located at {located}, closed form {exact}"
        );
        assert_eq!(special.multiplicity, 2, "the isotropic rod's bending pair");
        // The straight twisted rod: every point is straight (tip on the axis).
        for p in &straight.points {
            assert!(p.tip.position[0].hypot(p.tip.position[1]) < 1e-9);
        }
    }
}

/// A generic key and the library's own parameter are the same number: the
/// Euler column continued in `loads.tip_force[2]` (reread) and in
/// `load_scale` (edited in place) find the critical load π²/4 alike.
#[test]
fn a_load_component_continued_as_a_key_finds_euler() {
    const EULER: &str = include_str!("../../../problems/euler_column.toml");
    let (_, d) = diagram(
        EULER,
        &[
            "continuation.parameter=\"loads.tip_force[2]\"",
            "continuation.bounds=[-4.0, 0.0]",
            "continuation.start=-0.1",
            "continuation.both_directions=true",
            "continuation.switch_depth=0",
        ],
    );
    let critical = -std::f64::consts::PI.powi(2) / 4.0;
    let bp = d
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::BranchPoint)
        .map(|s| s.point.parameter)
        .min_by(|a, b| (a - critical).abs().total_cmp(&(b - critical).abs()))
        .expect("Euler's branch point");
    assert!((bp - critical).abs() < 1e-9, "{bp} against {critical}");
}

/// Keys that name no number of the rod are refused when the problem is
/// read, naming the key.
#[test]
fn keys_that_are_not_numbers_of_the_rod_are_refused() {
    for (key, says) in [
        ("solver.tolerance", "not a number of the rod"),
        ("support.translation", "not a number"),
        ("clamp.turn.angle", "not given"),
        ("clamp.d1", "not a number"),
    ] {
        let set = [format!("continuation.parameter=\"{key}\"")];
        let err = Problem::from_str_with(TWISTED, &set)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("continuation.parameter") && err.contains(says),
            "{key}: {err}"
        );
    }
}

const CANTILEVER: &str = include_str!("../../../problems/cantilever_tip_load.toml");

/// A stiffness continued downwards with a step whose predictor leaves the
/// physical domain (B ≤ 0, where no rod exists) is cut back and lands
/// exactly on its lower bound, where the cantilever is Bisshopp and
/// Drucker's at k = F L²/B2 (B1 does not enter the planar equilibrium:
/// k = 3 there; B2 = 0.2: k = 15).
#[test]
fn a_stiffness_step_beyond_the_physical_domain_lands_on_the_bound() {
    for (key, k_at_bound) in [("energy.stiffness[0]", 3.0), ("energy.stiffness[1]", 15.0)] {
        // (Longer steps on this unit range jump to another equilibrium
        // of the loaded cantilever, which the diagram warns of.)
        for step in ["0.5", "1.0"] {
            let parameter = format!("continuation.parameter=\"{key}\"");
            let step_key = format!("continuation.step={step}");
            let max_step = format!("continuation.max_step={step}");
            let (_, d) = diagram(
                CANTILEVER,
                &[
                    &parameter,
                    "continuation.start=1.0",
                    "continuation.bounds=[0.2, 1.0]",
                    &step_key,
                    &max_step,
                    "continuation.both_directions=true",
                    "continuation.switch_depth=0",
                ],
            );
            let down = &d.branches[1];
            let last = down.points.last().unwrap();
            assert_eq!(
                down.stop_reason,
                cosserat::continuation::BranchEnd::ReachedBound(0.2),
                "{key}, step {step}"
            );
            assert_eq!(last.parameter, 0.2, "{key}, step {step}: on the bound");
            let (deflection, projection, _) = cosserat::references::cantilever_tip(k_at_bound);
            let tip = last.tip.position;
            assert!(
                (tip[0] - deflection).abs() < 1e-8 && (tip[2] - projection).abs() < 1e-8,
                "{key}, step {step}: tip ({}, {}) against ({deflection}, {projection})",
                tip[0],
                tip[2]
            );
        }
    }
}
