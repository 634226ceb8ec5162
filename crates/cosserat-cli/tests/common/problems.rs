//! Problem files the tests share: the shipped ones by name, the smallest
//! valid problem, and reading a text that must be refused or accepted.
#![allow(dead_code)]

use std::path::Path;

use cosserat::input::Problem;

/// The repository's root (problems/, validation/).
pub const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// The path of the shipped problem `name` (problems/<name>.toml).
pub fn shipped(name: &str) -> String {
    format!("{ROOT}/problems/{name}.toml")
}

/// The text of the shipped problem `name`.
pub fn shipped_text(name: &str) -> String {
    std::fs::read_to_string(shipped(name)).unwrap()
}

/// The shipped problem `name`, read without overrides.
pub fn load(name: &str) -> Problem {
    Problem::from_path(Path::new(&shipped(name)), &[]).unwrap()
}

/// A planar cantilever under a tip load: the smallest valid problem.
pub const CANTILEVER: &str = "
[rod]
length = 1.0
[energy]
stiffness = [1.0, 1.0, 1.0]
[loads]
tip_force = [1.0, 0.0, 0.0]
";

/// The error text of `text` with `overrides`; panics when accepted.
pub fn refusal(text: &str, overrides: &[&str]) -> String {
    let overrides: Vec<String> = overrides
        .iter()
        .map(std::string::ToString::to_string)
        .collect();
    match Problem::from_str_with(text, &overrides) {
        Ok(_) => panic!("accepted: {overrides:?}"),
        Err(e) => e.to_string(),
    }
}

/// The problem `text` with `overrides`; panics when refused.
pub fn accepted(text: &str, overrides: &[&str]) -> Problem {
    let overrides: Vec<String> = overrides
        .iter()
        .map(std::string::ToString::to_string)
        .collect();
    Problem::from_str_with(text, &overrides).unwrap_or_else(|e| panic!("{overrides:?}: {e}"))
}
