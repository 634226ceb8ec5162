//! Issue 14, the input side: every number of a problem file has a
//! meaningful range and every array its length; what falls outside is
//! refused before any work, with the key's name, the allowed range and
//! what to do. Counts and sizes that could reach a computation are in
//! input_budgets.rs.

mod common;

use common::problems::{accepted, refusal, shipped_text, CANTILEVER};
use cosserat::references::CantileverTip;

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
    let exact = CantileverTip::at(3.0);
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
        let rod = Rod::new(
            1.0,
            std::sync::Arc::new(LinearElastic::uniform([b1, 1.0, b3], [0.0; 3]).unwrap()),
            Clamp::paper(),
            DeadLoads {
                tip_force: Vector3::new(1.0, 0.0, 0.0),
                tip_couple: Vector3::zeros(),
                distributed_force: Vector3::zeros(),
                point_loads: Vec::new(),
            },
            None,
        )
        .unwrap();
        // φ = π/2 from the horizontal d3 towards d1 (down): hanging.
        let shape = FixedShape {
            turning_angle: Profile::Constant(std::f64::consts::FRAC_PI_2),
        };
        let opts = StabilityOptions::new(100, 1, 1).unwrap();
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
    for key in ["arm.starts", "arm.iterations", "arm.samples"] {
        let e = refusal(&arm, &[&format!("{key}=0")]);
        assert!(e.contains(key), "{e}");
    }
    let e = refusal(&arm, &["arm.alpha=-88"]);
    assert!(e.contains("arm.alpha"), "{e}");
    accepted(&arm, &["arm.alpha=-88", "arm.elements=400"]);
    let e = refusal(&arm, &["arm.alpha=-88.9", "arm.elements=400"]);
    assert!(e.contains("arm.alpha"), "{e}");
}

/// Item 12: continuation in a stiffness of a shearable (Cosserat) column
/// keeps its shear and extension part. A clamped–free column under a dead
/// compressive load P with shear stiffness S1 and extensional stiffness
/// S3: linearized about the straight state, N1 = P θ, ν1 = Pθ/S1,
/// ν3 = 1 − P/S3, and the moment balance B2 θ'' + P (ν1 + ν3 θ) = 0 gives
/// B2 θ'' + P (1 + P/S1 − P/S3) θ = 0 with θ(0) = 0, θ'(L) = 0: the
/// branch point is at B2 = 4 L² P (1 + P/S1 − P/S3)/π² (Haringx's
/// P (1 + P/S1) = π² B/(4L²) when S3 → ∞).
#[test]
fn stiffness_continuation_of_a_shearable_column_reaches_haringx() {
    use cosserat::continuation::{continuation, SpecialKind};
    use cosserat::model::ModelLevel;
    use std::f64::consts::PI;
    let (p, s1, s3, l) = (1.0, 2.0, 10.0, 1.0);
    let exact = 4.0 * l * l * p * (1.0 + p / s1 - p / s3) / (PI * PI);
    let text = "[rod]\nlength = 1.0\n[energy]\nstiffness = [3.0, 0.35, 1.0]\n\
                shear = [2.0, 1e3, 10.0]\n[loads]\ntip_force = [0.0, 0.0, -1.0]\n\
                [continuation]\nparameter = \"energy.stiffness[1]\"\nstart = 0.35\n\
                bounds = [0.3, 3.0]\nstep = 0.1\nmax_step = 0.2\nelements = 40\norder = 3\n\
                eigenvalues = 2\nswitch_depth = 0\nmax_points = 40\n";
    let problem = accepted(text, &[]);
    assert_eq!(problem.model.level, ModelLevel::Cosserat);
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let bp = d
        .special_points
        .iter()
        .find(|s| s.kind == SpecialKind::BranchPoint)
        .expect("a branch point");
    let found = bp.point.parameter;
    eprintln!("branch point B2 = {found:.12}, closed form {exact:.12}");
    assert!((found - exact).abs() < 1e-8 * exact, "{found} vs {exact}");
    // The curvature parameter on the same shearable scene is accepted too
    // (it failed with "needs energy.shear").
    accepted(
        text,
        &[
            "continuation.parameter=\"energy.intrinsic_curvature[1]\"",
            "continuation.start=0.0",
            "continuation.bounds=[-1.0, 1.0]",
        ],
    );
    // A varying profile is not silently replaced by its value at s = 0.
    let e = refusal(text, &["energy.stiffness[1]={polynomial = [0.35, 0.1]}"]);
    assert!(e.contains("continuation.parameter"), "{e}");
}

/// Crashes: `rod.length = 1e-320` reached the finite elements (h = 1e-322,
/// B/h = inf). Lengths are refused outside [1e-6, 1e6] with the advice to
/// change the length unit.
#[test]
fn lengths_far_from_one_are_refused_with_the_unit_advice() {
    for l in ["0", "-1"] {
        let e = refusal(CANTILEVER, &[&format!("rod.length={l}")]);
        assert!(
            e.contains("rod.length") && e.contains("positive"),
            "{l}: {e}"
        );
    }
    for l in ["1e-320", "1e-7", "2e6", "1e300"] {
        let e = refusal(CANTILEVER, &[&format!("rod.length={l}")]);
        assert!(
            e.contains("rod.length") && e.contains("[1e-6, 1e6]") && e.contains("unit"),
            "{l}: {e}"
        );
    }
    for l in ["1e-6", "1e6", "30"] {
        accepted(CANTILEVER, &[&format!("rod.length={l}")]);
    }
}

