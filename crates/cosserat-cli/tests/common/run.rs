//! Running the built `cosserat` binary from a test: the binary, a scratch
//! directory per test, the output and its stderr.
#![allow(dead_code)]

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output};
use std::time::Duration;

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_cosserat");

/// A fresh, empty directory for one test (`prefix` names the test file).
pub fn scratch(prefix: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cosserat-{prefix}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the binary with `args` to its end.
pub fn run(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The run's stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The names of the files in `dir` (to check that nothing was left behind).
pub fn entries(dir: &Path) -> Vec<OsString> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect()
}

/// Sends `signal` (`-INT`, `-TERM`, `-HUP`, ...) to `child`.
pub fn signal(child: &Child, signal: &str) {
    let _ = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status();
}

/// Sends SIGINT after `ms` milliseconds and waits for the exit.
pub fn interrupt_after(child: &mut Child, ms: u64) -> ExitStatus {
    std::thread::sleep(Duration::from_millis(ms));
    signal(child, "-INT");
    child.wait().unwrap()
}

/// A `special N …` line of `continue`'s output: how the point was located
/// (the word after "located"), its printed parameter and its printed
/// error "(error of the parameter ±E)", if any.
pub fn special_line(line: &str) -> (String, f64, Option<f64>) {
    let parameter = line
        .split("at parameter ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no parameter in {line}"));
    let located = line
        .split("located ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap_or_else(|| panic!("no location in {line}"))
        .to_string();
    let error = line
        .split("(error of the parameter ±")
        .nth(1)
        .map(|r| r.trim_end_matches(')').parse().expect("a printed error"));
    (located, parameter, error)
}
