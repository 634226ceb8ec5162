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
        let (located, printed, error) = common::run::special_line(line);
        assert_eq!(located, "augmented", "{line}");
        // Printed to 12 decimals; located to 1e-10, with its stated
        // discretization error below that and within a factor 2 of the
        // actual one (plus the printed rounding).
        assert!(
            (printed - exact).abs() <= 1e-10 * exact,
            "{printed} vs the elastica {exact}"
        );
        let error = error.unwrap_or_else(|| panic!("no error stated: {line}"));
        assert!(error <= 1e-10 * exact, "{line}");
        assert!(
            (printed - exact).abs() <= 2.0 * error + 1e-12,
            "{line} vs {exact}"
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
    let (located, printed, error) = common::run::special_line(folds[0]);
    assert_eq!(located, "augmented", "{}", folds[0]);
    assert!(error.is_some(), "no error stated: {}", folds[0]);
    // clamp.angle = −α: a negative angle raises the clamp's tangent.
    let (alpha, _) = strip_elastica_fold(0.9).unwrap();
    assert!(
        (printed + alpha).abs() <= 1e-10 * alpha,
        "{printed} vs the elastica −{alpha}"
    );
}
