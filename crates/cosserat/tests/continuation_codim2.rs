//! Two-parameter continuation of a branch point: Euler's clamped–free
//! column followed in (load, length) traces F L²/B = π²/4, i.e.
//! F = π²/(4L²) — every point of the curve against the closed form, to
//! 1e-10 (measured: 7e-13), on the branch-point system with its phase
//! condition (the symmetric branch has F_p = 0, which makes the fold system
//! singular there). Every point states its discretization error (the
//! point located again on the refined family, `codim2/error.rs`), checked
//! against its actual error from the closed form.

use std::sync::Arc;

use cosserat::continuation::{
    continuation, follow_singular, CurveOptions, Lens2, Parameter, ParameterOn, RodLens,
    SpecialKind,
};
use cosserat::input::Problem;

const EULER: &str = include_str!("../../../problems/euler_column.toml");

#[test]
fn euler_branch_point_curve_is_pi_squared_over_four_l_squared() {
    euler_curve(&[]);
}

/// On 16 collocation intervals of order 2 the curve is off by 1e-3 to
/// 2e-2 (the discretization's O(h²)), and every point's estimated error
/// of the load at its length is that actual error within 1 % (measured:
/// 0.03–0.07 %), Richardson on twice the intervals (gain 4).
#[test]
fn a_coarse_curve_states_its_actual_error() {
    let curve = euler_curve_on(&[
        "solver.method=\"collocation\"",
        "solver.stages=1",
        "continuation.intervals=16",
    ]);
    for point in &curve.points {
        let [load, length] = point.parameters;
        let actual = (load - quarter_pi_squared(length)).abs();
        let [estimate, _] = point.parameter_error.expect("an estimate");
        assert!(actual > 1e-4, "L = {length}: a coarse mesh ({actual:e})");
        assert!(
            (estimate - actual).abs() <= 0.01 * actual,
            "L = {length}: estimated {estimate:e}, actual {actual:e}"
        );
    }
}

/// F L²/B = π²/4: Euler's critical load of the clamped–free column of
/// length L (B = 1).
fn quarter_pi_squared(length: f64) -> f64 {
    std::f64::consts::PI.powi(2) / (4.0 * length * length)
}

/// The same curve on collocation with 400 intervals (1597 unknowns): the
/// augmented system is solved in F_x's band shape
/// (`continuation/bordering.rs`), O(N) per Newton step — it was dense,
/// with a finite-difference gradient of g costing N + 2 Jacobians.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "a 1597-unknown curve, ≈ 3 s in release: run with --release"
)]
fn the_curve_is_followed_on_a_large_collocation_family() {
    euler_curve(&[
        "solver.method=\"collocation\"",
        "continuation.intervals=400",
    ]);
}

/// Follows Euler's branch point in (load, length) on the problem with
/// `sets` and checks every point against π²/(4L²), and its stated error
/// against the actual one: below 1e-10 relative and at least half the
/// actual error above the corrector's own (the estimate is the
/// discretization's alone; on 400 intervals of order 6 that is ≈ 1e-20
/// and the points are off by the Newton tolerance's remainder, measured
/// ≤ 3e-14 relative).
fn euler_curve(sets: &[&str]) {
    let curve = euler_curve_on(sets);
    let (mut shortest, mut longest) = (f64::INFINITY, 0.0f64);
    for point in &curve.points {
        let [load, length] = point.parameters;
        let exact = quarter_pi_squared(length);
        assert!(
            (load - exact).abs() <= 1e-10 * exact,
            "L = {length}: {load} vs {exact}"
        );
        let [estimate, _] = point.parameter_error.expect("an estimate");
        assert!(
            estimate <= 1e-10 * exact && (load - exact).abs() <= 2.0 * estimate + 1e-13 * exact,
            "L = {length}: estimated {estimate:e}, actual {:e}",
            (load - exact).abs()
        );
        assert!(point.singularity < 1e-9, "g = {}", point.singularity);
        shortest = shortest.min(length);
        longest = longest.max(length);
    }
    assert!(
        shortest <= 0.5 + 1e-9 && longest >= 2.0 - 1e-9,
        "[{shortest}, {longest}]: {:?}",
        curve.ends
    );
    assert!(curve.cusps.is_empty(), "a smooth curve has no cusp");
}

