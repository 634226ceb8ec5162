//! Continuation on the collocation discretization against shooting, two
//! independent discretizations of the same rod: the lateral-torsional
//! cantilever's two branch points (problems/lateral_torsional_buckling.toml)
//! on Gauss collocation of order 6 agree with single shooting's (DOP853)
//! to the collocation's own error, measured by a convergence study
//! (Richardson on 8, 16, 32 intervals), plus the located events' tolerance.

use cosserat::continuation::{continuation, SpecialKind};
use cosserat::input::Problem;

const LTB: &str = include_str!("../../../problems/lateral_torsional_buckling.toml");

/// The parameters of the branch points on the loading branch (no
/// switching), with `extra` overrides.
fn branch_points(extra: &[String]) -> Vec<f64> {
    let mut set = vec![
        "continuation.switch_depth=0".to_string(),
        "continuation.bounds=[0.0, 1.45]".to_string(),
    ];
    set.extend_from_slice(extra);
    let p = Problem::from_str_with(LTB, &set).unwrap();
    let (family, opts) = p.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    d.special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::BranchPoint)
        .map(|s| s.point.parameter)
        .collect()
}

fn collocation(intervals: usize) -> Vec<f64> {
    branch_points(&[
        "solver.method=\"collocation\"".into(),
        format!("continuation.intervals={intervals}"),
    ])
}

#[test]
fn lateral_torsional_branch_points_agree_with_shooting() {
    let shooting = branch_points(&[]);
    let meshes: Vec<Vec<f64>> = [8, 16, 32].iter().map(|&k| collocation(k)).collect();
    eprintln!("shooting {shooting:?}\ncollocation 8, 16, 32: {meshes:?}");
    assert_eq!(shooting.len(), 2, "{shooting:?}");
    for (i, &reference) in shooting.iter().enumerate() {
        let p: Vec<f64> = meshes.iter().map(|m| m[i]).collect();
        // The measured order from the three meshes, and the error of the
        // finest by Richardson: e(32) ≈ |p16 − p32| / (2^q − 1).
        let order = ((p[0] - p[1]) / (p[1] - p[2])).abs().log2();
        let q = order.min(6.0);
        let error = (p[1] - p[2]).abs() / (2f64.powf(q) - 1.0);
        eprintln!("point {i}: order {order:.2}, estimated error {error:e}");
        // The events are located to 1e-11 in the arclength (event_tolerance)
        // on each discretization; shooting integrates to 1e-10 relative.
        // Measured (32 intervals): 5.8e-11 and 1.07e-8 from shooting, with
        // estimated errors 2.0e-11 and 1.14e-8.
        let allowed = 3.0 * error + 1e-10 * reference;
        assert!(
            (p[2] - reference).abs() <= allowed,
            "branch point {i}: collocation {} against shooting {reference} (allowed {allowed:e})",
            p[2]
        );
        // The error is the collocation's own: removing the estimated
        // leading term (Richardson extrapolation) leaves the shooting and
        // event-location error (measured 1e-10 at the second point, where
        // the collocation's own is 1e-8).
        let extrapolated = p[2] - (p[1] - p[2]) / (2f64.powf(q) - 1.0);
        assert!(
            (extrapolated - reference).abs() <= 5e-10 * reference,
            "branch point {i}: extrapolated {extrapolated} against shooting {reference}"
        );
    }
}

/// The structured F_x of a collocation family (almost block diagonal,
/// [`cosserat::continuation::Family::residual_staircase`]) is the
/// derivative of its residual: central differences of F in each unknown
/// (h = 1e-6, truncation error O(h²)) at the straight-rod guess carried
/// across 6 intervals, away from any solution.
#[test]
fn the_structured_jacobian_is_the_derivative_of_the_residual() {
    let set = [
        "solver.method=\"collocation\"".to_string(),
        "continuation.intervals=6".to_string(),
    ];
    let p = Problem::from_str_with(LTB, &set).unwrap();
    let (family, _) = p.continuation.clone().unwrap();
    let load = 0.3;
    let mut x = family.initial_unknowns(load).unwrap();
    // Off the guess, so that no block is trivial.
    for (i, v) in x.iter_mut().enumerate() {
        *v += 1e-2 * ((i as f64) * 0.7).sin();
    }
    let n = x.len();
    let mut jac = family.staircase().expect("6 intervals are structured");
    let mut r = nalgebra::DVector::zeros(n);
    family
        .residual_staircase(&x, load, &mut r, &mut jac)
        .unwrap();
    let dense = jac.to_dense();
    let h = 1e-6;
    let (mut up, mut down) = (nalgebra::DVector::zeros(n), nalgebra::DVector::zeros(n));
    let mut worst: f64 = 0.0;
    for c in 0..n {
        let mut xp = x.clone();
        xp[c] += h;
        family.residual_only(&xp, load, &mut up).unwrap();
        xp[c] -= 2.0 * h;
        family.residual_only(&xp, load, &mut down).unwrap();
        let column = (&up - &down) / (2.0 * h);
        worst = worst.max((column - dense.column(c)).amax());
    }
    assert!(
        worst <= 1e-7 * dense.amax(),
        "{worst:e} against {:e}",
        dense.amax()
    );
}

