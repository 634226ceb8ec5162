//! A resumed continuation is the uninterrupted one, bit for bit: runs of
//! the shipped diagrams (one direction, and `both_directions` with branch
//! switching) are stopped after k points for many k, written to a diagram
//! file, read back and resumed; the resumed diagram must equal the
//! uninterrupted one exactly (every parameter, unknown, tangent,
//! eigenvalue, shape, special point and stop reason).

use std::path::Path;

use cosserat::continuation::{continuation, resume, Diagram};
use cosserat::input::Problem;
use cosserat::output::{read_saved, write_diagram};

fn problem(name: &str, set: &[&str]) -> Problem {
    let path = format!(
        "{}/problems/{name}.toml",
        concat!(env!("CARGO_MANIFEST_DIR"), "/../..")
    );
    let set: Vec<String> = set.iter().map(std::string::ToString::to_string).collect();
    Problem::from_path(Path::new(&path), &set).unwrap()
}

fn points(d: &Diagram) -> usize {
    d.branches.iter().map(|b| b.points.len()).sum()
}

/// Stops after `k` monitor calls, round-trips the diagram through a file,
/// resumes it, and compares with `full`.
fn check_resume(p: &Problem, full: &Diagram, k: usize, dir: &Path) {
    let (family, opts) = p.continuation.as_ref().unwrap();
    let mut calls = 0;
    let partial = continuation(family, opts, &mut |_, _| {
        calls += 1;
        calls < k
    })
    .unwrap();
    assert_eq!(partial.stop_reason, "interrupted", "k = {k}");
    let file = dir.join(format!("k{k}.h5"));
    write_diagram(&file, &p.text, "p", &partial, true).unwrap();
    let (_, saved) = read_saved(&file).unwrap();
    assert_eq!(saved.stop_reason, "interrupted");
    let resumed = resume(family, opts, &saved, &mut |_, _| true).unwrap();
    assert_eq!(resumed.stop_reason, "completed", "k = {k}");
    assert_eq!(resumed.branches.len(), full.branches.len(), "k = {k}");
    for (i, (a, b)) in resumed.branches.iter().zip(&full.branches).enumerate() {
        assert_eq!(a.points.len(), b.points.len(), "k = {k}, branch {i}");
        for (j, (x, y)) in a.points.iter().zip(&b.points).enumerate() {
            assert_eq!(x, y, "k = {k}, branch {i}, point {j}");
        }
        assert_eq!(a, b, "k = {k}, branch {i}");
    }
    assert_eq!(resumed.special_points, full.special_points, "k = {k}");
    assert_eq!(&resumed, full, "k = {k}");
}

fn study(name: &str, set: &[&str]) {
    let p = problem(name, set);
    let (family, opts) = p.continuation.as_ref().unwrap();
    let full = continuation(family, opts, &mut |_, _| true).unwrap();
    assert_eq!(full.stop_reason, "completed");
    let dir = std::env::temp_dir().join(format!("cosserat-resume-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let total = points(&full);
    // Early, late, and at every branch boundary of the uninterrupted run.
    let mut ks: Vec<usize> = vec![1, 2, 3, total / 3, total / 2, total - 2];
    let mut seen = 0;
    for b in &full.branches {
        seen += b.points.len().saturating_sub(1);
        ks.extend([seen.saturating_sub(1), seen, seen + 1]);
    }
    ks.retain(|&k| k >= 1 && k < total.saturating_sub(full.branches.len()));
    ks.sort_unstable();
    ks.dedup();
    eprintln!(
        "{name}: {total} points, {} branches, {} specials, ks {ks:?}",
        full.branches.len(),
        full.special_points.len()
    );
    for k in ks {
        check_resume(&p, &full, k, &dir);
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Euler's column: the trivial branch, the branch point, the switched
/// branches up to the tip-angle limit.
#[test]
fn euler_column_resumes_bit_for_bit() {
    study("euler_column", &["continuation.tip_angle_limit=120"]);
}

/// A start followed in both directions: the backward half is resumed
/// backwards (it used to retrace the forward half and report completed).
#[test]
fn both_directions_resume_bit_for_bit() {
    study("planar_clamp_angle", &[]);
}
