//! Fuzzing every command's option parsing: random argument vectors built
//! from the commands' own vocabulary and from arbitrary strings never
//! panic, and every rejection is a usage error (clap's exit code 2) that
//! names what is wrong.

use clap::Parser;
use cosserat_cli::cli::Cli;
use proptest::prelude::*;
#[path = "../../cosserat/tests/support/mod.rs"]
mod support;
use support::fuzz::runner;

const WORDS: &[&str] = &[
    "solve",
    "stability",
    "continue",
    "plot",
    "optimize",
    "validate",
    "bench",
    "work-precision",
    "help",
    "-o",
    "--output",
    "--set",
    "--force",
    "--method",
    "--plot",
    "--resume",
    "--measure",
    "--loading-path",
    "--control-path",
    "--holding-path",
    "--quick",
    "--case",
    "--cases",
    "-h",
    "--help",
    "-V",
    "problems/cantilever_tip_load.toml",
    "x.h5",
    "x.png",
    "rod.length=2",
    "solver.method=\"collocation\"",
    "shooting",
    "collocation",
    "multiple-shooting",
    "tip_x",
    "norm",
    "=",
    "--",
    "-",
    "",
    "é",
    "--set=a=b",
    "sweep",
    "merge",
    "--shard",
    "--threads",
    "0/2",
    "2/1",
    "0",
    "a.h5",
];

fn cases() -> u32 {
    std::env::var("COSSERAT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100_000)
}

fn check(args: Vec<String>) -> Result<(), TestCaseError> {
    let argv: Vec<String> = std::iter::once("cosserat".to_string())
        .chain(args)
        .collect();
    let parsed = std::panic::catch_unwind(|| {
        Cli::try_parse_from(&argv).map_err(|e| (e.exit_code(), e.to_string()))
    });
    let outcome = parsed.map_err(|_| TestCaseError::fail(format!("panic on {argv:?}")))?;
    if let Err((code, message)) = outcome {
        // Help and version requests exit 0; everything else is a usage error.
        prop_assert!(code == 2 || code == 0, "exit code {code} for {argv:?}");
        prop_assert!(!message.trim().is_empty(), "empty message for {argv:?}");
    }
    Ok(())
}

#[test]
fn vocabulary_argument_vectors_never_panic() {
    let strategy = prop::collection::vec(0..WORDS.len(), 0..8);
    runner(cases() / 2)
        .run(&strategy, |idx| {
            check(idx.into_iter().map(|i| WORDS[i].to_string()).collect())
        })
        .unwrap();
}

#[test]
fn arbitrary_argument_vectors_never_panic() {
    let strategy = prop::collection::vec(".{0,16}", 0..6);
    runner(cases() - cases() / 2).run(&strategy, check).unwrap();
}
