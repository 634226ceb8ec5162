//! No lost work, no clobbered file: every output is claimed before any
//! work (the directory must exist, the path must be absent or a regular
//! file that is not an input, `--force` to replace it, no second process
//! on it), images need `--force` like every other output, and what a killed
//! run leaves (lock, temporary files) does not stand in the next run's way.
mod common;
use common::problems::shipped;

use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::run::{run, stderr, BIN};

fn scratch(name: &str) -> PathBuf {
    common::run::scratch("lost", name)
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Exit 2 with every one of `expect` in stderr.
fn refused(o: &Output, expect: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for e in expect {
        assert!(err.contains(e), "`{e}` not in: {err}");
    }
}

#[test]
fn a_device_is_never_replaced() {
    let p = shipped("cantilever_tip_load");
    let o = run(&["solve", &p, "-o", "/dev/null", "--force"]);
    refused(&o, &["/dev/null", "not a regular file"]);
    let meta = std::fs::metadata("/dev/null").unwrap();
    assert!(
        meta.file_type().is_char_device(),
        "/dev/null is still a device"
    );
}

#[test]
fn the_input_is_never_the_output() {
    let dir = scratch("input");
    let problem = dir.join("p.toml");
    let text = std::fs::read_to_string(shipped("cantilever_tip_load")).unwrap();
    std::fs::write(&problem, &text).unwrap();
    let p = problem.to_str().unwrap();
    for args in [
        vec!["solve", p, "-o", p, "--force"],
        vec!["stability", p, "-o", p, "--force"],
    ] {
        refused(&run(&args), &["also an input"]);
        assert_eq!(std::fs::read_to_string(&problem).unwrap(), text);
    }
    // The same file under another name (a hard link) is still the input.
    let link = dir.join("q.h5");
    std::fs::hard_link(&problem, &link).unwrap();
    refused(
        &run(&["solve", p, "-o", link.to_str().unwrap(), "--force"]),
        &["also an input"],
    );
    assert_eq!(std::fs::read_to_string(&problem).unwrap(), text);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn directories_and_symbolic_links_are_refused() {
    let dir = scratch("kinds");
    let p = shipped("cantilever_tip_load");
    refused(
        &run(&["solve", &p, "-o", dir.to_str().unwrap(), "--force"]),
        &["a directory"],
    );
    let target = dir.join("target.h5");
    std::fs::write(&target, b"keep").unwrap();
    let link = dir.join("link.h5");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    refused(
        &run(&["solve", &p, "-o", link.to_str().unwrap(), "--force"]),
        &["a symbolic link"],
    );
    assert_eq!(std::fs::read(&target).unwrap(), b"keep");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A mistyped directory is found before a minute of work, not after it.
#[test]
fn a_missing_directory_is_found_before_any_work() {
    let missing = "/nonexistent-cosserat-dir/out.h5";
    for args in [
        vec!["sweep", &shipped("longest_arm_fig6") as &str, "-o", missing],
        vec!["optimize", &shipped("longest_arm"), "-o", missing],
        vec!["continue", &shipped("euler_column"), "-o", missing],
        vec![
            "optimize",
            &shipped("longest_arm"),
            "--loading-path",
            missing,
        ],
    ] {
        let t = Instant::now();
        let o = run(&args);
        refused(&o, &["nonexistent-cosserat-dir"]);
        assert!(
            t.elapsed() < Duration::from_secs(5),
            "{args:?}: refused only after {:?}",
            t.elapsed()
        );
        assert!(String::from_utf8_lossy(&o.stdout).is_empty() || !stderr(&o).is_empty());
    }
}

#[test]
fn one_file_named_twice_is_refused() {
    let dir = scratch("twice");
    let out = dir.join("d.h5");
    let o = run(&[
        "continue",
        &shipped("euler_column"),
        "-o",
        out.to_str().unwrap(),
        "--plot",
        out.to_str().unwrap(),
    ]);
    refused(&o, &["named twice"]);
    assert!(files(&dir).is_empty(), "{:?}", files(&dir));
    std::fs::remove_dir_all(dir).unwrap();
}

/// A second process on the same output is refused while the first runs;
/// the first finishes untouched.
#[test]
fn a_second_writer_is_refused() {
    let dir = scratch("lock");
    let out = dir.join("d.h5");
    let euler = shipped("euler_column");
    let args = [
        "continue",
        &euler,
        "-o",
        out.to_str().unwrap(),
        "--set",
        "continuation.step=0.002",
        "--set",
        "continuation.max_step=0.002",
        "--set",
        "continuation.max_points=100000",
    ];
    let mut first = Command::new(BIN)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    let second = run(&[&args[..], &["--force"]].concat());
    refused(&second, &["another cosserat process is writing"]);
    common::run::signal(&first, "-TERM");
    assert_eq!(first.wait().unwrap().code(), Some(130));
    assert_eq!(files(&dir), vec!["d.h5".to_string()], "no lock left");
    std::fs::remove_dir_all(dir).unwrap();
}

/// What a killed run leaves: a stale lock file and temporary files. The
/// next run takes the lock, removes the temporaries, and leaves only its
/// result.
#[test]
fn a_killed_runs_litter_is_cleared() {
    let dir = scratch("litter");
    let out = dir.join("c.h5");
    std::fs::write(dir.join(".c.h5.lock"), b"").unwrap();
    std::fs::write(dir.join(".c.h5.99999.tmp"), b"half a file").unwrap();
    std::fs::write(dir.join(".c.h5.other"), b"not ours").unwrap();
    let o = run(&[
        "solve",
        &shipped("cantilever_tip_load"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        files(&dir),
        vec![".c.h5.other".to_string(), "c.h5".to_string()]
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `plot` replaces an image only with `--force`, like every command.
#[test]
fn plot_needs_force() {
    let dir = scratch("plot");
    let diagram = dir.join("d.h5");
    let o = run(&[
        "continue",
        &shipped("euler_column"),
        "-o",
        diagram.to_str().unwrap(),
        "--set",
        "continuation.tip_angle_limit=60",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let png = dir.join("d.png");
    std::fs::write(&png, b"my figure").unwrap();
    let d = diagram.to_str().unwrap();
    let p = png.to_str().unwrap();
    refused(&run(&["plot", d, "-o", p]), &["exists", "--force"]);
    assert_eq!(std::fs::read(&png).unwrap(), b"my figure");
    refused(&run(&["plot", d, "-o", d, "--force"]), &["also an input"]);
    let o = run(&["plot", d, "-o", p, "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    assert_eq!(files(&dir), vec!["d.h5".to_string(), "d.png".to_string()]);
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--threads` is bounded: a million threads is an error, not a fork bomb.
#[test]
fn threads_are_bounded() {
    let dir = scratch("threads");
    let out = dir.join("s.h5");
    for n in ["1000000", "0", "100000"] {
        let o = run(&[
            "sweep",
            &shipped("longest_arm_fig6"),
            "-o",
            out.to_str().unwrap(),
            "--threads",
            n,
        ]);
        assert_eq!(o.status.code(), Some(2), "{n}: {}", stderr(&o));
        assert!(stderr(&o).contains("threads"), "{}", stderr(&o));
    }
    assert!(files(&dir).is_empty());
    std::fs::remove_dir_all(dir).unwrap();
}
