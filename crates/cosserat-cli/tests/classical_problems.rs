//! Classical problems posed only through the documented keys (issue 16's
//! acceptance), each run by `cosserat continue` and compared with a
//! reference computed here from its closed form: the pinned–pinned column
//! and its elastica (problems/pinned_column.toml: Euler's loads, the
//! elliptic-integral branch, the end slope stopped at 170°), the same
//! elastica under displacement control
//! (problems/pinned_elastica_displacement.toml), and Greenhill's twisted
//! rod with clamped ends under a thrust, through more than two turns
//! (problems/twisted_rod_thrust.toml: two double branch points), a ring
//! bent shut by turning its end (problems/ring_end_rotation.toml: the arc
//! through 2π), and the pinned arch's asymmetric branch point before its
//! fold (problems/pinned_arch_full.toml, against an independent scipy
//! shooting, scripts/pinned_arch_reference.py).
mod common;

use std::f64::consts::PI;
use std::path::Path;

use common::problems::shipped;
use common::run::{run, scratch, special_line, stderr};
use cosserat::references::{ellip_e, ellip_f, greenhill_clamped};

/// `cosserat continue NAME -o OUT` with `overrides`: its stdout, the run
/// having succeeded without a warning.
fn continued(name: &str, out: &Path, overrides: &[&str]) -> String {
    let mut args = vec![
        "continue".to_string(),
        shipped(name),
        "-o".into(),
        out.to_str().unwrap().into(),
    ];
    for o in overrides {
        args.extend(["--set".to_string(), (*o).to_string()]);
    }
    let o = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success() && o.stderr.is_empty(), "{}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The `special K` lines of a run's output, in order.
fn specials(stdout: &str) -> Vec<&str> {
    stdout
        .lines()
        .filter(|l| l.starts_with("special "))
        .collect()
}

/// The printed parameter of a special line within twice its stated error
/// (plus the 12 printed decimals) of `reference`, the error itself below
/// `bound` relative.
fn assert_located(line: &str, reference: f64, bound: f64) {
    let (_, printed, error) = special_line(line);
    let error = error.unwrap_or_else(|| panic!("no error stated: {line}"));
    assert!(error <= bound * reference, "{line}");
    assert!(
        (printed - reference).abs() <= 2.0 * error + 1e-12,
        "{line}: against {reference} off by {:e}",
        printed - reference
    );
}

/// K(k) and E(k), the complete elliptic integrals of modulus k.
fn complete(k: f64) -> (f64, f64) {
    (ellip_f(PI / 2.0, k), ellip_e(PI / 2.0, k))
}

/// The root of `f` (increasing) in (lo, hi) by bisection to round-off.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The pinned–pinned elastica of modulus k (B = L = 1): the thrust 4K²,
/// the tip's height over the base 2E/K − 1 and the midspan's sway 2k/√P.
struct Elastica {
    load: f64,
    height: f64,
    sway: f64,
}

impl Elastica {
    fn of_modulus(k: f64) -> Self {
        let (kk, e) = complete(k);
        let load = 4.0 * kk * kk;
        Self {
            load,
            height: 2.0 * e / kk - 1.0,
            sway: 2.0 * k / load.sqrt(),
        }
    }

    /// The elastica under the thrust `load` (> π²).
    fn at_load(load: f64) -> Self {
        Self::of_modulus(bisect(|k| Self::of_modulus(k).load - load, 0.0, 1.0))
    }

    /// The elastica whose tip stands at `height` over the base.
    fn at_height(height: f64) -> Self {
        Self::of_modulus(bisect(|k| height - Self::of_modulus(k).height, 0.0, 1.0))
    }
}

/// The first positive root of tan β = β (the clamped–pinned column's
/// β²): β − tan β changes sign once in (π, 3π/2).
fn clamped_pinned() -> f64 {
    let beta = bisect(|b| b.tan() - b, PI + 1e-9, 1.5 * PI - 1e-9);
    beta * beta
}

#[test]
fn pinned_column_buckles_at_eulers_loads_onto_its_elastica() {
    let dir = scratch("classical", "pinned-column");
    let out = dir.join("column.h5");
    let stdout = continued("pinned_column", &out, &[]);
    let lines = specials(&stdout);
    // The straight column: π², 4π², 9π² in the plane; out of it the hinge
    // holds the base (a clamped–pinned column, B1 = 2). The buckled
    // branches (modes 1 and 2) meet the rotated loops where the tip passes
    // the base: E/K = 1/2, P = 4K² and 16K².
    let through = Elastica::at_height(0.0).load;
    let expected = [
        (0, "in_plane", PI * PI),
        (1, "in_plane", 4.0 * PI * PI),
        (2, "out_of_plane", 2.0 * clamped_pinned()),
        (3, "in_plane", 9.0 * PI * PI),
        (4, "in_plane", through),
        (6, "in_plane", through),
        (8, "in_plane", 4.0 * through),
        (10, "in_plane", 4.0 * through),
    ];
    for (k, block, reference) in expected {
        let line = lines[k];
        assert!(
            line.contains("branch_point") && line.contains(block),
            "{line}"
        );
        assert!(line.contains("multiplicity 1"), "{line}");
        assert_located(line, reference, 1e-10);
    }
    let f = common::h5::open(&out);
    // The first mode's two buckled branches on the elastica at every point,
    // each stopped where the end slope reaches 170°.
    for branch in [1, 2] {
        let group = format!("branches/{branch}");
        let p = common::h5::read_f64(&f, &format!("{group}/parameter"));
        let m = common::h5::read_f64(&f, &format!("{group}/measures"));
        for (i, &load) in p.iter().enumerate() {
            let reference = Elastica::at_load(load);
            let (height, sway) = (m[3 * i], m[3 * i + 1]);
            assert!((height - reference.height).abs() < 1e-9, "{load}: {height}");
            assert!((sway.abs() - reference.sway).abs() < 1e-9, "{load}: {sway}");
        }
        let slope = common::h5::read_f64(&f, &format!("{group}/tip_angle"));
        let last = *slope.last().unwrap();
        assert!((last - 170f64.to_radians()).abs() < 1e-10, "{last}");
        let at_stop = Elastica::of_modulus(85f64.to_radians().sin()).load;
        assert!(
            (p.last().unwrap() - at_stop).abs() < 1e-8 * at_stop,
            "{p:?}"
        );
    }
}

#[test]
fn twisted_rod_under_thrust_loses_stability_at_greenhills_double_points() {
    let dir = scratch("classical", "twisted-thrust");
    let out = dir.join("twisted.h5");
    let stdout = continued("twisted_rod_thrust", &out, &[]);
    let lines = specials(&stdout);
    assert_eq!(lines.len(), 2, "{stdout}");
    // Both crossings are pairs (B1 = B2): multiplicity 2, the Morse index
    // 0 → 2 → 4, though three eigenvalues are tracked.
    for (line, morse) in lines.iter().zip([0, 2]) {
        assert!(line.contains("branch_point"), "{line}");
        assert!(
            line.contains(&format!("Morse index {morse}, multiplicity 2")),
            "{line}"
        );
        // The thrust at which Greenhill's determinant vanishes for the
        // printed twisting moment M L/B = θ C/B (C = B) is the problem's,
        // 10: the moment's error is the thrust's over dP/dM.
        let (_, theta, error) = special_line(line);
        let error = error.unwrap_or_else(|| panic!("no error stated: {line}"));
        let h = 1e-5;
        let slope = (greenhill_clamped(theta + h) - greenhill_clamped(theta - h)) / (2.0 * h);
        let off = (greenhill_clamped(theta) - 10.0) / slope;
        assert!(error <= 1e-10 * theta, "{line}");
        assert!(off.abs() <= 2.0 * error + 1e-12, "{line}: off by {off:e}");
    }
    // More than two full turns at the second point.
    assert!(special_line(lines[1]).1 > 4.0 * PI);
}

#[test]
fn pinned_elastica_under_displacement_control_follows_loves_force() {
    let dir = scratch("classical", "pinned-displacement");
    let out = dir.join("elastica.h5");
    let stdout = continued("pinned_elastica_displacement", &out, &[]);
    // Towards the full length the branch ends on its bound 0.9999: the
    // step that passed the fold at 1.0 (the straight rod) and came back
    // used to go on past it, the fold reported beyond the bounds.
    assert!(specials(&stdout).is_empty(), "{stdout}");
    let f = common::h5::open(&out);
    for (branch, bound) in [(0, 0.9999), (1, 0.2)] {
        let group = format!("branches/{branch}");
        let p = common::h5::read_f64(&f, &format!("{group}/parameter"));
        let m = common::h5::read_f64(&f, &format!("{group}/measures"));
        assert_eq!(*p.last().unwrap(), bound, "{p:?}");
        for (i, &height) in p.iter().enumerate() {
            let reference = Elastica::at_height(height);
            let k = (reference.sway * reference.load.sqrt()) / 2.0;
            let (force, sway, slope) = (m[3 * i], m[3 * i + 1], m[3 * i + 2]);
            // The support pushes the tip towards the base.
            assert!(
                (-force - reference.load).abs() < 1e-9 * reference.load,
                "{height}: {force} against {}",
                reference.load
            );
            assert!(
                (sway.abs() - reference.sway).abs() < 1e-9,
                "{height}: {sway}"
            );
            let sin_alpha = 2.0 * k * (1.0 - k * k).sqrt();
            assert!((slope.abs() - sin_alpha).abs() < 1e-9, "{height}: {slope}");
        }
    }
}

/// A guess of κ(0) beside a hinge is refused by its key: the planar
/// solver read its κ2 as the hinge's angle (3 rad from [0, 3, 0], and
/// Newton diverged); the angle's guess is `clamp.angle`.
#[test]
fn a_curvature_guess_beside_a_hinge_is_refused_by_name() {
    let text = common::problems::shipped_text("pinned_elastica_displacement");
    let message = common::problems::refusal(&text, &["solver.initial_curvature=[0,3,0]"]);
    assert!(message.contains("solver.initial_curvature"), "{message}");
    assert!(message.contains("clamp.angle"), "{message}");
}

/// A rod bent by turning its end (tip free, its frame held and turned about
/// d2) is an arc of curvature θ/L at every θ: through π, where the planar
/// model's held angle (atan2 of the frame) jumped by 2π and the branch
/// jumped with it onto the rod unwound by a turn (θ = 6.29 with the
/// turning 0.005), through the closed ring at 2π and beyond.
#[test]
fn ring_bent_by_its_end_follows_the_arc_through_a_full_turn() {
    let dir = scratch("classical", "ring");
    let out = dir.join("ring.h5");
    continued("ring_end_rotation", &out, &[]);
    let f = common::h5::open(&out);
    let p = common::h5::read_f64(&f, "branches/0/parameter");
    let m = common::h5::read_f64(&f, "branches/0/measures");
    assert_eq!(*p.last().unwrap(), 8.0, "{p:?}");
    // No step longer than the largest arclength step moves θ (one unit
    // of the scaled unknowns per radian of the turn, at least).
    assert!(
        p.windows(2).all(|w| w[1] > w[0] && w[1] - w[0] <= 0.5),
        "{p:?}"
    );
    for (i, &theta) in p.iter().enumerate().skip(1) {
        let (turning, x, z, moment) = (m[4 * i], m[4 * i + 1], m[4 * i + 2], m[4 * i + 3]);
        assert!((turning - theta).abs() < 1e-9, "{theta}: turning {turning}");
        assert!(
            (x - (1.0 - theta.cos()) / theta).abs() < 1e-9,
            "{theta}: x {x}"
        );
        assert!((z - theta.sin() / theta).abs() < 1e-9, "{theta}: z {z}");
        assert!((moment.abs() - theta).abs() < 1e-9, "{theta}: M {moment}");
    }
}

/// Every branch stays within its bounds: the second mode's branches,
/// switched at 4π² = 39.48 below the bound 40, began at 40.74 ("left the
/// bounds"); now they are landed on the bound, one point each.
#[test]
fn switched_branches_begin_within_the_bounds() {
    let dir = scratch("classical", "switch-bounds");
    let out = dir.join("column.h5");
    let stdout = continued("pinned_column", &out, &["continuation.bounds=[0,40]"]);
    let f = common::h5::open(&out);
    let branches = stdout.lines().filter(|l| l.starts_with("branch ")).count();
    assert_eq!(branches, 5, "{stdout}");
    for b in 0..branches {
        let p = common::h5::read_f64(&f, &format!("branches/{b}/parameter"));
        assert!(p.iter().all(|v| (0.0..=40.0).contains(v)), "{b}: {p:?}");
    }
    for line in stdout
        .lines()
        .filter(|l| l.contains("from special point 1"))
    {
        assert!(
            line.contains("1 points, parameter 40.000000 → 40.000000"),
            "{line}"
        );
        assert!(line.ends_with("reached the bound 40"), "{line}");
    }
}

/// The pinned–pinned arch (Θ = 0.5) loses stability at its asymmetric
/// branch point before its symmetric fold, both at the values of an
/// independent scipy shooting of the elastica (problems/pinned_arch_full.toml:
/// 5.92062588 ± 3e-9 and 6.8214789791 ± 1e-10, the reference's accuracy).
#[test]
fn pinned_arch_bifurcates_before_its_fold() {
    // scipy's DOP853 shooting of the elastica (problems/pinned_arch_full.toml).
    const BIFURCATION: f64 = 5.920_625_881_5;
    const FOLD: f64 = 6.821_478_979_130_86;
    let dir = scratch("classical", "pinned-arch");
    let out = dir.join("arch.h5");
    let stdout = continued("pinned_arch_full", &out, &[]);
    let lines = specials(&stdout);
    assert_eq!(lines.len(), 2, "{stdout}");
    let (located, bifurcation, error) = special_line(lines[0]);
    assert!(lines[0].contains("branch_point") && lines[0].contains("Morse index 0"));
    assert_eq!(located, "augmented");
    assert!((bifurcation - BIFURCATION).abs() < 3e-9, "{}", lines[0]);
    assert!(error.unwrap() < 1e-10, "{}", lines[0]);
    let (located, fold, _) = special_line(lines[1]);
    assert!(lines[1].contains("fold") && lines[1].contains("Morse index 1"));
    assert_eq!(located, "augmented");
    assert!((fold - FOLD).abs() < 1e-10, "{}", lines[1]);
    // Both ways off the branch point the load falls.
    for line in stdout
        .lines()
        .filter(|l| l.contains("from special point 0"))
    {
        assert!(line.ends_with("reached the bound -1"), "{line}");
    }
}

/// Switched again from the stored diagram at the point where the tip
/// passes the base (`--point special/4`): the loop of E/K = 1/2 turned by
/// ψ about the common end point, carried by the force F* = 4K² along the
/// turned chord's normal, so that the thrust is P = F* cos ψ: the tip
/// stays at the base and the midspan's sway is s₀ cos ψ = s₀ P/F*
/// (s₀ = 2k/√F*, the loop's own).
#[test]
fn loops_turned_about_their_closed_ends_carry_the_projected_force() {
    let dir = scratch("classical", "turned-loops");
    let (first, out) = (dir.join("column.h5"), dir.join("loops.h5"));
    continued("pinned_column", &first, &[]);
    let o = run(&[
        "continue",
        &shipped("pinned_column"),
        "--from",
        first.to_str().unwrap(),
        "--point",
        "special/4",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let loop_ = Elastica::at_height(0.0);
    let f = common::h5::open(&out);
    for branch in [1, 2] {
        let p = common::h5::read_f64(&f, &format!("branches/{branch}/parameter"));
        let m = common::h5::read_f64(&f, &format!("branches/{branch}/measures"));
        assert!(p.len() > 5 && p.iter().all(|&v| v < loop_.load), "{p:?}");
        for (i, &load) in p.iter().enumerate() {
            let (height, sway) = (m[3 * i], m[3 * i + 1]);
            assert!(height.abs() < 1e-9, "{load}: {height}");
            let projected = loop_.sway * load / loop_.load;
            assert!(
                (sway.abs() - projected.abs()).abs() < 1e-9,
                "{load}: {sway}"
            );
        }
    }
}

/// The pinned column's first branch point followed in the rod length
/// (`--curve`, the default curve steps) stays on Euler's P = π²B/L²: every
/// point within 1e-10 relative, its stated error below 1e-10 too
/// (measured: 220 points, 8.3e-13). The curve's corrector had diverged on
/// its first step (a length of 805, "more than 100000 steps") and ended the
/// curve; a diverging or failing corrector now halves the step.
#[test]
fn the_pinned_columns_branch_point_follows_eulers_load_in_the_length() {
    let dir = scratch("classical", "pinned_curve");
    let (diagram, curve) = (dir.join("d.h5"), dir.join("c.h5"));
    continued("pinned_column", &diagram, &["continuation.switch_depth=0"]);
    let o = run(&[
        "continue",
        &shipped("pinned_column"),
        "-o",
        curve.to_str().unwrap(),
        "--from",
        diagram.to_str().unwrap(),
        "--point",
        "special/0",
        "--curve",
        "--set",
        "continuation.curve={parameter=\"rod.length\", start=1.0, bounds=[0.5, 2.0]}",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let file = common::h5::open(&curve);
    let floats = |name: &str| file.dataset(name).unwrap().floats().unwrap().to_vec();
    let (p, e) = (floats("curve/parameters"), floats("curve/parameter_error"));
    assert!(p.len() >= 40, "{} values", p.len());
    let (mut shortest, mut longest) = (f64::INFINITY, 0.0f64);
    for (row, error) in p.chunks(2).zip(e.chunks(2)) {
        let euler = PI * PI / (row[1] * row[1]);
        assert!(
            (row[0] - euler).abs() <= 1e-10 * euler && error[0] <= 1e-10 * euler,
            "L = {}: {} ± {} vs {euler}",
            row[1],
            row[0],
            error[0]
        );
        shortest = shortest.min(row[1]);
        longest = longest.max(row[1]);
    }
    assert!(
        shortest < 0.5 + 1e-3 && longest > 2.0 - 1e-3,
        "[{shortest}, {longest}]"
    );
}
