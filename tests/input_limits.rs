//! Issue 14, the input side: every number of a problem file has a
//! meaningful range and every array its length; what falls outside is
//! refused before any work, with the key's name, the allowed range and
//! what to do. Where a bad count could reach a computation, the
//! computation returns an error instead of panicking.

use cosserat::io::Problem;
mod support;
use support::references::cantilever_tip;

/// A planar cantilever under a tip load: the smallest valid problem.
const CANTILEVER: &str = "
[rod]
length = 1.0
[energy]
stiffness = [1.0, 1.0, 1.0]
[loads]
tip_force = [1.0, 0.0, 0.0]
";

/// The error text of `text` with `overrides`; panics when accepted.
fn refusal(text: &str, overrides: &[&str]) -> String {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    match Problem::from_str_with(text, &overrides) {
        Ok(_) => panic!("accepted: {overrides:?}"),
        Err(e) => e.to_string(),
    }
}

fn accepted(text: &str, overrides: &[&str]) -> Problem {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Problem::from_str_with(text, &overrides).unwrap_or_else(|e| panic!("{overrides:?}: {e}"))
}

/// A problem with every optional table present, so that every
/// fixed-length key can be overridden.
const EVERY_TABLE: &str = "
[rod]
length = 1.0
[energy]
stiffness = [1.0, 1.0, 1.0]
intrinsic_curvature = [0.0, 0.0, 0.0]
shear = [100.0, 100.0, 100.0]
[clamp]
position = [0.0, 0.0, 0.0]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [1.0, 0.0, 0.0]
tip_couple = [0.0, 0.0, 0.0]
distributed_force = [0.0, 0.0, 0.0]
[solver]
initial_curvature = [0.0, 0.0, 0.0]
[continuation]
parameter = \"load_scale\"
start = 0.1
bounds = [0.0, 1.0]
";

/// Item 8: every fixed-length array of every table refuses a longer or a
/// shorter array, naming the key and the expected length.
#[test]
fn every_fixed_length_key_takes_exactly_its_length() {
    let three = [
        "energy.stiffness",
        "energy.intrinsic_curvature",
        "energy.shear",
        "clamp.position",
        "clamp.d1",
        "clamp.d3",
        "loads.tip_force",
        "loads.tip_couple",
        "loads.distributed_force",
        "solver.initial_curvature",
    ];
    // The base is accepted as written.
    accepted(EVERY_TABLE, &[]);
    for key in three {
        for (value, got) in [("[1, 0, 0, 5]", 4), ("[1, 0]", 2), ("[]", 0)] {
            let e = refusal(EVERY_TABLE, &[&format!("{key}={value}")]);
            assert!(
                e.contains(key) && e.contains("expected exactly 3") && e.contains(&got.to_string()),
                "{key}={value}: {e}"
            );
        }
    }
    for (value, got) in [("[0, 1, 2]", 3), ("[0]", 1)] {
        let e = refusal(EVERY_TABLE, &[&format!("continuation.bounds={value}")]);
        assert!(
            e.contains("continuation.bounds") && e.contains("expected exactly 2"),
            "{got}: {e}"
        );
    }
    // Support vectors (optional keys of an optional table).
    for key in [
        "support.axis",
        "support.position",
        "support.d1",
        "support.d3",
    ] {
        let e = refusal(
            CANTILEVER,
            &[
                "support.translation=\"axial\"",
                "support.axis=[0, 0, 1]",
                &format!("{key}=[0, 0, 1, 0]"),
            ],
        );
        assert!(
            e.contains(key) && e.contains("expected exactly 3"),
            "{key}: {e}"
        );
    }
}

/// The example in a file (not through `--set`): the message names
/// the key, the lengths and the line of the file.
#[test]
fn a_four_entry_tip_force_in_a_file_is_refused_with_its_line() {
    let text = CANTILEVER.replace(
        "tip_force = [1.0, 0.0, 0.0]",
        "tip_force = [1.0, 0.0, 0.0, 4.0]",
    );
    let e = refusal(&text, &[]);
    assert!(
        e.contains("loads.tip_force")
            && e.contains("has 4 entries, expected exactly 3")
            && e.contains("line 7"),
        "{e}"
    );
}

