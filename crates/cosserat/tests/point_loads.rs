//! Interior point loads (`[[loads.point]]`) against closed forms: a
//! cantilever loaded at s₀ < L by a force and nothing at its tip is
//! Bisshopp and Drucker's cantilever of length s₀ (the elliptic integrals of
//! `cosserat::references::cantilever_tip`) followed by a straight piece —
//! an exact check that every method stops at the jump of n(s).
mod support;

use cosserat::bvp::{solve, Equilibrium, Method, SolverOptions};
use cosserat::continuation::{continuation, Diagram, Location, SpecialKind, SpecialPoint};
use cosserat::input::Problem;
use cosserat::model::{DeadLoads, ModelChoice, ModelLevel, PointForce, Rod};
use cosserat::references::CantileverTip;
use cosserat::references::{arch_elastica_folds, strip_elastica_fold};
use nalgebra::Vector3;

/// Every method; 8 segments and the default collocation mesh put no node at
/// s₀ = 0.61 of their own.
const METHODS: [Method; 4] = [
    Method::Shooting,
    Method::MultipleShooting { segments: 8 },
    Method::Collocation { stages: 2 },
    Method::Collocation { stages: 3 },
];
const LEVELS: [ModelLevel; 2] = [ModelLevel::Planar, ModelLevel::Kirchhoff];

/// L = 1, B = (10, 1, 10), the paper's clamp (d1(0) = e1 down), the force
/// F e1 at s₀.
fn loaded_at(s0: f64, force: f64) -> Rod {
    let loads = DeadLoads {
        point_forces: vec![PointForce {
            s: s0,
            force: Vector3::new(force, 0.0, 0.0),
        }],
        ..Default::default()
    };
    support::rods::uniform(1.0, [10.0, 1.0, 10.0], loads)
}

fn options(method: Method) -> SolverOptions {
    SolverOptions {
        method,
        ..Default::default()
    }
}

fn solve_with(rod: &Rod, level: ModelLevel, method: Method) -> Equilibrium {
    let choice = ModelChoice::forced(rod, level).unwrap();
    solve(rod, &choice, &options(method)).unwrap_or_else(|e| panic!("{level:?} {method:?}: {e}"))
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
        for level in LEVELS {
            for method in METHODS {
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
