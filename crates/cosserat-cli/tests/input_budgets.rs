//! Issue 14, the input side, continued from input_limits.rs: counts and
//! sizes that could reach a computation (eigenvalue counts and stability
//! options beyond the mesh, the memory budget, the problem file's size and
//! type) are refused before any work, naming the key and what to do; where
//! a bad count reaches a computation from a library caller, the
//! computation returns an error instead of panicking.

mod common;

use common::problems::{accepted, refusal, shipped_text, CANTILEVER};
use cosserat::input::Problem;

/// Crashes: `continuation.eigenvalues = 100` on 16 elements of order 2
/// indexed past the tracker's columns. Refused at input with the block's
/// size; and the tracker itself returns an error where a count beyond the
/// mesh reaches it (a library caller), instead of panicking.
#[test]
fn eigenvalue_counts_beyond_the_mesh_are_refused_not_a_panic() {
    use cosserat::continuation::continuation;
    let text = shipped_text("euler_column");
    let e = refusal(&text, &["continuation.eigenvalues=100"]);
    assert!(
        e.contains("continuation.eigenvalues") && e.contains("32 unknowns"),
        "{e}"
    );
    accepted(&text, &["continuation.eigenvalues=32"]);
    let e = refusal(&text, &["stability.eigenvalues=401"]);
    assert!(
        e.contains("stability.eigenvalues") && e.contains("400 unknowns"),
        "{e}"
    );
    // A support removes up to six unknowns.
    let e = refusal(
        CANTILEVER,
        &[
            "support.rotation=\"fixed\"",
            "support.translation=\"free\"",
            "stability.elements=2",
            "stability.order=1",
            "stability.eigenvalues=1",
        ],
    );
    assert!(e.contains("stability.eigenvalues"), "{e}");
    // Past the reader: the computation says why.
    let p = accepted(&text, &[]);
    let (family, mut opts) = p.continuation.clone().unwrap();
    opts.stability = opts.stability.with_eigenvalues(100).unwrap();
    opts.max_points = 3;
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        continuation(&family, &opts, &mut |_, _| true)
    }));
    let e = match outcome.expect("no panic") {
        Ok(_) => panic!("100 eigenvalues on 32 unknowns were accepted"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("continuation.eigenvalues"), "{e}");
}

/// Memory: sizes that exhausted the machine are refused by the reader,
/// before anything is allocated, naming the key and the estimate.
#[test]
fn sizes_beyond_the_memory_budget_are_refused_with_the_estimate() {
    let column = shipped_text("euler_column");
    let arm = std::fs::read_to_string(concat!(
        concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
        "/problems/longest_arm_fig6.toml"
    ))
    .unwrap();
    let cases: [(&str, &[&str], &str); 7] = [
        (CANTILEVER, &["solver.output_points=1000000000000"], "solver.output_points"),
        (
            CANTILEVER,
            &["solver.method=\"multiple-shooting\"", "solver.segments=1000000"],
            "solver.segments",
        ),
        (
            CANTILEVER,
            &["solver.method=\"collocation\"", "solver.max_intervals=100000000"],
            "solver.max_intervals",
        ),
        (CANTILEVER, &["stability.elements=100000000"], "stability.elements"),
        (&column, &["continuation.max_points=1000000000"], "continuation.max_points"),
        (&arm, &["arm.map_samples=100000000000"], "arm.map_samples"),
        (
            &arm,
            &["sweep.axes=[{key=\"energy.stiffness[0]\",linspace=[0.25,7,1000]},{key=\"energy.stiffness[2]\",linspace=[0.2,4,1000]}]", "sweep.families=2"],
            "sweep.axes",
        ),
    ];
    // Continuation's systems are O(N) above 200 unknowns (band LU, the
    // kernel by inverse iteration): the largest mesh the key allows fits,
    // with its stored points bounded.
    accepted(
        &column,
        &[
            "solver.method=\"collocation\"",
            "continuation.intervals=10000",
            "continuation.max_points=100",
        ],
    );
    for (text, sets, field) in cases {
        let e = refusal(text, sets);
        assert!(
            e.starts_with(field) && e.contains("would allocate about") && e.contains("budget"),
            "{sets:?}: {e}"
        );
    }
    // The shipped problems fit with room to spare.
    let dir = concat!(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."), "/problems");
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let p = Problem::from_path(&path, &[]).unwrap();
        let total = cosserat::input::memory::estimate(&p).total();
        assert!(total < 1e9, "{}: {total:e}", path.display());
    }
}