/// Arrays of pairs and the sweep's `[start, stop, count]`.
#[test]
fn arm_bounds_and_sweep_spacings_take_exactly_their_length() {
    let arm = format!(
        "{CANTILEVER}
[arm]
coefficients = 3
bounds = [[-4.0, 4.0], [-2.0, 2.0, 7.0]]
"
    );
    let e = refusal(&arm, &[]);
    assert!(
        e.contains("arm.bounds[1]") && e.contains("expected exactly 2"),
        "{e}"
    );
    for kind in ["linspace", "logspace"] {
        let sweep = format!(
            "{CANTILEVER}
[sweep]
axes = [{{ key = \"loads.tip_force[0]\", {kind} = [1.0, 2.0, 3, 4] }}]
"
        );
        let e = refusal(&sweep, &[]);
        assert!(
            e.contains(&format!("sweep.axes[0].{kind}")) && e.contains("expected exactly 3"),
            "{e}"
        );
    }
}

/// Item 7: `solver.tolerance = 1` "converged" to a wrong shape. Every
/// tolerance-like key is refused outside its documented range, with the
/// key, the range and a value to choose; both ends are accepted.
#[test]
fn every_tolerance_has_a_meaningful_range() {
    let e = refusal(CANTILEVER, &["solver.tolerance=1"]);
    assert!(
        e.contains("solver.tolerance") && e.contains("outside [1e-15, 1e-6]") && e.contains("e.g."),
        "{e}"
    );
    let continued = format!(
        "{CANTILEVER}
[continuation]
parameter = \"load_scale\"
start = 0.1
bounds = [0.0, 1.0]
"
    );
    for (key, lo, hi) in [
        ("solver.tolerance", "1e-15", "1e-6"),
        ("solver.integration_tolerance", "1e-14", "1e-6"),
        ("solver.collocation_tolerance", "1e-14", "1e-6"),
        ("continuation.tolerance", "1e-15", "1e-6"),
    ] {
        for v in [lo, hi] {
            accepted(&continued, &[&format!("{key}={v}")]);
        }
        for v in ["2e-6", "1", "1e300", "1e-16", "0", "-1e-10", "nan", "inf"] {
            let e = refusal(&continued, &[&format!("{key}={v}")]);
            assert!(
                e.contains(key) && e.contains(&format!("[{lo}, {hi}]")),
                "{key}={v}: {e}"
            );
        }
    }
    // The tip angle is at most 180°: a larger limit would never act.
    for v in ["181", "0", "-5", "inf"] {
        let e = refusal(&continued, &[&format!("continuation.tip_angle_limit={v}")]);
        assert!(
            e.contains("continuation.tip_angle_limit") && e.contains("(0, 180]"),
            "{e}"
        );
    }
    accepted(&continued, &["continuation.tip_angle_limit=180"]);
    // A zero step budget was silently raised to 1.
    let e = refusal(CANTILEVER, &["solver.max_steps=0"]);
    assert!(e.contains("solver.max_steps"), "{e}");
}

/// At the loosest tolerances accepted (Newton 1e-6, integration 1e-6) the
/// answer is still right to the digits the range promises: the planar
/// cantilever's tip against Bisshopp & Drucker's elliptic integrals.
#[test]
fn the_loosest_tolerances_accepted_still_give_the_elastica() {
    let p = accepted(
        CANTILEVER,
        &[
            "loads.tip_force=[3, 0, 0]",
            "solver.tolerance=1e-6",
            "solver.integration_tolerance=1e-6",
        ],
    );
    let eq = cosserat::bvp::solve(&p.rod, &p.model, &p.options).unwrap();
    let tip = eq.samples.last().unwrap().position;
    let exact = cantilever_tip(3.0);
    let err = (tip[0] - exact.x).abs().max((tip[2] - exact.z).abs());
    eprintln!("tip error at the loosest tolerances: {err:.2e}");
    assert!(err < 1e-5, "{err:e}");
}

/// Item 9: an arm hanging straight down is in tension, stable under any
/// load: its fixed shape has no critical load (the search had reported a
/// γ_crit of 3e20, a number of round-off).
#[test]
fn a_hanging_arm_has_no_critical_load() {
    use cosserat::model::{Clamp, DeadLoads, LinearElastic, Profile, Rod};
    use cosserat::stability::{critical_load, FixedShape, StabilityOptions};
    use nalgebra::Vector3;
    for (b1, b3) in [(4.0, 1.27), (1.0, 1.0), (0.25, 4.0)] {
        let rod = Rod {
            length: 1.0,
            energy: std::sync::Arc::new(LinearElastic::uniform([b1, 1.0, b3], [0.0; 3])),
            clamp: Clamp::paper(),
            loads: DeadLoads {
                tip_force: Vector3::new(1.0, 0.0, 0.0),
                tip_couple: Vector3::zeros(),
                distributed_force: Vector3::zeros(),
            },
            support: None,
        };
        // φ = π/2 from the horizontal d3 towards d1 (down): hanging.
        let shape = FixedShape {
            turning_angle: Profile::Constant(std::f64::consts::FRAC_PI_2),
        };
        let opts = StabilityOptions {
            elements: 100,
            order: 1,
            eigenvalues: 1,
        };
        let crit = critical_load(&rod, &shape, &opts).unwrap();
        assert_eq!(
            crit.load_factor, None,
            "B̄ = ({b1}, {b3}): {:?}",
            crit.load_factor
        );
    }
}

/// Item 9: every reach direction has a meaning or is refused. Straight
/// down (−90°) is unbounded; near it the reach grows like 4/|cos α|,
/// resolved by a mesh of N elements only while |cos α| ≥ 8/N; beyond ±90°
/// the arm reaches to the other side.
#[test]
fn arm_reach_directions_are_defined_or_refused() {
    let arm = format!(
        "{CANTILEVER}
[arm]
coefficients = 3
bounds = [[-4.0, 4.0], [-2.0, 2.0]]
"
    );
    for alpha in ["-90", "-89.9", "-86", "-94", "-181", "200", "nan"] {
        let e = refusal(&arm, &[&format!("arm.alpha={alpha}")]);
        assert!(e.contains("arm.alpha"), "{alpha}: {e}");
        if alpha == "-90" {
            assert!(
                e.contains("unbounded") && e.contains("−85.4") && e.contains("arm.elements"),
                "{e}"
            );
        }
    }
    // |cos α| ≥ 8/N: −85.4° at N = 100 (cos 85.4° = 0.0802), −88.85° at 400.
    for alpha in ["-85", "-95", "0", "90", "120", "180", "-180", "-60"] {
        accepted(&arm, &[&format!("arm.alpha={alpha}")]);
    }
    let e = refusal(&arm, &["arm.alpha=-88"]);
    assert!(e.contains("arm.alpha"), "{e}");
    accepted(&arm, &["arm.alpha=-88", "arm.elements=400"]);
    let e = refusal(&arm, &["arm.alpha=-88.9", "arm.elements=400"]);
    assert!(e.contains("arm.alpha"), "{e}");
}