/// Euler's branch point in (load, length) on the problem with `sets`,
/// every point a branch point (|g| at the tolerance), no warning.
fn euler_curve_on(sets: &[&str]) -> cosserat::continuation::SingularCurve {
    let mut all = vec!["continuation.switch_depth=0".to_string()];
    all.extend(sets.iter().map(|s| (*s).to_string()));
    let problem = Problem::from_str_with(EULER, &all).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let bp = d
        .special_points
        .iter()
        .find(|s| s.kind == SpecialKind::BranchPoint && s.block.name() == "in_plane")
        .expect("Euler's branch point");
    let length = Arc::new(RodLens::new(problem.rod.clone(), Parameter::Length));
    let pair: Arc<dyn Lens2> = Arc::new(ParameterOn::new(Parameter::LoadScale, length));
    let curve_opts = CurveOptions {
        bounds: [(0.0, 100.0), (0.5, 2.0)],
        step: 0.1,
        max_step: 0.3,
        ..CurveOptions::default()
    };
    let curve = follow_singular(
        &family,
        &pair,
        SpecialKind::BranchPoint,
        &bp.point.unknowns,
        [bp.point.parameter, 1.0],
        &curve_opts,
    )
    .unwrap();
    eprintln!(
        "{} unknowns, {} points of the curve",
        family.size(),
        curve.points.len()
    );
    assert_eq!(curve.keys, ["load_scale", "rod.length"]);
    assert!(curve.points.len() > 10, "{} points", curve.points.len());
    assert!(curve.warnings.is_empty(), "{:?}", curve.warnings);
    curve
}

/// A fold curve with a cusp: the paper's Fig. 2 rod (its clamp turned,
/// a tip weight) has a pair of folds in the clamp angle; followed in the
/// rod length, the fold curve comes down to a cusp where the pair is born —
/// at the clamp pointing straight up, 3π/2, and Euler's critical length of
/// the upright column, L √(F/B) = π/2 (paper eq. (2)): below it the upright
/// rod stands, above it buckles. Located to 1e-9 in both parameters.
#[test]
fn the_fold_pair_of_a_turned_clamp_is_born_at_eulers_upright_column() {
    const FIG2: &str = include_str!("../../../problems/planar_clamp_angle.toml");
    let problem = Problem::from_str_with(FIG2, &[]).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let fold = d
        .special_points
        .iter()
        .find(|s| s.kind == SpecialKind::Fold && s.point.parameter > 5.0)
        .expect("the fold near 5.46");
    let length = Arc::new(RodLens::new(problem.rod.clone(), Parameter::Length));
    let pair: Arc<dyn Lens2> = Arc::new(ParameterOn::new(Parameter::ClampAngle, length));
    let curve_opts = CurveOptions {
        bounds: [(-6.3, 6.3), (1.0, 2.6)],
        step: 0.05,
        max_step: 0.1,
        ..CurveOptions::default()
    };
    let curve = follow_singular(
        &family,
        &pair,
        SpecialKind::Fold,
        &fold.point.unknowns,
        [fold.point.parameter, 2.4],
        &curve_opts,
    )
    .unwrap();
    assert_eq!(curve.cusps.len(), 1, "one cusp");
    let [angle, l] = curve.cusps[0].point.parameters;
    let (up, euler) = (1.5 * std::f64::consts::PI, std::f64::consts::FRAC_PI_2);
    assert!((angle - up).abs() < 1e-9, "cusp angle {angle} vs 3π/2");
    assert!((l - euler).abs() < 1e-9, "cusp length {l} vs π/2");
    // Its stated error, the cusp located again on the refined family: the
    // length's within a factor 2 of its actual error (measured 2.90e-13
    // against 2.90e-13); the angle is 3π/2 on every discretization (the
    // upright rod's symmetry), so only bounded.
    let [e_angle, e_length] = curve.cusps[0].parameter_error.expect("an estimate");
    let actual = (l - euler).abs();
    assert!(
        (0.5 * actual..=2.0 * actual).contains(&e_length),
        "length: estimated {e_length:e}, actual {actual:e}"
    );
    assert!(e_angle < 1e-9 && (angle - up).abs() <= 2.0 * e_angle + 1e-14);
    assert!(curve.warnings.is_empty(), "{:?}", curve.warnings);
    // Every point of the curve is a fold: |g| at the tolerance.
    assert!(curve.points.iter().all(|p| p.singularity < 1e-8));
}
