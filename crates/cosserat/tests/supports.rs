//! Rods held at both ends: the clamp at s = 0 and a tip support (pinned,
//! guided, sliding, free to spin). Reactions against linear beam theory,
//! critical loads of columns against their classical values from both the
//! constrained second variation and the BVP Jacobian, and Greenhill's
//! twisted column with clamped ends.
mod support;
use support::methods::methods;

use std::f64::consts::PI;

use cosserat::bvp::{solve, Equilibrium, Method, SolverOptions};
use cosserat::input::Problem;
use cosserat::model::ModelLevel;
use cosserat::references::greenhill_clamped;
use cosserat::stability::{analyze, StabilityOptions};
use support::columns::clamped_pinned;

/// A unit column (B = 1, L = 1) along e3, clamped at the origin, with a tip
/// support and loads given as overrides.
const COLUMN: &str = "[rod]\nlength = 1.0\n[energy]\nstiffness = [1.0, 1.0, 1.0]\n\
                      [support]\naxis = [0.0, 0.0, 1.0]\n";

fn problem(overrides: &[&str]) -> Problem {
    let o: Vec<String> = overrides
        .iter()
        .map(std::string::ToString::to_string)
        .collect();
    Problem::from_str_with(COLUMN, &o).unwrap()
}

fn solve_with(p: &Problem, method: Method) -> Equilibrium {
    let opts = SolverOptions {
        method,
        ..p.options.clone()
    };
    solve(&p.rod, &p.model, &opts).unwrap_or_else(|e| panic!("{method:?}: {e}"))
}

const METHODS: [Method; 3] = methods(4);

/// A tip displaced across by δ: the guided clamp pushes back with 12Bδ/L³
/// and bends the clamp with 6Bδ/L², the sliding pin with 3Bδ/L³ (linear
/// beam theory, up to relative O(δ²)); planar and spatial levels agree.
#[test]
fn reactions_match_beam_theory() {
    let delta = 1e-3;
    for (rotation, force, moment) in [("fixed", 12.0, 6.0), ("free", 3.0, 3.0)] {
        for model in ["auto", "kirchhoff"] {
            let p = problem(&[
                "support.translation=\"axial\"",
                &format!("support.rotation=\"{rotation}\""),
                &format!("support.position=[{delta}, 0.0, 1.0]"),
                &format!("solver.model=\"{model}\""),
            ]);
            for method in METHODS {
                let eq = solve_with(&p, method);
                let reaction = eq.tip().force[0];
                let clamp_moment = eq.samples[0].moment[1].abs();
                assert!(
                    (reaction / (force * delta) - 1.0).abs() < 1e-5,
                    "{rotation} {model} {method:?}: R = {reaction}"
                );
                assert!(
                    (clamp_moment / (moment * delta) - 1.0).abs() < 1e-5,
                    "{rotation} {model} {method:?}: M(0) = {clamp_moment}"
                );
                assert!((eq.tip().position[0] - delta).abs() < 1e-12);
            }
        }
    }
}

/// The lowest eigenvalue of the constrained second variation along the
/// thrust, and the smallest singular value of the BVP Jacobian (the
/// buckling modes of an isotropic or twisted column come in pairs, so the
/// determinant touches zero without changing sign).
struct Column {
    overrides: Vec<String>,
}

impl Column {
    fn at(&self, thrust: f64) -> Problem {
        let mut o: Vec<&str> = self.overrides.iter().map(String::as_str).collect();
        let load = format!("loads.tip_force=[0.0, 0.0, {}]", -thrust);
        o.push(&load);
        problem(&o)
    }

    fn lowest(&self, thrust: f64) -> (f64, f64) {
        let p = self.at(thrust);
        let eq = solve_with(&p, Method::Shooting);
        let opts = StabilityOptions::new(40, 3, 2).unwrap();
        let st = analyze(&p.rod, &eq, &p.options, &opts).unwrap();
        let lowest = st
            .blocks
            .iter()
            .flat_map(|b| b.eigenvalues.iter().copied())
            .fold(f64::INFINITY, f64::min);
        let smallest = eq.jacobian.clone().svd(false, false).singular_values.min();
        (lowest, smallest)
    }

