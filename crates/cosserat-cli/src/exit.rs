//! The exit codes of `cosserat` — the one table (README, "Exit codes"):
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success: the result is written |
//! | 1 | the output could not be written after the run (an I/O failure: disk full, a directory removed meanwhile) |
//! | 2 | bad input: the problem file, a `--set`, the command line, an input or output path; nothing was computed or written |
//! | 3 | no result of the asked quality: the solver did not converge, a verdict is undecided where one was required, a validation case failed |
//! | 130 | interrupted (SIGINT, SIGTERM or SIGHUP): what was finished is written as a resumable file |
//!
//! Nothing else leaves the process: a panic (101) is a bug.

use std::process::ExitCode;

/// The output could not be written after the run.
pub const OUTPUT: u8 = 1;
/// Bad input; nothing was computed or written.
pub const BAD_INPUT: u8 = 2;
/// No result of the asked quality (no convergence, a failed check).
pub const NO_RESULT: u8 = 3;
/// Stopped by a signal; finished work is written.
pub const INTERRUPTED: u8 = 130;

/// Prints `error: message` and returns `code`.
pub fn fail(code: u8, message: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {message}");
    ExitCode::from(code)
}
