//! `cosserat continue problems/shallow_arch_snap.toml`: the shallow arch
//! snaps through at a fold of the half crown load, reported as a fold
//! located on the minimally augmented system, at the elastica's fold
//! (`cosserat::references::arch_elastica_folds`, an independent shooting)
//! to 1e-10 relative; the diagram file records how each fold was located
//! and the resume reader reads it back. The buckled strip turned at its
//! clamps (problems/bistable_strip_snap.toml) likewise, at the elastica's
//! fold angle (`strip_elastica_fold`).
mod common;

use common::problems::shipped;
use common::run::{scratch, BIN};
use cosserat::continuation::Location;
use cosserat::output::read_saved;
use cosserat::references::{arch_elastica_folds, strip_elastica_fold};

/// The shipped arch's half-angle Θ (its `energy.intrinsic_curvature[1]`).
const THETA: f64 = 0.3;

#[test]
fn shallow_arch_reports_its_snap_through_fold_at_the_elastica_value() {
    let dir = scratch("snap", "arch");
    let out = dir.join("arch.h5");
    let o = std::process::Command::new(BIN)
        .args([
            "continue",
            &shipped("shallow_arch_snap"),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    let folds: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("special") && l.contains(" fold "))
        .collect();
    assert_eq!(folds.len(), 2, "{stdout}");
    let reference = arch_elastica_folds(THETA).unwrap().loads;
    for (line, exact) in folds.iter().zip(reference) {
        assert!(line.ends_with("located augmented"), "{line}");
        let printed: f64 = line
            .split("at parameter ")
            .nth(1)
            .and_then(|r| r.split(',').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no parameter in {line}"));
        // Printed to 12 decimals; located to 1e-10.
        assert!(
            (printed - exact).abs() <= 1e-10 * exact,
            "{printed} vs the elastica {exact}"
        );
    }
    let (_, saved) = read_saved(&out).unwrap();
    assert_eq!(saved.specials.len(), 2);
    assert!(saved
        .specials
        .iter()
        .all(|s| s.location == Location::Augmented));
}

#[test]
fn buckled_strip_reports_its_fold_at_the_elastica_angle() {
    let dir = scratch("snap", "strip");
    let out = dir.join("strip.h5");
    let o = std::process::Command::new(BIN)
        .args([
            "continue",
            &shipped("bistable_strip_snap"),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let folds: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("special") && l.contains(" fold "))
        .collect();
    assert_eq!(folds.len(), 1, "{stdout}");
    assert!(folds[0].ends_with("located augmented"), "{}", folds[0]);
    let printed: f64 = folds[0]
        .split("at parameter ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no parameter in {}", folds[0]));
    // clamp.angle = −α: a negative angle raises the clamp's tangent.
    let (alpha, _) = strip_elastica_fold(0.9).unwrap();
    assert!(
        (printed + alpha).abs() <= 1e-10 * alpha,
        "{printed} vs the elastica −{alpha}"
    );
}
