//! Greenhill's shaft continued in its thrust at a fixed twisting couple
//! (problems/greenhill.toml): the straight isotropic rod (B1 = B2) loses
//! stability where a pair of eigenvalues of δ²V crosses zero together —
//! the helical modes of both senses, turned by any angle about the axis —
//! so the branch point has multiplicity 2, det F_x a double root there,
//! and the kernel of F_x is a plane.
//!
//! Reference: with the base clamped and the tip held on the axis and in
//! direction (sliding along and spinning about it), the linearized
//! equation B w'''' − i M w''' + P w'' = 0, w = w' = 0 at both ends, has a
//! nontrivial solution first at the smallest root of a 4 × 4
//! characteristic determinant (Greenhill 1883; Ziegler, *Principles of
//! Structural Stability*, 1968, Sec. 2.7): `references::greenhill_clamped`,
//! itself tested against 4π² at M = 0 and Greenhill's torque at P = 0
//! (tests/references.rs). The pinned–pinned form P/B + M²/(4B²) = π²/L²
//! needs a pinned base, which a clamp with an axial torque cannot give.

use cosserat::continuation::{continuation, Diagram, SpecialKind};
use cosserat::input::Problem;
use cosserat::references::greenhill_clamped;

const GREENHILL: &str = include_str!("../../../problems/greenhill.toml");

/// The couple of problems/greenhill.toml, M L/B.
const TWIST: f64 = 2.0;

fn diagram(set: &[&str]) -> Diagram {
    let set: Vec<String> = set.iter().map(ToString::to_string).collect();
    let problem = Problem::from_str_with(GREENHILL, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    continuation(&family, &opts, &mut |_, _| true).unwrap()
}

/// One branch point, of multiplicity 2, at Greenhill's load to 1e-10
/// (the shooting Jacobian sees the bending modes, so it is located on
/// Govaerts' bordered G, whose entries have a simple root where
/// det F_x has a double one); the Morse index jumps 0 → 2 across it.
#[test]
fn the_straight_shaft_loses_stability_at_a_double_branch_point() {
    let d = diagram(&["continuation.switch_depth=0"]);
    let reference = greenhill_clamped(TWIST);
    assert_eq!(d.special_points.len(), 1, "{:?}", d.warnings);
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let sp = &d.special_points[0];
    assert_eq!(sp.kind, SpecialKind::BranchPoint);
    assert_eq!(sp.multiplicity, 2);
    let p = sp.point.parameter;
    assert!(
        (p - reference).abs() <= 1e-10 * reference,
        "branch point at {p:.13}, Greenhill's load {reference:.13}"
    );
    let branch = &d.branches[0].points;
    assert_eq!(branch[sp.index].morse_index, 0);
    assert_eq!(branch[sp.index + 1].morse_index, 2);
}

/// Switching follows two independent directions of the planar kernel,
/// both ways: four branches, whose first points are congruent (the same
/// thrust, curvature norm and spectrum — each is the other turned about
/// the axis) but not the same equilibrium, and lie beyond the critical
/// thrust on buckled (non-straight) shapes.
///
/// Copies agree only to the integration's noise, which the first points,
/// close to the double point, amplify: at the default tolerance 1e-12 they
/// differed by 3e-9 with F_p by central differences and by 1e-8 with the
/// exact F_p — two realizations of step-size sequences (the first point
/// itself moves by 1e-6 in p between tolerances 1e-12 and 1e-13). At 1e-13
/// they agree to 1e-15 with either F_p, so the congruence checked below is
/// the copies', not the step sequences' luck.
#[test]
fn switching_follows_two_kernel_directions_to_congruent_branches() {
    let d = diagram(&[
        "continuation.bounds=[25.0, 38.0]",
        "continuation.max_points=12",
        "solver.integration_tolerance=1e-13",
    ]);
    let reference = greenhill_clamped(TWIST);
    let sp = &d.special_points[0];
    assert_eq!(sp.multiplicity, 2);
    assert_eq!(sp.children.len(), 4, "{:?}", d.warnings);
    let firsts: Vec<_> = sp
        .children
        .iter()
        .map(|&c| d.branches[c].points[0].clone())
        .collect();
    let straight = d.branches[0].points[0].norm;
    let first = &firsts[0];
    assert!(first.parameter > reference);
    assert!(first.norm > straight + 1e-3, "buckled: {}", first.norm);
    for other in &firsts[1..] {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-8 * a.abs().max(1.0);
        assert!(close(first.parameter, other.parameter));
        assert!(close(first.norm, other.norm));
        for (a, b) in first.eigenvalues.iter().zip(&other.eigenvalues) {
            assert!((a - b).abs() <= 1e-6, "{a} vs {b}");
        }
        let apart: f64 = first
            .unknowns
            .iter()
            .zip(&other.unknowns)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(apart > 1e-3, "distinct equilibria: {apart}");
    }
}

/// The helical branches' fold lies on a branch of symmetric copies (the
/// helix turned about the axis), where it is the bracketed root of τ_p;
/// its stated error comes from the same root bracketed again on the
/// refined family's slice (integration tolerances 100× tighter). Against
/// a convergence study in the integration tolerance — the fold at
/// 1e-9 / 1e-10 / 1e-11 is 2.10e-8 / 2.23e-9 / 2.64e-10 from the fold at
/// the integrator's floor 1e-14 (first order in the tolerance, measured
/// ratios 9.4 and 8.4) — each estimate is within a factor 2 of that
/// actual error (measured 2.1e-8, 2.2e-9, 2.6e-10).
#[test]
#[cfg_attr(debug_assertions, ignore = "four diagrams: ≈ 3 s in release")]
fn the_fold_on_the_helical_branches_states_its_error() {
    let fold = |tolerance: f64| {
        let d = diagram(&[
            "continuation.switch_depth=1",
            &format!("solver.integration_tolerance={tolerance:e}"),
        ]);
        let folds: Vec<_> = d
            .special_points
            .iter()
            .filter(|s| s.kind == SpecialKind::Fold)
            .cloned()
            .collect();
        assert_eq!(folds.len(), 4, "one fold a helical branch: {folds:?}");
        folds[0].clone()
    };
    let reference = fold(1e-14).point.parameter;
    for tolerance in [1e-9, 1e-10, 1e-11] {
        let sp = fold(tolerance);
        let estimate = sp.parameter_error.expect("an estimate");
        let actual = (sp.point.parameter - reference).abs();
        assert!(
            (0.5 * actual..=2.0 * actual).contains(&estimate),
            "tolerance {tolerance:e}: estimated {estimate:e}, actual {actual:e}"
        );
    }
}
