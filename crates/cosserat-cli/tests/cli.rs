//! The `cosserat solve` command: the HDF5 contract, overrides, and every
//! class of bad input (exit code 2, a message naming the field, no output).
mod common;
use common::problems::shipped;

use std::path::{Path, PathBuf};

use common::run::{entries, run, stderr};
use cosserat::output::store::Group;

fn scratch(name: &str) -> PathBuf {
    common::run::scratch("cli", name)
}
const CANTILEVER: &str = include_str!("../../../problems/cantilever_tip_load.toml");

/// Writes `text` as a problem file, runs `solve` with an output file, and
/// checks exit code 2, that stderr contains every one of `expect`, and that
/// no output (nor a temporary) was left behind.
fn rejects(name: &str, text: &str, extra: &[&str], expect: &[&str]) {
    ends_with(2, name, text, extra, expect);
}

/// [`rejects`] on the shipped cantilever with `edit.0` replaced by `edit.1`.
fn rejects_edited(name: &str, edit: (&str, &str), expect: &[&str]) {
    rejects(name, &CANTILEVER.replace(edit.0, edit.1), &[], expect);
}

/// A run that ends without a result: exit `code` (2 bad input, 3 no
/// converged result), the messages, and nothing written.
fn ends_with(code: i32, name: &str, text: &str, extra: &[&str], expect: &[&str]) {
    let dir = scratch(name);
    let problem = dir.join("problem.toml");
    std::fs::write(&problem, text).unwrap();
    let out = dir.join("out.h5");
    let mut args = vec![
        "solve",
        problem.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(code), "{name}: {err}");
    for e in expect {
        assert!(err.contains(e), "{name}: `{e}` not in: {err}");
    }
    let left = entries(&dir);
    assert_eq!(left.len(), 1, "{name}: output left behind: {left:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn syntax_error_gives_line_and_column() {
    rejects_edited(
        "syntax",
        ("length = 1.0", "length = = 1.0"),
        &["line 6, column", "length"],
    );
}

#[test]
fn unknown_key_is_named() {
    rejects_edited(
        "unknown",
        ("length = 1.0", "lenght = 1.0"),
        &["unknown field `lenght`", "line 6"],
    );
}

#[test]
fn missing_key_is_named() {
    rejects_edited(
        "missing",
        ("stiffness = [10.0, 1.0, 10.0]", ""),
        &["missing field `stiffness`"],
    );
}

#[test]
fn wrong_type_is_named() {
    rejects_edited(
        "type",
        ("length = 1.0", "length = \"long\""),
        &["invalid type", "line 6"],
    );
}

#[test]
fn non_positive_length_and_stiffness_are_named() {
    rejects_edited(
        "length",
        ("length = 1.0", "length = 0.0"),
        &["rod.length", "positive"],
    );
    let text = CANTILEVER.replace("[10.0, 1.0, 10.0]", "[10.0, -1.0, 10.0]");
    rejects(
        "stiffness",
        &text,
        &[],
        &["energy.stiffness[1]", "positive"],
    );
    // A tapered stiffness that reaches zero inside the rod.
    rejects(
        "taper",
        CANTILEVER,
        &["--set", "energy.stiffness=[10, {polynomial=[1, -1.5]}, 10]"],
        &["energy.stiffness[1]", "positive"],
    );
}

#[test]
fn clamp_frame_must_be_orthonormal() {
    let text = CANTILEVER.replace("d1 = [1.0, 0.0, 0.0]", "d1 = [1.0, 0.0, 0.1]");
    rejects("frame-unit", &text, &[], &["clamp.d1", "unit"]);
    let text = CANTILEVER.replace("d1 = [1.0, 0.0, 0.0]", "d1 = [0.6, 0.0, 0.8]");
    rejects("frame-orthogonal", &text, &[], &["clamp.d3", "orthogonal"]);
}

#[test]
fn nan_and_infinity_are_rejected() {
    for (name, v) in [("nan", "nan"), ("inf", "inf"), ("neginf", "-inf")] {
        let text = CANTILEVER.replace("[3.0, 0.0, 0.0]", &format!("[{v}, 0.0, 0.0]"));
        rejects(name, &text, &[], &["loads.tip_force[0]", "finite"]);
    }
    rejects(
        "nan-length",
        CANTILEVER,
        &["--set", "rod.length=nan"],
        &["rod.length"],
    );
}

#[test]
fn bad_overrides_and_options_are_named() {
    rejects(
        "set-form",
        CANTILEVER,
        &["--set", "rod.length"],
        &["key=value"],
    );
    rejects(
        "set-key",
        CANTILEVER,
        &["--set", "rod.colour=2"],
        &["unknown field `colour`"],
    );
    rejects(
        "method",
        CANTILEVER,
        &["--method", "magic"],
        &["solver.method", "magic"],
    );
    rejects(
        "model",
        CANTILEVER,
        &["--set", "solver.model=\"cubic\""],
        &["solver.model"],
    );
    let spatial = CANTILEVER.replace("[3.0, 0.0, 0.0]", "[3.0, 1.0, 0.0]");
    rejects(
        "forced-planar",
        &spatial,
        &["--set", "solver.model=planar"],
        &["planar model cannot represent", "d2(0)"],
    );
}

#[test]
fn unconverged_solve_is_an_error_not_a_result() {
    ends_with(
        3,
        "no-convergence",
        CANTILEVER,
        &[
            "--set",
            "solver.max_iterations=1",
            "--set",
            "solver.strategy=direct",
        ],
        &["did not converge", "residual history"],
    );
}

#[test]
fn existing_output_needs_force() {
    let dir = scratch("force");
    let problem = dir.join("p.toml");
    std::fs::write(&problem, CANTILEVER).unwrap();
    let out = dir.join("out.h5");
    std::fs::write(&out, b"precious").unwrap();
    let p = problem.to_str().unwrap();
    let o = run(&["solve", p, "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--force"));
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");
    let o = run(&["solve", p, "-o", out.to_str().unwrap(), "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_dir_all(dir).unwrap();
}

fn read_vectors(g: &Group, name: &str, n: usize) -> Vec<f64> {
    let ds = g.dataset(name).unwrap();
    assert_eq!(ds.shape(), [n, 3], "{name}");
    ds.floats().unwrap().to_vec()
}

fn string_attr(loc: &Group, name: &str) -> String {
    loc.attrs.text(name).unwrap().to_owned()
}

#[test]
fn solution_file_follows_the_contract() {
    let dir = scratch("contract");
    let out = dir.join("cantilever.h5");
    let problem = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("problems/cantilever_tip_load.toml");
    let o = run(&[
        "solve",
        problem.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        "solver.output_points=51",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    for word in [
        "model", "planar", "method", "newton", "residual", "tip", "tangent", "time",
    ] {
        assert!(
            stdout.contains(word),
            "`{word}` missing from the report:\n{stdout}"
        );
    }
    let f = common::h5::open(&out);
    assert!(string_attr(&f, "problem").contains("output_points = 51"));
    let g = f.group("solution").unwrap();
    let s = common::h5::read_f64(g, "s");
    assert_eq!(s.len(), 51);
    assert_eq!((s[0], s[50]), (0.0, 1.0));
    for name in ["position", "d1", "d2", "d3", "curvature", "moment", "force"] {
        read_vectors(g, name, 51);
    }
    assert_eq!(string_attr(g, "model"), "planar");
    assert_eq!(string_attr(g, "method"), "shooting");
    assert!(g.attrs.count("iterations").unwrap() >= 1);
    assert!(g.attrs.float("residual").unwrap() <= 1e-10);
    // The force is the dead tip load everywhere; the moment is B2 κ2.
    let force = read_vectors(g, "force", 51);
    assert!(force.chunks(3).all(|f| f == [3.0, 0.0, 0.0]));
    let (m, k) = (
        read_vectors(g, "moment", 51),
        read_vectors(g, "curvature", 51),
    );
    assert!(m.iter().zip(&k).all(|(m, k)| (m - k).abs() < 1e-15));
    std::fs::remove_dir_all(dir).unwrap();
}

/// A tolerance round-off cannot reach is refused at input with its range;
/// one within the range that the iteration budget cannot reach is an
/// error, not a result.
#[test]
fn impossible_tolerance_is_an_error_not_a_result() {
    rejects(
        "impossible-tolerance",
        CANTILEVER,
        &["--set", "solver.tolerance=1e-30"],
        &["solver.tolerance", "outside [1e-15, 1e-6]"],
    );
    ends_with(
        3,
        "unreached-tolerance",
        CANTILEVER,
        &[
            "--set",
            "solver.tolerance=1e-15",
            "--set",
            "solver.max_iterations=1",
            "--set",
            "solver.strategy=\"direct\"",
        ],
        &["did not converge"],
    );
}

/// A long soft cantilever where single shooting (even with the load ramp)
/// converges to a looped, unstable equilibrium: the report says so.
#[test]
fn unstable_result_is_flagged() {
    let file = shipped("cantilever_tip_load");
    let long = [
        "solve",
        &file,
        "--set",
        "rod.length=12",
        "--set",
        "loads.tip_force=[1,0,0]",
    ];
    let o = run(&long);
    let out = String::from_utf8_lossy(&o.stdout);
    let err = stderr(&o);
    assert!(
        out.contains("UNSTABLE") && err.contains("warning: this equilibrium is unstable"),
        "{out}\n{err}"
    );
    let o = run(&[
        &long[..],
        &[
            "--method",
            "multiple-shooting",
            "--set",
            "solver.segments=16",
        ],
    ]
    .concat());
    assert!(String::from_utf8_lossy(&o.stdout).contains("stability stable"));
}

/// Bad `[arm]` input to `cosserat optimize` (actuator limit, loads the arm
/// does not take, `--resume` without an output file): exit code 2, a
/// message naming the field, nothing written.
#[test]
fn optimize_rejects_bad_arm_input() {
    const ARM: &str = include_str!("../../../problems/longest_arm_fig5.toml");
    let cases: [(&str, String, &[&str], &str); 4] = [
        (
            "arm-negative-limit",
            ARM.replace(
                "map_samples = 4000",
                "map_samples = 4000\nmax_curvature = -1.0",
            ),
            &[],
            "arm.max_curvature",
        ),
        (
            "arm-sideways-load",
            ARM.replace("tip_force = [1.0, 0.0, 0.0]", "tip_force = [1.0, 0.5, 0.0]"),
            &[],
            "loads",
        ),
        (
            "arm-no-load",
            ARM.replace("tip_force = [1.0, 0.0, 0.0]", "tip_force = [0.0, 0.0, 0.0]"),
            &[],
            "loads",
        ),
        ("arm-resume-no-output", ARM.to_string(), &["--resume"], "-o"),
    ];
    for (name, text, extra, expect) in cases {
        let dir = scratch(name);
        let problem = dir.join("problem.toml");
        std::fs::write(&problem, text).unwrap();
        let out = dir.join("out.h5");
        let plot = dir.join("out.png");
        let mut args = vec!["optimize", problem.to_str().unwrap()];
        if extra.is_empty() {
            args.extend(["-o", out.to_str().unwrap()]);
        }
        args.extend(["--plot", plot.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let o = run(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(expect), "{name}: `{expect}` not in: {err}");
        let left = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(left, 1, "{name}: output left behind");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