    /// The thrust where the lowest eigenvalue vanishes (secant from a
    /// bracket around `estimate`), where the Jacobian must be singular too:
    /// its smallest singular value drops by more than 1e5 from 0.9 P.
    fn critical(&self, estimate: f64) -> f64 {
        let (mut a, mut b) = (0.9 * estimate, 1.1 * estimate);
        let (mut fa, mut fb) = (self.lowest(a).0, self.lowest(b).0);
        assert!(fa > 0.0 && fb < 0.0, "bracket {fa} {fb}");
        for _ in 0..40 {
            if fb == fa || (b - a).abs() < 1e-14 * b {
                break;
            }
            let c = b - fb * (b - a) / (fb - fa);
            (a, fa) = (b, fb);
            (b, fb) = (c, self.lowest(c).0);
        }
        let (_, away) = self.lowest(0.9 * b);
        let (_, here) = self.lowest(b);
        assert!(
            here < 1e-5 * away,
            "σ_min(F_x) {here} at {b}, {away} at 0.9 P"
        );
        b
    }
}

#[test]
fn columns_buckle_at_their_classical_loads() {
    let cases = [
        // Guided clamp: 4π² B/L².
        ("fixed", "auto", 4.0 * PI * PI),
        ("fixed", "kirchhoff", 4.0 * PI * PI),
        // Sliding pin: x² with tan x = x.
        ("free", "auto", clamped_pinned()),
        ("free", "kirchhoff", clamped_pinned()),
    ];
    for (rotation, model, reference) in cases {
        let column = Column {
            overrides: vec![
                "support.translation=\"axial\"".into(),
                format!("support.rotation=\"{rotation}\""),
                format!("solver.model=\"{model}\""),
            ],
        };
        let p = column.critical(reference);
        assert!(
            (p - reference).abs() / reference < 1e-9,
            "{rotation} {model}: {p} vs {reference}"
        );
    }
}

/// Greenhill with clamped ends: the tip slides along and spins about the
/// axis under a thrust P and an axial torque M; the critical thrust for
/// M L/B = 2 and 5 from the characteristic determinant.
#[test]
fn twisted_column_buckles_at_greenhill_load() {
    for torque in [2.0, 5.0] {
        let reference = greenhill_clamped(torque);
        let column = Column {
            overrides: vec![
                "support.translation=\"axial\"".into(),
                "support.rotation=\"axial\"".into(),
                format!("loads.tip_couple=[0.0, 0.0, {torque}]"),
            ],
        };
        assert_eq!(column.at(1.0).model.level, ModelLevel::Kirchhoff);
        let p = column.critical(reference);
        assert!(
            (p - reference).abs() / reference < 1e-8,
            "M = {torque}: {p} vs {reference}"
        );
    }
}

/// Bad supports are errors naming the field.
#[test]
fn bad_supports_name_the_field() {
    let err = |o: &[&str]| {
        let o: Vec<String> = o.iter().map(std::string::ToString::to_string).collect();
        Problem::from_str_with(COLUMN, &o).unwrap_err().to_string()
    };
    assert!(err(&["support.translation=\"sideways\""]).contains("support.translation"));
    assert!(err(&["support.axis=[0.0, 0.0, 2.0]"]).contains("support.axis"));
    let no_axis = "[rod]\nlength = 1.0\n[energy]\nstiffness = [1.0, 1.0, 1.0]\n\
                   [support]\nrotation = \"axial\"\n";
    let e = Problem::from_str_with(no_axis, &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("support.axis"), "{e}");
    assert!(
        err(&["support.translation=\"free\"", "support.rotation=\"free\""]).contains("support")
    );
    assert!(err(&["support.position=[0.0, nan, 1.0]"]).contains("support.position"));
}

/// A hinged base (clamp.hinge): the pinned–pinned column buckles at π² B/L²
/// (Euler's fundamental case) and the pinned–guided one, a clamped–pinned
/// column turned round, at x² with tan x = x; the hinge is refused where
/// the planar model cannot run.
#[test]
fn hinged_base_columns_buckle_at_their_classical_loads() {
    for (rotation, reference) in [("free", PI * PI), ("fixed", clamped_pinned())] {
        let column = Column {
            overrides: vec![
                "clamp.hinge=true".into(),
                "support.translation=\"axial\"".into(),
                format!("support.rotation=\"{rotation}\""),
            ],
        };
        assert_eq!(column.at(1.0).model.level, ModelLevel::Planar);
        let p = column.critical(reference);
        assert!(
            (p - reference).abs() / reference < 1e-9,
            "hinge + {rotation}: {p} vs {reference}"
        );
    }
    let spatial = ["clamp.hinge=true", "loads.tip_couple=[0.0, 0.0, 1.0]"];
    let o: Vec<String> = spatial
        .iter()
        .map(std::string::ToString::to_string)
        .collect();
    let e = Problem::from_str_with(COLUMN, &o).unwrap_err().to_string();
    assert!(e.contains("clamp.hinge"), "{e}");
}
