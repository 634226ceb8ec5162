//! Branches of symmetric copies (an isotropic rod's buckled shapes turned
//! about its axis) are followed in a slice: the phase condition keeps each
//! point transverse to its copies, so the four branches switched off a
//! double branch point — two kernel directions, both ways — are congruent:
//! copies of one another, they turn at the same fold to 1e-9 and end at the
//! same bound, with no event left unlocated. Before the slice, Greenhill's
//! branches drifted along their copies at a nearly constant load (folds
//! that could not be located), and none started off the twisted rod's
//! double point.

use cosserat::continuation::{continuation, Diagram, SpecialKind};
use cosserat::input::Problem;

fn run(text: &str, set: &[&str]) -> Diagram {
    let set: Vec<String> = set.iter().map(ToString::to_string).collect();
    let problem = Problem::from_str_with(text, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    continuation(&family, &opts, &mut |_, _| true).unwrap()
}

fn congruent(d: &Diagram) {
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let children = &d.special_points[0].children;
    assert_eq!(children.len(), 4, "two kernel directions, both ways");
    let ends: Vec<f64> = children
        .iter()
        .map(|&c| d.branches[c].points.last().unwrap().parameter)
        .collect();
    let folds: Vec<f64> = d
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold)
        .map(|s| s.point.parameter)
        .collect();
    for f in &folds {
        assert!((f - folds[0]).abs() <= 1e-9 * folds[0].abs(), "{folds:?}");
    }
    for e in &ends {
        assert!(
            (e - ends[0]).abs() <= 1e-6 * ends[0].abs().max(1.0),
            "{ends:?}"
        );
    }
}

#[test]
fn greenhill_branches_are_congruent_copies() {
    let d = run(
        include_str!("../../../problems/greenhill.toml"),
        &["continuation.max_points=60"],
    );
    congruent(&d);
    let folds = d
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold)
        .count();
    assert_eq!(folds, 4, "each copy turns at its fold");
}

#[test]
fn the_twisted_rod_switches_onto_its_buckled_copies() {
    let d = run(
        include_str!("../../../problems/twisted_rod.toml"),
        &["continuation.max_points=30"],
    );
    congruent(&d);
}
