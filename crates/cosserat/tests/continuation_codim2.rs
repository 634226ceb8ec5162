//! Two-parameter continuation of a branch point: Euler's clamped–free
//! column followed in (load, length) traces F L²/B = π²/4, i.e.
//! F = π²/(4L²) — every point of the curve against the closed form, to
//! 1e-10 (measured: 7e-13), on the branch-point system with its phase
//! condition (the symmetric branch has F_p = 0, which makes the fold system
//! singular there).

use std::sync::Arc;

use cosserat::continuation::{
    continuation, follow_singular, CurveOptions, Lens2, Parameter, ParameterOn, RodLens,
    SpecialKind,
};
use cosserat::input::Problem;

const EULER: &str = include_str!("../../../problems/euler_column.toml");

#[test]
fn euler_branch_point_curve_is_pi_squared_over_four_l_squared() {
    let problem = Problem::from_str_with(EULER, &["continuation.switch_depth=0".into()]).unwrap();
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
    assert_eq!(curve.keys, ["load_scale", "rod.length"]);
    assert!(curve.points.len() > 10, "{} points", curve.points.len());
    let (mut shortest, mut longest) = (f64::INFINITY, 0.0f64);
    for point in &curve.points {
        let [load, length] = point.parameters;
        let exact = std::f64::consts::PI.powi(2) / (4.0 * length * length);
        assert!(
            (load - exact).abs() <= 1e-10 * exact,
            "L = {length}: {load} vs {exact}"
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