/// Stiffness ratios beyond 1/(4ε) ≈ 1.1e15 lose the softer stiffness in
/// round-off; the range B1, B3 ∈ [1e-3, 1e12] (B2 = 1) is kept.
#[test]
fn stiffness_ratios_beyond_round_off_are_refused() {
    accepted(CANTILEVER, &["energy.stiffness=[1e-3, 1, 1e12]"]);
    accepted(CANTILEVER, &["energy.stiffness=[1e12, 1, 1e-3]"]);
    let e = refusal(CANTILEVER, &["energy.stiffness=[1e-4, 1, 1e12]"]);
    assert!(
        e.contains("energy.stiffness[0]")
            && e.contains("energy.stiffness[2]")
            && e.contains("ratio"),
        "{e}"
    );
    // Along s too: a table from 1 to 1e16.
    let e = refusal(
        CANTILEVER,
        &["energy.stiffness=[1, {s = [0, 1], values = [1, 1e16]}, 1]"],
    );
    assert!(e.contains("ratio"), "{e}");
}

/// Item 6: positive-definiteness is checked exactly where the profile
/// allows. B2(s) = (s − 0.43215)² − 1e-9 is positive at every one of
/// 1001 equally spaced samples of [0, 1] (the nearest, 0.432, gives
/// 2.3e-8 − 1e-9) but negative at s = 0.43215: refused, with its minimum
/// and where. A table is checked at its knots, exactly.
#[test]
fn stiffness_dipping_between_samples_is_refused() {
    let (s0, delta): (f64, f64) = (0.43215, 1e-9);
    let sampled = (0..=1000)
        .map(|i| {
            let s = f64::from(i) / 1000.0;
            (s - s0).powi(2) - delta
        })
        .fold(f64::INFINITY, f64::min);
    assert!(sampled > 0.0);
    let poly = format!(
        "energy.stiffness=[1, {{polynomial = [{:e}, {:e}, 1.0]}}, 1]",
        s0 * s0 - delta,
        -2.0 * s0
    );
    let e = refusal(CANTILEVER, &[&poly]);
    assert!(
        e.contains("energy.stiffness[1]") && e.contains("-1.000000e-9") && e.contains("0.4321"),
        "{e}"
    );
    // Touching zero exactly (a double root) cannot be certified positive.
    let e = refusal(
        CANTILEVER,
        &["energy.stiffness=[1, {polynomial = [0.25, -1.0, 1.0]}, 1]"],
    );
    assert!(e.contains("energy.stiffness[1]"), "{e}");
    // Clearly positive: accepted.
    accepted(
        CANTILEVER,
        &["energy.stiffness=[1, {polynomial = [0.26, -1.0, 1.0]}, 1]"],
    );
    // A table whose one knot inside [0, L] is negative.
    let e = refusal(
        CANTILEVER,
        &["energy.stiffness=[1, {s = [0, 0.5003, 1], values = [1, -1e-9, 1]}, 1]"],
    );
    assert!(
        e.contains("energy.stiffness[1]") && e.contains("0.5003"),
        "{e}"
    );
}

/// Numbers at the ends of the floating-point range: stiffnesses of 1e±300
/// gave a critical load of NaN, or "stable under any load", with exit
/// code 0. Material and load numbers are refused outside [1e-100, 1e100];
/// inside, Euler's column still buckles at γ = π²/4 (Euler 1744) at both
/// ends of the range.
#[test]
fn numbers_near_the_floating_point_limits_are_refused_or_right() {
    use cosserat::stability::critical_load;
    let column = shipped_text("euler_column");
    for set in [
        "energy.stiffness=[1e-300, 1e-300, 1e-300]",
        "energy.stiffness=[1e300, 1e300, 1e300]",
        "loads.tip_force=[0, 0, -1e300]",
        "energy.shear=[1e-320, 1, 1]",
        "energy.intrinsic_curvature=[0, 1e200, 0]",
    ] {
        let e = refusal(&column, &[set]);
        assert!(e.contains("[1e-100, 1e100]"), "{set}: {e}");
    }
    for b in ["1e-90", "1e90"] {
        let p = accepted(&column, &[&format!("energy.stiffness=[{b}, {b}, {b}]")]);
        let crit = critical_load(&p.rod, p.shape.as_ref().unwrap(), &p.stability).unwrap();
        let gamma = crit.gamma.expect("a critical load");
        let euler = std::f64::consts::PI.powi(2) / 4.0;
        assert!((gamma - euler).abs() < 1e-8 * euler, "B = {b}: γ = {gamma}");
    }
}
