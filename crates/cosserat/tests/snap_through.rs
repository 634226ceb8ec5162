//! Snap-through of a shallow circular arch under a central point load
//! (problems/shallow_arch_snap.toml: the left half of a clamped arch, its
//! crown a guided clamp carrying half the load Q = P/2; B = ℓ = 1).
//!
//! Two independent references, neither from the code under test
//! (`cosserat::references::arch`): a shooting of the planar elastica by
//! RK4 with Richardson's extrapolation (the folds where dQ/dy = 0 along the
//! crown height y), and the inextensible shallow-arch theory, the limit
//! Θ → 0 of the fold load over Θ.

use cosserat::continuation::{continuation, Diagram, Location, SpecialKind};
use cosserat::input::Problem;
use cosserat::references::{arch_elastica_folds, shallow_arch_fold, strip_elastica_fold};

const ARCH: &str = include_str!("../../../problems/shallow_arch_snap.toml");

/// The shipped arch's half-angle Θ.
const THETA: f64 = 0.3;

/// The shipped arch with half-angle Θ: curvature, clamp angle and crown.
fn arch(theta: f64) -> Problem {
    let crown = [-(1.0 - theta.cos()) / theta, theta.sin() / theta];
    let sets = [
        format!("energy.intrinsic_curvature[1]={theta}"),
        format!("clamp.angle={}", -theta),
        format!("support.position[0]={}", crown[0]),
        format!("support.position[2]={}", crown[1]),
        format!("continuation.bounds=[-1.0, {}]", 10.0 * theta),
    ];
    Problem::from_str_with(ARCH, &sets).unwrap()
}

fn diagram(problem: &Problem) -> Diagram {
    let (family, opts) = problem.continuation.clone().unwrap();
    continuation(&family, &opts, &mut |_, _| true).unwrap()
}

/// The folds of branch 0, in the order they were passed.
fn folds(d: &Diagram) -> Vec<(f64, Location)> {
    let mut f: Vec<_> = d
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold && s.branch == 0)
        .map(|s| (s.index, s.point.parameter, s.location))
        .collect();
    f.sort_by_key(|s| s.0);
    f.into_iter().map(|(_, p, l)| (p, l)).collect()
}

/// The shipped arch snaps at the elastica's fold and restabilizes at its
/// second fold, both located on the minimally augmented system to 1e-10
/// relative (measured: 3e-12 and 1e-11); the stable branch loses
/// stability at the first.
#[test]
fn shallow_arch_folds_are_located_to_1e_10_against_the_elastica() {
    let elastica = arch_elastica_folds(THETA).unwrap();
    let reference = elastica.loads;
    let bound = elastica.correction;
    assert!(bound < 1e-10, "Richardson correction {bound:e}");
    let d = diagram(&arch(THETA));
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let found = folds(&d);
    assert_eq!(found.len(), 2, "{found:?}");
    for ((p, location), exact) in found.iter().zip(&reference) {
        assert_eq!(*location, Location::Augmented);
        let error = (p - exact).abs() / exact;
        eprintln!("fold {p:.14} vs elastica {exact:.14}: relative {error:.1e}");
        assert!(error <= 1e-10, "fold {p} vs {exact}: {error:e}");
    }
    // Each fold's stated error (located again at integration tolerances
    // 100× tighter) bounds its actual one within a factor 2 and the
    // reference's own error.
    for sp in d
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold)
    {
        let estimate = sp.parameter_error.expect("an augmented fold's error");
        let actual = reference
            .iter()
            .map(|r| (sp.point.parameter - r).abs())
            .fold(f64::INFINITY, f64::min);
        assert!(
            actual <= 2.0 * estimate + bound,
            "{actual:e} > 2 × {estimate:e}"
        );
    }
    // Before the snap the arch is stable, after it unstable.
    let points = &d.branches[0].points;
    let first = points
        .iter()
        .position(|q| q.parameter > 0.5 * reference[0])
        .unwrap();
    assert!(points[first].stable);
    let beyond = points
        .windows(2)
        .position(|w| w[1].parameter < w[0].parameter)
        .unwrap();
    assert!(!points[beyond + 2].stable, "unstable past the snap");
}