/// The budget is COSSERAT_MEMORY_BUDGET (bytes, with a suffix) — run in
/// the binary so that the variable does not leak into parallel tests.
#[test]
fn the_memory_budget_comes_from_the_environment() {
    let dir = std::env::temp_dir().join(format!("cosserat-limits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("p.toml");
    std::fs::write(&file, CANTILEVER).unwrap();
    let run = |budget: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_cosserat"))
            .args(["solve", file.to_str().unwrap()])
            .args([
                "--set",
                "solver.output_points=100000",
                "--set",
                "stability.elements=10",
            ])
            .arg("-o")
            .arg(dir.join(format!("out-{}.h5", budget.replace(' ', ""))))
            .env("COSSERAT_MEMORY_BUDGET", budget)
            .output()
            .unwrap()
    };
    // 100000 points × 528 bytes = 50 MiB.
    let small = run("20M");
    let err = String::from_utf8_lossy(&small.stderr);
    assert!(
        !small.status.success() && err.contains("solver.output_points") && err.contains("20.0 MiB"),
        "{err}"
    );
    let large = run("1 GiB");
    assert!(
        large.status.success(),
        "{}",
        String::from_utf8_lossy(&large.stderr)
    );
    let bad = run("lots");
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains("COSSERAT_MEMORY_BUDGET"),
        "{err}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A problem file over 1 MiB is refused before it is read, and a
/// directory, a device or a FIFO is refused by its type (reading /dev/zero
/// never ended; opening a FIFO blocks) — each quickly, naming the path.
#[test]
fn problem_files_are_bounded_regular_files() {
    use std::fmt::Write as _;
    use std::path::Path;
    use std::time::Instant;
    let dir = std::env::temp_dir().join(format!("cosserat-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let big = dir.join("big.toml");
    let mut text = CANTILEVER.to_string();
    writeln!(text, "# {}", "x".repeat(1 << 20)).expect("writing to a String cannot fail");
    std::fs::write(&big, text).unwrap();
    let fifo = dir.join("fifo.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    let mut paths: Vec<(&Path, &str)> = vec![
        (&big, "1 MiB"),
        (Path::new("/dev/zero"), "not a regular file"),
        (&dir, "directory"),
    ];
    if made.is_ok_and(|s| s.success()) {
        paths.push((&fifo, "not a regular file"));
    }
    for (path, expect) in paths {
        let t = Instant::now();
        let e = Problem::from_path(path, &[])
            .expect_err("refused")
            .to_string();
        assert!(t.elapsed().as_secs_f64() < 1.0);
        assert!(
            e.contains(&path.display().to_string()) && e.contains(expect),
            "{e}"
        );
    }
    // The text itself (a library caller) is bounded too.
    let e = refusal(&format!("{CANTILEVER}#{}\n", "y".repeat(1 << 20)), &[]);
    assert!(e.contains("1048576"), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Item 8 (a failure becoming a value): options no mesh can honour were
/// clamped silently (order 5 ran at order 3); the analyses now say so.
#[test]
fn stability_options_out_of_range_are_errors_not_clamps() {
    use cosserat::model::{Clamp, DeadLoads, LinearElastic, Profile, Rod};
    use cosserat::stability::{critical_load, FixedShape, StabilityOptions};
    let rod = Rod::new(
        1.0,
        std::sync::Arc::new(LinearElastic::uniform([1.0, 1.0, 1.0], [0.0; 3]).unwrap()),
        Clamp::paper(),
        DeadLoads {
            tip_force: nalgebra::Vector3::new(1.0, 0.0, 0.0),
            ..Default::default()
        },
        None,
    )
    .unwrap();
    let shape = FixedShape {
        turning_angle: Profile::Constant(0.0),
    };
    // Options no mesh can honour cannot be built at all, so no analysis
    // can receive them.
    for (elements, order) in [(10, 5), (0, 2), (10, 0)] {
        let e = StabilityOptions::new(elements, order, 1)
            .expect_err("refused")
            .to_string();
        assert!(e.contains("order 1, 2 or 3"), "{e}");
    }
    let opts = StabilityOptions::new(10, 2, 1).unwrap();
    assert!(critical_load(&rod, &shape, &opts).is_ok());
}
