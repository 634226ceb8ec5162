//! Interior point loads (`[[loads.point]]`) against closed forms: a
//! cantilever loaded at s₀ < L by a force and nothing at its tip is
//! Bisshopp and Drucker's cantilever of length s₀ (the elliptic integrals of
//! `cosserat::references::cantilever_tip`) followed by a straight piece —
//! an exact check that every method stops at the jump of n(s).
mod support;

use cosserat::bvp::Method;
use cosserat::continuation::{
    continuation, DerivativeMethod, Diagram, Location, SpecialKind, SpecialPoint,
};
use cosserat::input::{Problem, ProblemError};
use cosserat::model::{DeadLoads, ModelChoice, ModelLevel, PointLoad, Rod};
use cosserat::references::CantileverTip;
use cosserat::references::{arch_elastica_folds, strip_elastica_fold};
use cosserat::stability::StabilityOptions;
use nalgebra::Vector3;
use support::methods::{options, solve_with, EVERY_METHOD, UNSHEARABLE_LEVELS};
use support::parameter_derivative::richardson_parameter_derivative;

/// L = 1, B = (10, 1, 10), the paper's clamp (d1(0) = e1 down), the force
/// F e1 at s₀.
fn loaded_at(s0: f64, force: f64) -> Rod {
    let loads = DeadLoads {
        point_loads: vec![PointLoad::force(s0, Vector3::new(force, 0.0, 0.0))],
        ..Default::default()
    };
    support::rods::uniform(1.0, [10.0, 1.0, 10.0], loads)
}

/// The angle of d3 from e3 towards e1.
fn angle(d3: &Vector3<f64>) -> f64 {
    d3[0].atan2(d3[2])
}

#[test]
fn a_cantilever_loaded_inside_is_bisshopp_drucker_up_to_the_load() {
    let s0 = 0.61;
    for force in [2.0, 8.0, 20.0] {
        // The cantilever of length s₀: k = F s₀²/B, lengths scaled by s₀.
        let reference = CantileverTip::at(force * s0 * s0);
        let at_load = Vector3::new(reference.x * s0, 0.0, reference.z * s0);
        let d3 = Vector3::new(reference.angle.sin(), 0.0, reference.angle.cos());
        let tip = at_load + d3 * (1.0 - s0);
        let rod = loaded_at(s0, force);
        assert_eq!(ModelChoice::for_rod(&rod).level, ModelLevel::Planar);
        for level in UNSHEARABLE_LEVELS {
            for method in EVERY_METHOD {
                let eq = solve_with(&rod, level, method);
                let samples = eq.resample(&rod, &options(method), &[s0, 1.0]).unwrap();
                let (load, end) = (&samples[0], &samples[1]);
                let errors = [
                    (load.position - at_load).norm(),
                    (angle(&load.directors[2]) - reference.angle).abs(),
                    (end.position - tip).norm(),
                    (angle(&end.directors[2]) - reference.angle).abs(),
                    end.curvature.norm(),
                ];
                let worst = errors.iter().copied().fold(0.0, f64::max);
                assert!(
                    worst <= 1e-9,
                    "F = {force}, {level:?}, {method:?}: errors {errors:?}"
                );
            }
        }
    }
}

const ARCH_FULL: &str = include_str!("../../../problems/shallow_arch_full.toml");
const ARCH_HALF: &str = include_str!("../../../problems/shallow_arch_snap.toml");
const STRIP_FULL: &str = include_str!("../../../problems/bistable_strip_full.toml");
const STRIP_HALF: &str = include_str!("../../../problems/bistable_strip_snap.toml");

fn diagram(text: &str, sets: &[&str]) -> Diagram {
    let sets: Vec<String> = sets.iter().map(|s| (*s).to_string()).collect();
    let problem = Problem::from_str_with(text, &sets).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    continuation(&family, &opts, &mut |_, _| true).unwrap()
}

/// The first fold of branch `b` located on the augmented system.
fn first_fold(d: &Diagram, b: usize) -> SpecialPoint {
    d.special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold && s.branch == b)
        .min_by_key(|s| s.index)
        .cloned()
        .expect("a fold")
}

