//! SIGINT, SIGTERM or SIGHUP at random moments of `optimize` and `sweep`,
//! then `--resume` until the run completes: the file is the one an
//! uninterrupted run writes, bit for bit in its datasets. (`continue` is
//! checked the same way in tests/continuation_cli.rs and, at every point of
//! the shipped diagrams, in tests/resume.rs.)
mod common;
use common::problems::shipped;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_cosserat");

/// Runs `args` with `-o out` (and `--resume` after the first run),
/// signalling each run after the given delays, then once more to the end.
fn interrupted_then_resumed(args: &[&str], out: &Path, delays_ms: &[u64]) {
    let o = out.to_str().unwrap();
    let signals = ["-INT", "-TERM", "-HUP"];
    for (i, &ms) in delays_ms.iter().enumerate() {
        let mut c = Command::new(BIN);
        c.args(args).args(["-o", o]);
        if i > 0 {
            c.arg("--resume");
        }
        let mut child = c
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(ms));
        let _ = Command::new("kill")
            .args([signals[i % 3], &child.id().to_string()])
            .status();
        let code = child.wait().unwrap().code();
        assert!(
            matches!(code, Some(0 | 130)),
            "run {i} signalled at {ms} ms: {code:?}"
        );
    }
    let status = Command::new(BIN)
        .args(args)
        .args(["-o", o, "--resume"])
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
}

fn uninterrupted(args: &[&str], out: &Path) {
    let status = Command::new(BIN)
        .args(args)
        .args(["-o", out.to_str().unwrap()])
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cosserat-ir-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Delays from a seed: moments spread over the run.
fn delays(seed: u64, n: usize, max_ms: u64) -> Vec<u64> {
    let mut x = seed;
    (0..n)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            50 + (x >> 33) % max_ms
        })
        .collect()
}

#[test]
fn optimize_resumes_to_the_uninterrupted_file() {
    let dir = scratch("optimize");
    let p = shipped("longest_arm_fig5");
    let args = ["optimize", p.as_str(), "--set", "arm.map_samples=300"];
    let full = dir.join("full.h5");
    uninterrupted(&args, &full);
    for seed in 1..=3 {
        let part = dir.join(format!("part{seed}.h5"));
        interrupted_then_resumed(&args, &part, &delays(seed, 3, 900));
        common::h5::assert_same_datasets(&part, &full);
    }
    let left = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(left, 4, "no lock or temporary file left");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn sweep_resumes_to_the_uninterrupted_file() {
    let dir = scratch("sweep");
    let p = shipped("longest_arm_fig7");
    let args = [
        "sweep",
        p.as_str(),
        "--threads",
        "2",
        "--set",
        "sweep.axes=[{ key = \"energy.stiffness[0]\", values = [1.0, 4.0] }, { key = \"arm.alpha\", values = [30, 15, 0] }]",
    ];
    let full = dir.join("full.h5");
    uninterrupted(&args, &full);
    for seed in 1..=2 {
        let part = dir.join(format!("part{seed}.h5"));
        interrupted_then_resumed(&args, &part, &delays(seed, 3, 2500));
        common::h5::assert_same_datasets(&part, &full);
    }
    std::fs::remove_dir_all(dir).unwrap();
}
