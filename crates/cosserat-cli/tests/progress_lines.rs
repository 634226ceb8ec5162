//! Progress of `continue`, `sweep` and `optimize` where stderr is not a
//! terminal (a cluster log, a pipe): plain
//! timed lines with done/total, rate and time left (issue 19, item 6). The
//! interval is set to 0 s here so every update prints.

mod common;

use std::process::Command;

use common::problems::shipped;
use common::run::{scratch, BIN};

fn run_logged(args: &[&str]) -> String {
    let out = Command::new(BIN)
        .args(args)
        .env("COSSERAT_PROGRESS_SECONDS", "0")
        .output()
        .expect("the binary runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn continuation_and_sweep_report_progress_in_a_log() {
    let dir = scratch("progress_lines", "runs");
    let diagram = dir.join("euler.h5");
    let log = run_logged(&[
        "continue",
        &shipped("euler_column"),
        "-o",
        diagram.to_str().unwrap(),
    ]);
    assert!(
        log.lines()
            .any(|l| l.starts_with("progress  ") && l.contains("points, branch")),
        "{log}"
    );
    let sweep = dir.join("sweep.h5");
    let log = run_logged(&[
        "sweep",
        &shipped("cantilever_tip_load"),
        "-o",
        sweep.to_str().unwrap(),
        "--set",
        "sweep.axes=[{key=\"loads.tip_force[0]\", values=[1.0, 2.0, 3.0]}]",
    ]);
    let last = log.lines().rfind(|l| l.starts_with("progress  "));
    assert!(
        last.is_some_and(|l| l.contains("3/3 points") && l.contains("/s")),
        "{log}"
    );
}

#[test]
fn an_optimization_reports_progress_in_a_log() {
    let dir = scratch("progress_lines", "optimize");
    let out = dir.join("arm.h5");
    let log = run_logged(&[
        "optimize",
        &shipped("longest_arm"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        log.lines()
            .any(|l| l.starts_with("progress  ") && l.contains(" points, ")),
        "{log}"
    );
}