/// The full clamped arch with its crown load as `[[loads.point]]` folds
/// where the half model (crown load P/2 on a guided clamp) folds, P = 2Q,
/// and where the independent elastica shooting folds, to 1e-8 relative;
/// on the full arch the asymmetric branch point (Morse index 1 → 2) comes
/// only after the fold, on the unstable branch, for Θ = 0.3: the limit
/// point governs this low arch.
#[test]
#[cfg_attr(debug_assertions, ignore = "two continuations: seconds in release")]
fn full_arch_loaded_at_its_crown_folds_as_the_half_model() {
    let elastica = arch_elastica_folds(0.3).unwrap();
    let exact = 2.0 * elastica.loads[0];
    let full = diagram(
        ARCH_FULL,
        &[
            "continuation.bounds=[-1.0, 5.0]",
            "continuation.switch_depth=0",
        ],
    );
    let fold = first_fold(&full, 0);
    assert_eq!(fold.location, Location::Augmented);
    let half = diagram(ARCH_HALF, &["continuation.bounds=[-1.0, 3.0]"]);
    let half_fold = 2.0 * first_fold(&half, 0).point.parameter;
    let p = fold.point.parameter;
    eprintln!("full fold {p:.13}, half 2Q {half_fold:.13}, elastica {exact:.13}");
    assert!((p - exact).abs() <= 1e-8 * exact, "{p} vs elastica {exact}");
    assert!(
        (p - half_fold).abs() <= 1e-8 * exact,
        "{p} vs half {half_fold}"
    );
    let branch_point = full
        .special_points
        .iter()
        .find(|s| s.kind == SpecialKind::BranchPoint && s.branch == 0)
        .expect("the asymmetric branch point");
    eprintln!(
        "asymmetric branch point at P = {:.10} after the fold (index {} > {})",
        branch_point.point.parameter, branch_point.index, fold.index
    );
    assert!(branch_point.index > fold.index);
    assert!(branch_point.point.parameter < p);
    let before: Vec<_> = full.branches[0].points[..fold.index]
        .iter()
        .filter(|q| q.parameter > 0.1)
        .collect();
    assert!(before.iter().all(|q| q.stable), "stable up to the fold");
}

/// The full strip with both clamps turned by one linked parameter
/// (`continuation.link`) folds at the half model's and the elastica's α
/// to 1e-8 relative; its in-plane Morse index turns 0 → 1 before the
/// fold: the asymmetric mode comes first, so the full strip loses
/// stability before the symmetric fold (the half model cannot see it).
#[test]
#[cfg_attr(debug_assertions, ignore = "two continuations: seconds in release")]
fn full_strip_turned_by_a_linked_parameter_folds_as_the_half_model() {
    let (exact, _) = strip_elastica_fold(0.9).unwrap();
    let bounds = "continuation.bounds=[-0.9, 0.05]";
    let full = diagram(STRIP_FULL, &[bounds]);
    let half = diagram(STRIP_HALF, &[bounds]);
    let fold_of = |d: &Diagram| {
        let f = d
            .special_points
            .iter()
            .find(|s| s.kind == SpecialKind::Fold)
            .cloned()
            .expect("a fold");
        assert_eq!(f.location, Location::Augmented);
        f
    };
    let (fold, half_fold) = (fold_of(&full), fold_of(&half));
    let alpha = -fold.point.parameter;
    eprintln!(
        "full α {alpha:.13}, half {:.13}, elastica {exact:.13}",
        -half_fold.point.parameter
    );
    assert!((alpha - exact).abs() <= 1e-8 * exact);
    assert!((fold.point.parameter - half_fold.point.parameter).abs() <= 1e-8 * exact);
    let points = &full.branches[fold.branch].points;
    assert_eq!(points[0].morse_index, 0, "the inverted strip is stable");
    let lost = points[..fold.index]
        .iter()
        .position(|q| q.morse_index > 0)
        .expect("stability lost before the fold");
    eprintln!(
        "asymmetric mode: Morse index 0 → 1 between α = {:.6} and {:.6}",
        -points[lost - 1].parameter,
        -points[lost].parameter
    );
    assert!(-points[lost].parameter < alpha);
}

/// A point force's component and a linked parameter are differentiated
/// exactly (the sensitivity equations carried across the jump; the sum of
/// the linked keys' partials), against extrapolated central differences
/// to 1e-9 relative, on single and multiple shooting and on continuation's
/// fixed-mesh collocation (Gauss steps split at the jump).
#[test]
fn point_force_and_linked_parameters_have_exact_derivatives() {
    let cases = [
        (
            ARCH_FULL,
            "continuation.start=1.5",
            "loads.point[0].force[0]",
        ),
        (STRIP_FULL, "continuation.start=0.0", "clamp.angle"),
    ];
    for (text, start, key) in cases {
        for method in ["shooting", "multiple-shooting", "collocation"] {
            let sets = [
                start.to_string(),
                format!("solver.method={method:?}"),
                "solver.segments=5".to_string(),
            ];
            let problem = Problem::from_str_with(text, &sets).unwrap();
            let (family, opts) = problem.continuation.clone().unwrap();
            let p = opts.start;
            assert_eq!(
                family.derivative_method(p).unwrap(),
                DerivativeMethod::Exact,
                "{key}"
            );
            let mut x = family.initial_unknowns(p + 0.3).unwrap();
            for (i, v) in x.iter_mut().enumerate() {
                *v += 0.1 * (1.0 + i as f64).sin();
            }
            let exact = family.parameter_derivative(&x, p).unwrap();
            let fd = richardson_parameter_derivative(&family, &x, p, 1e-2);
            let err = (&exact - &fd).amax();
            assert!(
                err <= 1e-9 * fd.amax(),
                "{key} {method}: |F_p − reference| = {err:e}, |F_p| = {:e}",
                fd.amax()
            );
        }
    }
}