/// The shipped file (Θ = 0.3) is within 1e-10 of the elastica whose fold
/// it states in its comment.
#[test]
fn the_shipped_numbers_are_the_elastica_fold() {
    let reference = arch_elastica_folds(THETA).unwrap().loads;
    assert!(
        (reference[0] - 2.231_578_884_9).abs() < 1e-10,
        "{}",
        reference[0]
    );
    assert!(
        (reference[1] - 0.785_268_0).abs() < 1e-7,
        "{}",
        reference[1]
    );
}

/// As the arch flattens the fold load over Θ tends to the inextensible
/// shallow-arch value q* = 7.41543, at order Θ² (measured orders 2.00,
/// 2.00 from Θ = 0.2, 0.1, 0.05); each fold also within 1e-9 of the
/// elastica at its Θ.
#[test]
fn the_fold_tends_to_shallow_arch_theory_at_order_two() {
    let limit = shallow_arch_fold();
    assert!((limit - 7.415_43).abs() < 1e-5, "q* = {limit}");
    let thetas = [0.2, 0.1, 0.05];
    let mut errors = vec![];
    for &theta in &thetas {
        let d = diagram(&arch(theta));
        let (p, location) = folds(&d)[0];
        assert_eq!(location, Location::Augmented);
        let reference = arch_elastica_folds(theta).unwrap().loads;
        assert!(
            (p - reference[0]).abs() <= 1e-9 * reference[0],
            "Θ = {theta}: {p} vs {}",
            reference[0]
        );
        errors.push((p / theta - limit).abs());
    }
    for (i, pair) in errors.windows(2).enumerate() {
        let order = (pair[0] / pair[1]).ln() / (thetas[i] / thetas[i + 1]).ln();
        eprintln!(
            "Θ {} → {}: error {:.3e} → {:.3e}, order {order:.3}",
            thetas[i],
            thetas[i + 1],
            pair[0],
            pair[1]
        );
        assert!((order - 2.0).abs() < 0.1, "order {order}");
    }
}

/// The same folds on the collocation discretization (64 intervals of 3
/// Gauss points, 381 unknowns: the banded corrector, a dense augmented
/// system once per fold) are located on the augmented system too, to the
/// method's own error (measured 4e-12 and 1e-11 relative; 2.5e-11 at 48
/// intervals, the order-6 ratio).
#[test]
fn collocation_folds_are_located_on_the_augmented_system() {
    let sets = [
        "solver.method=collocation",
        "continuation.intervals=64",
        "continuation.max_points=1500",
        "continuation.max_step=0.4",
        "continuation.bounds=[-1.0, 2.5]",
    ]
    .map(String::from);
    let problem = Problem::from_str_with(ARCH, &sets).unwrap();
    let d = diagram(&problem);
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    assert!(
        d.branches[0].points[0].unknowns.len() > 200,
        "the banded path"
    );
    let reference = arch_elastica_folds(THETA).unwrap().loads;
    let found = folds(&d);
    assert_eq!(found.len(), 2, "{found:?}");
    for ((p, location), exact) in found.iter().zip(&reference) {
        assert_eq!(*location, Location::Augmented);
        assert!((p - exact).abs() <= 1e-10 * exact, "{p} vs {exact}");
    }
}

/// Each fold located on a coarse collocation mesh carries its
/// discretization error: its `parameter_error` (the fold located again on
/// twice the intervals, Richardson-scaled) matches the actual error
/// against the elastica within 10 % (measured on 16 intervals of order 6:
/// 4.0e-8 and 4.1e-8 against 4.01e-8 and 4.12e-8), far above the
/// reference's own error and the location tolerance; and the branch is
/// reported as outgrowing its mesh (on 64 intervals, where the folds are
/// right to 1e-10, it is not: the test above).
#[test]
#[cfg_attr(debug_assertions, ignore = "a collocation diagram: release only")]
fn collocation_folds_carry_their_discretization_error() {
    let sets = [
        "solver.method=collocation",
        "continuation.intervals=16",
        "continuation.max_points=1500",
        "continuation.max_step=0.4",
        "continuation.bounds=[-1.0, 2.5]",
    ]
    .map(String::from);
    let problem = Problem::from_str_with(ARCH, &sets).unwrap();
    let d = diagram(&problem);
    // The mesh is too coarse for the collocation tolerance 1e-10, and the
    // diagram says so — once, for its one branch.
    assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
    assert!(
        d.warnings[0].starts_with("branch 0: its most deformed point")
            && d.warnings[0].contains("raise continuation.intervals"),
        "{:?}",
        d.warnings
    );
    let elastica = arch_elastica_folds(THETA).unwrap();
    assert!(elastica.correction < 1e-10);
    let mut folds: Vec<_> = d
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold && s.branch == 0)
        .collect();
    folds.sort_by_key(|s| s.index);
    assert_eq!(folds.len(), 2);
    for (sp, exact) in folds.iter().zip(&elastica.loads) {
        assert_eq!(sp.location, Location::Augmented);
        let actual = (sp.point.parameter - exact).abs();
        let estimate = sp.parameter_error.expect("an augmented fold's error");
        eprintln!(
            "fold {:.12}: error {actual:.3e}, estimate {estimate:.3e}",
            sp.point.parameter
        );
        assert!(actual > 1e-9, "a mesh coarse enough to show its error");
        assert!(
            (estimate / actual - 1.0).abs() <= 0.1,
            "estimate {estimate:e} against {actual:e}"
        );
    }
}

