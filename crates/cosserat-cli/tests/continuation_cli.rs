//! `cosserat continue` from the command line: the HDF5 diagram contract and
//! a plot, interrupted and killed runs keeping their points, and a run
//! interrupted and resumed giving the file of an uninterrupted one.
mod common;

use cosserat::output::store::Group;

use std::path::Path;

use common::h5::{read_f64, stop_reason};
use common::problems::shipped;
use common::run::{entries, interrupt_after, scratch, signal, BIN};

#[test]
fn cli_writes_the_diagram_contract_and_a_plot() {
    let dir = scratch("continuation", "contract");
    let out = dir.join("euler.h5");
    let png = dir.join("euler.svg");
    let file = shipped("euler_column");
    let o = std::process::Command::new(BIN)
        .args([
            "continue",
            &file,
            "-o",
            out.to_str().unwrap(),
            "--plot",
            png.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = common::h5::open(&out);
    assert!(f.attrs.has("problem"));
    let b0 = f.group("branches/0").unwrap();
    let m = read_f64(b0, "parameter").len();
    assert!(m > 10);
    assert_eq!(b0.dataset("tip_position").unwrap().shape(), vec![m, 3]);
    assert_eq!(b0.dataset("eigenvalues").unwrap().shape()[0], m);
    assert_eq!(b0.dataset("stable").unwrap().shape(), vec![m]);
    assert_eq!(b0.dataset("morse_index").unwrap().shape(), vec![m]);
    let sp = f.group("special_points").unwrap();
    let kinds = sp.dataset("kind").unwrap().texts().unwrap().to_vec();
    assert!(kinds
        .iter()
        .all(|k| k.as_str() == "fold" || k.as_str() == "branch_point"));
    for name in [
        "branch",
        "index",
        "parameter",
        "tip_position",
        "null_vectors",
    ] {
        assert!(sp.dataset(name).is_ok(), "{name}");
    }
    let svg = std::fs::read_to_string(&png).unwrap();
    assert!(svg.contains("<svg") && svg.contains("BP1"));
    std::fs::remove_dir_all(dir).unwrap();
}

/// The parameter at the points of a diagram's first branch.
fn first_branch(f: &Group) -> Vec<f64> {
    read_f64(f.group("branches/0").unwrap(), "parameter")
}

/// `cosserat continue` on the Euler column with the arclength step fixed
/// at `step`, so that the run lasts long enough to be interrupted.
fn slow_euler(out: &Path, step: &str, extra: &[&str]) -> std::process::Command {
    let file = shipped("euler_column");
    let mut c = std::process::Command::new(BIN);
    c.args(["continue", &file, "-o", out.to_str().unwrap()])
        .args(["--set", &format!("continuation.step={step}")])
        .args(["--set", &format!("continuation.max_step={step}")])
        .args(["--set", "continuation.max_points=100000"])
        .args(extra)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
    c
}

#[test]
fn interrupted_run_keeps_its_points() {
    let dir = scratch("continuation", "interrupted");
    let out = dir.join("slow.h5");
    let mut child = slow_euler(&out, "0.0005", &[]).spawn().unwrap();
    let status = interrupt_after(&mut child, 2600);
    assert_eq!(status.code(), Some(130), "interrupted runs exit with 130");
    let f = common::h5::open(&out);
    assert_eq!(stop_reason(&f), "interrupted");
    let points = first_branch(&f);
    assert!(points.len() > 5, "{} points kept", points.len());
    // No temporary files left behind.
    let left = entries(&dir);
    assert_eq!(left.len(), 1, "{left:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A kill (SIGKILL, no handler runs) loses at most the last 2 s: the
/// checkpoint written while the run grew is a valid diagram file.
#[test]
fn killed_run_leaves_its_last_checkpoint() {
    let dir = scratch("continuation", "killed");
    let out = dir.join("slow.h5");
    // Steps of 0.00025: the straight branch alone (63 600 points) outlasts
    // the 3.5 s before the kill (at 0.0005 a faster build finished it).
    let mut child = slow_euler(&out, "0.00025", &[]).spawn().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(3500));
    child.kill().unwrap();
    let _ = child.wait();
    let f = common::h5::open(&out);
    let points = first_branch(&f);
    assert!(points.len() > 5, "{} points kept", points.len());
    assert!(points.windows(2).all(|w| w[1] > w[0]), "points in order");
    assert_eq!(
        stop_reason(&f),
        "in progress",
        "a checkpoint is never marked completed"
    );
    drop(f);
    // The lock of the killed process does not block the resumed run, which
    // goes on from the checkpoint (more points) and cleans up after itself.
    let mut child = slow_euler(&out, "0.00025", &["--resume"]).spawn().unwrap();
    let status = interrupt_after(&mut child, 3000);
    assert_eq!(status.code(), Some(130));
    let f = common::h5::open(&out);
    let more = first_branch(&f);
    assert!(
        more.len() > points.len(),
        "{} → {}",
        points.len(),
        more.len()
    );
    assert_eq!(more[..points.len()], points[..], "the kept points are kept");
    let left = entries(&dir);
    assert_eq!(left.len(), 1, "no lock or temporary file left: {left:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Interrupt a run (SIGINT, then SIGTERM, then SIGHUP), resume it each
/// time, and get the file an uninterrupted run writes: the same datasets,
/// bit for bit.
#[test]
fn interrupted_run_resumes_to_the_same_diagram() {
    let dir = scratch("continuation", "resumed");
    let (partial, full) = (dir.join("partial.h5"), dir.join("full.h5"));
    // Steps of 0.002: the whole diagram takes ≈ 3 s of CPU, so the run is
    // still going at 1.5 s (at 0.004 a faster build finished it sooner).
    let command = |out: &Path, extra: &[&str]| slow_euler(out, "0.002", extra);
    let mut child = command(&partial, &[]).spawn().unwrap();
    let status = interrupt_after(&mut child, 1500);
    assert_eq!(
        status.code(),
        Some(130),
        "the run should still be going at 1.5 s"
    );
    for sig in ["-TERM", "-HUP"] {
        let mut child = command(&partial, &["--resume"]).spawn().unwrap();
        std::thread::sleep(std::time::Duration::from_millis(700));
        signal(&child, sig);
        let code = child.wait().unwrap().code();
        assert!(matches!(code, Some(0 | 130)), "{sig}: {code:?}");
    }
    assert!(command(&partial, &["--resume"]).status().unwrap().success());
    assert!(command(&full, &[]).status().unwrap().success());
    for f in [&partial, &full] {
        assert_eq!(stop_reason(&common::h5::open(f)), "completed");
    }
    common::h5::assert_same_datasets(&partial, &full);
    let left = entries(&dir);
    assert_eq!(left.len(), 2, "no lock or temporary file left: {left:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// `cosserat bench continue` prints its timing and the diagram it timed:
/// the median, and the in-plane branch point of the Euler column at
/// π²/4 (Euler 1744) to the 12 digits it prints. No timing is asserted.
#[test]
fn bench_continue_names_the_median_and_the_special_points() {
    let file = shipped("euler_column");
    let o = std::process::Command::new(BIN)
        .args(["bench", "continue", &file, "--repeat", "2"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("median"), "{text}");
    assert!(text.contains("over 2 runs"), "{text}");
    let in_plane = text
        .lines()
        .find(|l| l.starts_with("special") && l.contains("branch_point") && l.contains("in_plane"))
        .unwrap_or_else(|| panic!("no in-plane branch point in\n{text}"));
    let p: f64 = in_plane
        .split("at parameter ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no parameter in {in_plane}"));
    let euler = std::f64::consts::PI.powi(2) / 4.0;
    assert!((p - euler).abs() < 1e-10, "{p} against π²/4 = {euler}");
    assert!(text.contains("out_of_plane"), "{text}");
}