/// The points of the loading branch up to λ = 0.4 (below the first
/// branch point), with `extra` overrides.
fn points_to(extra: &[String]) -> usize {
    let mut set = vec![
        "continuation.switch_depth=0".to_string(),
        "continuation.bounds=[0.0, 0.4]".to_string(),
    ];
    set.extend_from_slice(extra);
    let p = Problem::from_str_with(LTB, &set).unwrap();
    let (family, opts) = p.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    d.branches[0].points.len()
}

/// The collocation mesh's node states enter the arclength as their
/// root-mean-square (a discrete L² norm), so a step moves the load as far
/// on 32 intervals as on 8 and about as far as shooting's: the same steps
/// take the same number of points (measured: 8 and 8 points on 8 and 32
/// intervals, shooting 7; with the Euclidean norm of all node states 10
/// and 17).
#[test]
fn collocation_steps_do_not_shrink_with_the_mesh() {
    let shooting = points_to(&[]);
    let coarse = points_to(&[
        "solver.method=\"collocation\"".into(),
        "continuation.intervals=8".into(),
    ]);
    let fine = points_to(&[
        "solver.method=\"collocation\"".into(),
        "continuation.intervals=32".into(),
    ]);
    eprintln!("points to λ = 0.4: shooting {shooting}, collocation 8: {coarse}, 32: {fine}");
    assert!(
        fine <= coarse + 1,
        "32 intervals {fine} points, 8 intervals {coarse}"
    );
    assert!(
        fine <= shooting + 2,
        "collocation {fine} points, shooting {shooting}"
    );
}

/// The Euler column's double branch point (B1 = B2, the Kirchhoff model
/// sees both buckling planes) on collocation meshes of 16 and 32
/// intervals: 16 (≈ 150 unknowns) runs the dense bordered test and the
/// dense kernel of [F_x F_p], 32 (≈ 300, above the dense limit) the O(N)
/// ones (inverse iteration on the band LU, `continuation/kernel.rs`). Both
/// are located at π²/4 (Euler 1744) within the collocation error measured
/// between them (|p16 − π²/4| bounds the error of the finer mesh, whose
/// order is ≥ 2) plus the event tolerance, and both switch onto the four
/// buckled branches (two kernel directions, both ways), which bend.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "two collocation diagrams, ≈ 3 s in release: run with --release"
)]
fn double_branch_point_switches_on_a_large_collocation_family() {
    let reference = std::f64::consts::PI.powi(2) / 4.0;
    let column = include_str!("../../../problems/euler_column.toml");
    let run = |intervals: usize| {
        let set = [
            "solver.method=\"collocation\"".to_string(),
            "solver.model=\"kirchhoff\"".to_string(),
            format!("continuation.intervals={intervals}"),
            "continuation.bounds=[0.0, 2.7]".to_string(),
        ];
        let p = Problem::from_str_with(column, &set).unwrap();
        let (family, opts) = p.continuation.clone().unwrap();
        (
            family.size(),
            continuation(&family, &opts, &mut |_, _| true).unwrap(),
        )
    };
    let (coarse_size, coarse) = run(16);
    let (fine_size, fine) = run(32);
    assert!(
        coarse_size <= 200 && fine_size > 200,
        "{coarse_size}, {fine_size}"
    );
    let located = |d: &cosserat::continuation::Diagram| {
        let bps: Vec<_> = d
            .special_points
            .iter()
            .filter(|s| s.kind == SpecialKind::BranchPoint)
            .collect();
        assert_eq!(bps.len(), 1, "one double branch point");
        assert_eq!(bps[0].multiplicity, 2);
        bps[0].point.parameter
    };
    let (p16, p32) = (located(&coarse), located(&fine));
    let error16 = (p16 - reference).abs();
    eprintln!(
        "16: {p16} ({error16:e}), 32: {p32} ({:e})",
        (p32 - reference).abs()
    );
    assert!(
        (p32 - reference).abs() <= error16 + 1e-10 * reference,
        "32 intervals: {p32} against π²/4 = {reference}"
    );
    for d in [&coarse, &fine] {
        assert_eq!(d.branches.len(), 5, "the loading branch and four switched");
        for b in &d.branches[1..] {
            let last = b.points.last().unwrap();
            assert!(last.parameter > 2.6, "a switched branch reaches the bound");
            assert!(last.norm > 0.1, "and is buckled (‖κ‖ = {})", last.norm);
        }
    }
}