/// The inverted buckled strip (problems/bistable_strip_snap.toml) snaps
/// when its clamps are turned up by the elastica's fold angle, located on
/// the augmented system to 1e-10 relative (measured 3e-13); the start is
/// the inverted state (the crown below the clamps) and stable.
#[test]
fn buckled_strip_snaps_at_the_elastica_fold_angle() {
    const STRIP: &str = include_str!("../../../problems/bistable_strip_snap.toml");
    let (exact, correction) = strip_elastica_fold(0.9).unwrap();
    assert!(correction < 1e-10, "Richardson correction {correction:e}");
    let d = diagram(&Problem::from_str_with(STRIP, &[]).unwrap());
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let start = &d.branches[0].points[0];
    assert!(
        start.measures[0] > 0.1,
        "inverted: crown {}",
        start.measures[0]
    );
    assert!(start.stable);
    let found: Vec<_> = d
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold)
        .collect();
    assert_eq!(found.len(), 1, "one fold");
    assert_eq!(found[0].location, Location::Augmented);
    // clamp.angle turns the tangent towards d1 (down): −α raises it.
    let alpha = -found[0].point.parameter;
    let error = (alpha - exact).abs() / exact;
    eprintln!("fold α {alpha:.14} vs elastica {exact:.14}: relative {error:.1e}");
    assert!(error <= 1e-10, "α {alpha} vs {exact}");
    assert!(
        (exact - 0.643_051_6).abs() < 1e-7,
        "the file's comment: {exact}"
    );
}

/// Large systems: multiple shooting on 260 segments (1557 unknowns) and
/// collocation on 400 intervals (2397 unknowns) locate both folds on the
/// augmented system, solved in F_x's band shape (`continuation/
/// bordering.rs`; it used to be dense up to 1000 unknowns, the bracketed
/// root kept beyond, 1.9e-9 off), to 1e-10 of the elastica.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "two large diagrams, ≈ 5 s in release: run with --release"
)]
fn large_systems_locate_their_folds_on_the_augmented_system() {
    let reference = arch_elastica_folds(THETA).unwrap().loads;
    let run = |method: &[String]| {
        let mut sets = method.to_vec();
        sets.extend(
            [
                "continuation.max_points=3000",
                "continuation.max_step=2.0",
                "continuation.bounds=[-1.0, 2.5]",
            ]
            .map(String::from),
        );
        diagram(&Problem::from_str_with(ARCH, &sets).unwrap())
    };
    let shooting = [
        "solver.method=multiple-shooting".to_string(),
        "solver.segments=260".to_string(),
    ];
    let collocation = [
        "solver.method=collocation".to_string(),
        "continuation.intervals=400".to_string(),
    ];
    for method in [&shooting[..], &collocation[..]] {
        let d = run(method);
        let size = d.branches[0].points[0].unknowns.len();
        assert!(size > 1500, "{method:?}: {size} unknowns");
        assert!(d.warnings.is_empty(), "{method:?}: {:?}", d.warnings);
        let found = folds(&d);
        assert_eq!(found.len(), 2, "{found:?}");
        for ((p, location), exact) in found.iter().zip(&reference) {
            eprintln!("{method:?}, {size} unknowns: fold {p} against {exact}");
            assert_eq!(*location, Location::Augmented);
            assert!((p - exact).abs() <= 1e-10 * exact, "{p} vs {exact}");
        }
    }
}
