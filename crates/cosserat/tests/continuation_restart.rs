//! A continuation restarted from a point of a stored branch goes on along
//! the same curve: Euler's buckled column restarted from its tenth point
//! ends where the uninterrupted branch ends, at the 170° tip angle whose
//! load is the elastica's K(sin 85°)² (the step sizes differ, so the
//! points between differ; the curve and its end do not).

use std::f64::consts::FRAC_PI_2;

use cosserat::continuation::{continuation, continuation_from, StartPoint};
use cosserat::input::Problem;
use cosserat::references::ellip_f;

const EULER: &str = include_str!("../../../problems/euler_column.toml");

#[test]
fn a_restart_from_a_stored_point_reproduces_the_branch() {
    let problem = Problem::from_str_with(EULER, &[]).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let full = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let buckled = &full.branches[1];
    let from = &buckled.points[10];
    let mut restart_opts = opts.clone();
    restart_opts.start = from.parameter;
    restart_opts.switch_depth = 0;
    let start = StartPoint::new(from.unknowns.clone(), Some(from.tangent.clone()));
    let again = continuation_from(&family, &restart_opts, &start, &mut |_, _| true).unwrap();
    let branch = &again.branches[0];
    // The first point is the stored one, re-converged.
    let first = &branch.points[0];
    assert!((first.parameter - from.parameter).abs() < 1e-14);
    assert!((first.tip_angle - from.tip_angle).abs() < 1e-9);
    // It travels the same way and ends at the same point.
    let (end, full_end) = (
        branch.points.last().unwrap(),
        buckled.points.last().unwrap(),
    );
    assert!(
        end.parameter > first.parameter,
        "forward, as the stored branch"
    );
    assert_eq!(branch.stop_reason, buckled.stop_reason);
    let exact = ellip_f(FRAC_PI_2, 85f64.to_radians().sin()).powi(2);
    for p in [end.parameter, full_end.parameter] {
        assert!(
            (p - exact).abs() < 1e-8 * exact,
            "end load {p}, elastica {exact}"
        );
    }
    assert!((end.parameter - full_end.parameter).abs() < 1e-9 * exact);
}

/// Unknowns of another discretization are refused, not squeezed.
#[test]
fn unknowns_of_another_discretization_are_refused() {
    let problem = Problem::from_str_with(EULER, &[]).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let start = StartPoint::new(vec![0.0; family.size() + 3], None);
    let err = continuation_from(&family, &opts, &start, &mut |_, _| true).unwrap_err();
    assert!(err.to_string().contains("unknowns"), "{err}");
}