/// A straight clamped column pressed by a dead axial force P at s₀ < L
/// (nothing beyond it) buckles as a clamped–free column of length s₀: the
/// part beyond s₀ carries no force and turns rigidly (ω' = 0 there), so
/// B ω'' + P ω = 0 on [0, s₀], ω(0) = 0, ω'(s₀) = 0 gives
/// P_cr = π² B / (4 s₀²) — at P_cr the lowest eigenvalue of the in-plane
/// block is zero. With s₀ = 0.61 on no uniform mesh's boundary, the
/// elements are graded to put s₀ on one: the eigenvalue must converge at
/// the order-2 elements' rate h⁴ (an element straddling the jump of n(s)
/// would drop it to about h).
#[test]
fn a_column_pressed_inside_buckles_as_the_column_up_to_the_force() {
    let s0 = 0.61;
    let b2 = 1.0;
    let critical = std::f64::consts::PI.powi(2) * b2 / (4.0 * s0 * s0);
    let loads = DeadLoads {
        point_loads: vec![PointLoad::force(s0, Vector3::new(0.0, 0.0, -critical))],
        ..Default::default()
    };
    let rod = support::rods::uniform(1.0, [10.0, b2, 10.0], loads);
    let eq = solve_with(&rod, ModelLevel::Planar, Method::Shooting);
    let solver = options(Method::Shooting);
    let lowest = |elements| {
        let opts = StabilityOptions::new(elements, 2, 2).unwrap();
        let st = cosserat::stability::analyze(&rod, &eq, &solver, &opts).unwrap();
        st.blocks
            .iter()
            .find(|b| b.block == cosserat::stability::Block::InPlane)
            .map(|b| b.eigenvalues[0])
            .unwrap()
    };
    let meshes = [9_usize, 17, 33, 65];
    let errors: Vec<f64> = meshes.iter().map(|&e| lowest(e).abs()).collect();
    for (w, n) in errors.windows(2).zip(meshes.windows(2)) {
        let order = (w[0] / w[1]).ln() / (n[1] as f64 / n[0] as f64).ln();
        assert!(order > 3.5, "errors {errors:?}: measured order {order}");
    }
    assert!(errors[3] < 1e-6 * critical, "errors {errors:?}");
}

/// The field a problem's refusal names.
fn refused_field(text: &str, sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| (*s).to_string()).collect();
    match Problem::from_str_with(text, &sets) {
        Err(ProblemError::Invalid { field, .. }) => field,
        other => panic!("{sets:?}: expected a named refusal, got {other:?}"),
    }
}

/// Hostile point loads and links are refused by the key they come from:
/// a point outside (0, L) or not finite, a non-finite force or couple, a
/// couple on collocation (which does not carry its jump); an unknown, repeated, self-linked or non-numeric linked
/// key, a zero factor, and a file value that is not the link's at the
/// start.
#[test]
fn hostile_point_loads_and_links_are_refused_by_name() {
    let point = [
        (&["loads.point[0].s=0.0"][..], "loads.point[0].s"),
        (&["loads.point[0].s=2.0"][..], "loads.point[0].s"),
        (&["loads.point[0].s=-0.5"][..], "loads.point[0].s"),
        (&["loads.point[0].s=nan"][..], "loads.point[0].s"),
        (
            &["loads.point[0].force[1]=inf"][..],
            "loads.point[0].force[1]",
        ),
        (
            &["loads.point[0].couple=[0.0, nan, 0.0]"][..],
            "loads.point[0].couple[1]",
        ),
        (
            &[
                "loads.point[0].couple=[0.0, 1.0, 0.0]",
                "solver.method=\"collocation\"",
            ][..],
            "loads.point[0].couple",
        ),
    ];
    for (sets, field) in point {
        assert_eq!(refused_field(ARCH_FULL, sets), field, "{sets:?}");
    }
    let link = |l: &str| format!("continuation.link={l}");
    let links = [
        (
            link(r#"[{ key = "support.turn.nope", factor = -1.0 }]"#),
            "continuation.link[0].key",
        ),
        (
            link(r#"[{ key = "support.turn.angle" }, { key = "support.turn.angle" }]"#),
            "continuation.link[1].key",
        ),
        (
            link(r#"[{ key = "clamp.angle" }]"#),
            "continuation.link[0].key",
        ),
        (
            link(r#"[{ key = "support.translation" }]"#),
            "continuation.link[0].key",
        ),
        (
            link(r#"[{ key = "support.turn.angle", factor = 0.0 }]"#),
            "continuation.link[0].factor",
        ),
        (
            link(r#"[{ key = "support.turn.angle", offset = 0.2 }]"#),
            "continuation.link[0]",
        ),
        (
            link(r#"[{ key = "support.turn.angle", fact = 1.0 }]"#),
            "continuation",
        ),
    ];
    for (set, field) in &links {
        let got = match Problem::from_str_with(STRIP_FULL, std::slice::from_ref(set)) {
            Err(ProblemError::Invalid { field, .. }) => field,
            Err(other) => format!("{other}"),
            Ok(_) => panic!("{set}: accepted"),
        };
        assert!(
            got.starts_with(field),
            "{set}: named {got}, expected {field}"
        );
    }
}
