//! `cosserat continue --from DIAGRAM --point B/I`: restarts, chained
//! stages, and refusals with a named reason and exit code 2.

mod common;

use common::h5::read_f64;
use common::run::{run, scratch, stderr};

fn shipped(name: &str) -> String {
    format!("{}/../../problems/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

/// `cosserat continue PROBLEM -o OUT --from FROM --point POINT EXTRA…`.
fn continue_from(
    problem: &str,
    out: &str,
    from: &str,
    point: &str,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec![
        "continue", problem, "-o", out, "--from", from, "--point", point,
    ];
    args.extend_from_slice(extra);
    run(&args)
}

/// A restart from a point of the buckled Euler branch ends where the
/// uninterrupted branch ends (the 170° landing), and says where it started.
#[test]
fn a_restart_goes_on_along_the_stored_branch() {
    let dir = scratch("from", "restart");
    let full = dir.join("full.h5");
    let again = dir.join("again.h5");
    let euler = shipped("euler_column");
    let o = run(&["continue", &euler, "-o", full.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = continue_from(
        &euler,
        again.to_str().unwrap(),
        full.to_str().unwrap(),
        "1/10",
        &["--set", "continuation.switch_depth=0"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("branch 1 point 10: load_scale = "), "{out}");
    assert!(out.contains("tip angle 170.00° reached"), "{out}");
}

/// A second stage in another parameter: the twisted rod's straight branch
/// stored, then continued in the torsional stiffness from its point at one
/// full turn — the key of the first stage is held at the stored value.
#[test]
fn a_chained_stage_holds_the_first_parameter() {
    let dir = scratch("from", "chain");
    let first = dir.join("twist.h5");
    let second = dir.join("stiffness.h5");
    let twisted = shipped("twisted_rod");
    let o = run(&[
        "continue",
        &twisted,
        "-o",
        first.to_str().unwrap(),
        "--set",
        "continuation.bounds=[0.0, 6.3]",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = continue_from(
        &twisted,
        second.to_str().unwrap(),
        first.to_str().unwrap(),
        "0/last",
        &[
            "--set",
            "continuation.parameter=\"energy.stiffness[2]\"",
            "--set",
            "continuation.start=1.0",
            "--set",
            "continuation.bounds=[0.5, 1.5]",
            "--set",
            "continuation.switch_depth=0",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("support.turn.angle = 6.3"), "{out}");
    // Held at θ = 6.3, the straight rod carries M = C θ/L and loses
    // stability where M L/B = 2x₁: C = 2x₁ B/θ = 8.98682/6.3 = 1.42648.
    let exact = cosserat::references::twisted_clamped_moment() / 6.3;
    assert!((exact - 1.42648).abs() < 1e-5);
    assert!(
        out.contains("branch_point on branch 0 at parameter 1.4264"),
        "{out}"
    );
}

/// Refusals: a malformed or missing point, a file that is not a diagram,
/// and --from without --point.
#[test]
fn bad_stored_points_are_refused_by_name() {
    let dir = scratch("from", "refusals");
    let full = dir.join("full.h5");
    let out = dir.join("out.h5");
    let euler = shipped("euler_column");
    let o = run(&["continue", &euler, "-o", full.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    for (point, says) in [
        ("7/0", "branches"),
        ("1/999", "points"),
        ("x", "BRANCH/POINT"),
        ("1/y", "points"),
    ] {
        let o = continue_from(
            &euler,
            out.to_str().unwrap(),
            full.to_str().unwrap(),
            point,
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{point}");
        assert!(stderr(&o).contains(says), "{point}: {}", stderr(&o));
        assert!(!out.exists(), "nothing written");
    }
    let o = continue_from(&euler, out.to_str().unwrap(), &euler, "0/0", &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a diagram file"), "{}", stderr(&o));
    let o = run(&[
        "continue",
        &euler,
        "-o",
        out.to_str().unwrap(),
        "--from",
        full.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "--from needs --point");
}

/// `--point special/K` switches at a stored branch point: the Euler
/// column's two buckled branches again, ending at the same 170° tip angle,
/// in a diagram that carries the stored straight branch and the point.
#[test]
fn a_stored_branch_point_is_switched_again() {
    let dir = scratch("from", "special");
    let full = dir.join("full.h5");
    let again = dir.join("again.h5");
    let euler = shipped("euler_column");
    let o = run(&["continue", &euler, "-o", full.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let first = String::from_utf8_lossy(&o.stdout).into_owned();
    let o = continue_from(
        &euler,
        again.to_str().unwrap(),
        full.to_str().unwrap(),
        "special/0",
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let buckled = |text: &str| {
        text.lines()
            .filter(|l| l.contains("from special point 0; tip angle 170.00° reached"))
            .map(|l| {
                l.split(',')
                    .next()
                    .unwrap_or_default()
                    .split_whitespace()
                    .last()
                    .unwrap_or_default()
                    .to_string()
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(buckled(&out).len(), 2, "{out}");
    assert_eq!(buckled(&out), buckled(&first), "the same branches: {out}");
    for bad in ["special/9", "special/x"] {
        let o = continue_from(
            &euler,
            dir.join("bad.h5").to_str().unwrap(),
            full.to_str().unwrap(),
            bad,
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(stderr(&o).contains("special points"), "{}", stderr(&o));
    }
}

/// Hostile `--from` paths: a device, a directory, a file that is not HDF5,
/// a missing file — each refused by name with exit code 2, nothing
/// written, nothing read without end.
#[test]
fn hostile_stored_diagrams_are_refused() {
    let dir = scratch("from", "hostile");
    let out = dir.join("out.h5");
    let garbage = dir.join("garbage.h5");
    std::fs::write(&garbage, b"not an hdf5 file").unwrap();
    let euler = shipped("euler_column");
    let missing = dir.join("missing.h5");
    for from in [
        std::path::Path::new("/dev/zero"),
        dir.as_path(),
        garbage.as_path(),
        missing.as_path(),
    ] {
        let o = continue_from(
            &euler,
            out.to_str().unwrap(),
            from.to_str().unwrap(),
            "0/0",
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{}", from.display());
        assert!(stderr(&o).contains("not a diagram file"), "{}", stderr(&o));
        assert!(!out.exists(), "nothing written");
    }
}

/// `--curve`: Euler's stored branch point followed in the rod length stays
/// on F = π²B/(4L²) at every point of the curve file.
#[test]
fn a_stored_branch_point_is_followed_in_a_second_parameter() {
    let dir = scratch("from", "curve");
    let full = dir.join("full.h5");
    let curve = dir.join("curve.h5");
    let euler = shipped("euler_column");
    let o = run(&["continue", &euler, "-o", full.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let set = "continuation.curve={parameter=\"rod.length\", start=1.0, bounds=[0.5, 2.0], step=0.1, max_step=0.3}";
    let args = |point: &str, curve_flag: bool, set: Option<&str>| {
        let mut a = vec![
            "continue".to_string(),
            euler.clone(),
            "-o".into(),
            curve.to_str().unwrap().into(),
            "--from".into(),
            full.to_str().unwrap().into(),
            "--point".into(),
            point.into(),
        ];
        if curve_flag {
            a.push("--curve".into());
        }
        if let Some(s) = set {
            a.extend(["--set".to_string(), s.to_string()]);
        }
        a
    };
    let call = |a: Vec<String>| run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let o = call(args("special/0", true, Some(set)));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .contains("largest estimated discretization error of load_scale at fixed rod.length"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let file = common::h5::open(&curve);
    let floats = |name: &str| file.dataset(name).unwrap().floats().unwrap().to_vec();
    let (p, e) = (floats("curve/parameters"), floats("curve/parameter_error"));
    assert!(p.len() >= 20, "{} values", p.len());
    assert_eq!(p.len(), e.len());
    for (row, error) in p.chunks(2).zip(e.chunks(2)) {
        let exact = std::f64::consts::PI.powi(2) / (4.0 * row[1] * row[1]);
        let actual = (row[0] - exact).abs();
        assert!(
            actual <= 1e-10 * exact,
            "L = {}: {} vs {exact}",
            row[1],
            row[0]
        );
        // The stated error of the load at this length is the actual one
        // (shooting: measured to two or three digits), above the
        // corrector's own remainder.
        assert!(
            error[0] <= 1e-10 * exact && actual <= 2.0 * error[0] + 1e-13 * exact,
            "L = {}: estimated {:e}, actual {actual:e}",
            row[1],
            error[0]
        );
    }
    drop(file);
    std::fs::remove_file(&curve).unwrap();
    // Refused: no [continuation.curve]; a point that is not special.
    let o = call(args("special/0", true, None));
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("[continuation.curve]"),
        "{}",
        stderr(&o)
    );
    let o = call(args("1/3", true, Some(set)));
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("special/K"), "{}", stderr(&o));
    assert!(!curve.exists(), "nothing written by a refusal");
}

/// `--from SOLVE.h5`: the displacement-controlled elastica started from
/// the equilibrium `cosserat solve` stored follows the same branches as
/// the run that solves its own start (Newton at the start value from the
/// same unknowns), to the corrector's tolerance.
#[test]
fn a_solve_file_starts_the_continuation() {
    let dir = scratch("from", "solve");
    let (solved, own, from) = (
        dir.join("solve.h5"),
        dir.join("own.h5"),
        dir.join("from.h5"),
    );
    let problem = shipped("clamped_elastica_displacement");
    let o = run(&["solve", &problem, "-o", solved.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&["continue", &problem, "-o", own.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&[
        "continue",
        &problem,
        "-o",
        from.to_str().unwrap(),
        "--from",
        solved.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("the equilibrium solved by shooting"), "{out}");
    let (a, b) = (common::h5::open(&own), common::h5::open(&from));
    let mut worst: f64 = 0.0;
    for i in 0..2 {
        let path = format!("branches/{i}");
        let (ga, gb) = (a.group(&path).unwrap(), b.group(&path).unwrap());
        for name in ["parameter", "unknowns"] {
            let (u, v) = (read_f64(ga, name), read_f64(gb, name));
            assert_eq!(u.len(), v.len(), "branch {i} {name}");
            worst = u
                .iter()
                .zip(&v)
                .fold(worst, |w, (x, y)| w.max((x - y).abs()));
        }
    }
    assert!(worst < 1e-9, "the branches differ by {worst}");
}

/// Hostile and wrong `--from` files without `--point` are refused by name
/// with exit code 2 and nothing written: a device, a directory, a file
/// that is not HDF5, a missing file, a damaged solve file, a diagram, a
/// solve of another problem, at another model level, or with another
/// discretization.
#[test]
fn wrong_solve_files_are_refused() {
    let dir = scratch("from", "solve-hostile");
    let out = dir.join("out.h5");
    let problem = shipped("clamped_elastica_displacement");
    let solve = |name: &str, extra: &[&str]| {
        let path = dir.join(name);
        let mut args = vec!["solve", &problem, "-o", path.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        path
    };
    let good = solve("good.h5", &[]);
    let damaged = dir.join("damaged.h5");
    let mut bytes = std::fs::read(&good).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0xff;
    std::fs::write(&damaged, bytes).unwrap();
    let garbage = dir.join("garbage.h5");
    std::fs::write(&garbage, b"not an hdf5 file").unwrap();
    let diagram = dir.join("diagram.h5");
    let o = run(&["continue", &problem, "-o", diagram.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let other = dir.join("other.h5");
    let o = run(&[
        "solve",
        &shipped("cantilever_tip_load"),
        "-o",
        other.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let spatial = solve("spatial.h5", &["--set", "solver.model=\"kirchhoff\""]);
    let segments = solve(
        "segments.h5",
        &[
            "--set",
            "solver.method=\"multiple-shooting\"",
            "--set",
            "solver.segments=4",
        ],
    );
    let cases: [(&std::path::Path, &str); 9] = [
        (std::path::Path::new("/dev/zero"), "not a solve file"),
        (dir.as_path(), "not a solve file"),
        (&garbage, "not a solve file"),
        (&dir.join("missing.h5"), "not a solve file"),
        (&damaged, "is damaged"),
        (&diagram, "not a solve file (it has no /solution group)"),
        (&other, "solved for another problem: its ["),
        (&spatial, "solved at the kirchhoff model"),
        (&segments, "the solve has 21 unknowns"),
    ];
    for (from, says) in cases {
        let o = run(&[
            "continue",
            &problem,
            "-o",
            out.to_str().unwrap(),
            "--from",
            from.to_str().unwrap(),
        ]);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{}: {}",
            from.display(),
            stderr(&o)
        );
        assert!(
            stderr(&o).contains(says),
            "{}: {}",
            from.display(),
            stderr(&o)
        );
        assert!(!out.exists(), "nothing written");
    }
}

/// The cantilever of problems/cantilever_tip_load.toml (B = (10, 1, 10),
/// a 3 N tip force across it) with a `[continuation]` of its length —
/// the number that moves the state scales (positions L, curvatures 1/L)
/// by which a diagram stores its node states. Two shape points: the
/// continued length moves the equally spaced shape points, and only the
/// tip is compared here.
const LENGTH_TABLE: &str = "
[continuation]
parameter = \"rod.length\"
start = 1.0
bounds = [1.0, 1.35]
step = 0.1
max_step = 0.2
switch_depth = 0
shape_points = 2
";

/// The `--set` of a discretization: single shooting, multiple shooting
/// on 8 segments, Gauss collocation on 32 intervals.
fn method_sets(method: &str) -> Vec<String> {
    let mut sets = vec![format!("solver.method=\"{method}\"")];
    match method {
        "multiple-shooting" => sets.push("solver.segments=8".into()),
        "collocation" => sets.push("continuation.intervals=32".into()),
        _ => {}
    }
    sets.into_iter()
        .flat_map(|s| ["--set".to_string(), s])
        .collect()
}

/// `cosserat` with `args` then `sets`, which must succeed.
fn run_ok(args: &[&str], sets: &[String]) -> std::process::Output {
    let mut all: Vec<&str> = args.to_vec();
    all.extend(sets.iter().map(String::as_str));
    let o = run(&all);
    assert!(o.status.success(), "{all:?}: {}", stderr(&o));
    o
}

/// Starting in another key from a stored point: a diagram of the
/// cantilever's length (each method), then from its last point a run
/// continuing the tip force (each method: the stored mesh, or another one
/// the point is carried onto). The first point of the new branch is the
/// stored equilibrium: its tip agrees to 1e-9 with an independent
/// `cosserat solve` (single shooting) of the problem at the stored length.
#[test]
fn a_point_starts_another_key_at_its_equilibrium() {
    let dir = scratch("from", "other-key");
    let problem = dir.join("cantilever.toml");
    let text = std::fs::read_to_string(shipped("cantilever_tip_load")).unwrap();
    std::fs::write(&problem, text + LENGTH_TABLE).unwrap();
    let problem = problem.to_str().unwrap();
    let force = [
        "continuation.parameter=\"loads.tip_force[0]\"",
        "continuation.start=3.0",
        "continuation.bounds=[3.0, 4.0]",
    ]
    .iter()
    .flat_map(|s| ["--set".to_string(), s.to_string()])
    .collect::<Vec<_>>();
    let methods = ["shooting", "multiple-shooting", "collocation"];
    for stored in methods {
        let diagram = dir.join(format!("length-{stored}.h5"));
        let d = diagram.to_str().unwrap();
        run_ok(&["continue", problem, "-o", d], &method_sets(stored));
        let file = common::h5::open(&diagram);
        let length = *read_f64(file.group("branches/0").unwrap(), "parameter")
            .last()
            .unwrap();
        drop(file);
        assert!(length > 1.3, "the diagram reached L = {length}");
        let solved = dir.join(format!("solve-{stored}.h5"));
        let set = format!("rod.length={length}");
        run_ok(
            &[
                "solve",
                problem,
                "-o",
                solved.to_str().unwrap(),
                "--set",
                &set,
            ],
            &[],
        );
        let solution = common::h5::open(&solved);
        let position = read_f64(solution.group("solution").unwrap(), "position");
        let exact = &position[position.len() - 3..];
        drop(solution);
        for method in methods {
            let out = dir.join(format!("force-{stored}-{method}.h5"));
            let mut sets = method_sets(method);
            sets.extend(force.iter().cloned());
            let o = run_ok(
                &[
                    "continue",
                    problem,
                    "-o",
                    out.to_str().unwrap(),
                    "--from",
                    d,
                    "--point",
                    "0/last",
                ],
                &sets,
            );
            let said = String::from_utf8_lossy(&o.stdout);
            assert!(said.contains(&format!("rod.length = {length}")), "{said}");
            let file = common::h5::open(&out);
            let branch = file.group("branches/0").unwrap();
            assert_eq!(read_f64(branch, "parameter")[0], 3.0);
            let tip = &read_f64(branch, "tip_position")[..3];
            let worst = tip
                .iter()
                .zip(exact)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-9,
                "stored by {stored}, run by {method}: the first tip {tip:?} is {worst:e} from \
                 the solve's {exact:?}"
            );
        }
    }
}

/// A stored point of another state layout is refused by name (exit 2,
/// nothing written): a planar diagram started in the spatial model; and
/// a switch at a stored branch point on another mesh, which replays the
/// stored branch on its own points.
#[test]
fn a_point_of_another_discretization_is_refused_by_name() {
    let dir = scratch("from", "other-mesh");
    let out = dir.join("out.h5");
    let full = dir.join("full.h5");
    let euler = shipped("euler_column");
    let sets = [
        "--set",
        "solver.method=\"multiple-shooting\"",
        "--set",
        "solver.segments=4",
        "--set",
        "continuation.bounds=[0.0, 3.0]",
        "--set",
        "continuation.switch_depth=0",
    ];
    let mut args = vec!["continue", euler.as_str(), "-o", full.to_str().unwrap()];
    args.extend_from_slice(&sets);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let cases: [(&str, &[&str], &str); 2] = [
        (
            "0/3",
            &["--set", "solver.model=\"kirchhoff\""],
            "the stored point is of the planar model",
        ),
        (
            "special/0",
            &[],
            "switch at a stored branch point with the stored solver.method and mesh",
        ),
    ];
    for (point, extra, says) in cases {
        let o = continue_from(
            &euler,
            out.to_str().unwrap(),
            full.to_str().unwrap(),
            point,
            extra,
        );
        assert_eq!(o.status.code(), Some(2), "{point}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{point}: {}", stderr(&o));
        assert!(!out.exists(), "nothing written");
    }
}
