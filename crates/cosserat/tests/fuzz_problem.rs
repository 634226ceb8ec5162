//! Fuzzing the problem-file reader: mutated problem files and random
//! `--set` overrides must never panic, and every rejection must name a line
//! or a field.
//!
//! The number of inputs is `COSSERAT_FUZZ_CASES` (default 100 000, split
//! over the three generators below). The seeds are every shipped problem
//! file and the corpus in tests/corpus/: bad inputs kept with the field
//! their rejection must name (`# expect: …` on the first line), so that a
//! class of bad input once covered stays covered.

use cosserat::input::Problem;
use proptest::prelude::*;
mod support;
use support::fuzz::runner;

/// The seeds: problems/*.toml and tests/corpus/*.toml, sorted by path so
/// that the generators are deterministic.
fn bases() -> &'static [String] {
    static BASES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    BASES.get_or_init(|| {
        let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
        let mut paths: Vec<_> = ["problems", "crates/cosserat/tests/corpus"]
            .iter()
            .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap())
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        paths.sort();
        paths
            .iter()
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect()
    })
}

/// Every corpus file is rejected with a message naming what its first line
/// expects.
#[test]
fn corpus_rejections_name_their_field() {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("crates/cosserat/tests/corpus");
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let expect = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{}: no `# expect:` line", path.display()));
        let err = Problem::from_str_with(&text, &[])
            .err()
            .unwrap_or_else(|| panic!("{}: accepted", path.display()))
            .to_string();
        assert!(err.contains(expect), "{}: {err}", path.display());
        seen += 1;
    }
    assert!(seen >= 10, "{seen} corpus files");
}

const KEYS: [&str; 35] = [
    "rod.length",
    "energy.kind",
    "energy.stiffness",
    "energy.intrinsic_curvature",
    "energy.quartic",
    "clamp.position",
    "clamp.d1",
    "clamp.d3",
    "loads.tip_force",
    "loads.tip_couple",
    "loads.distributed_force",
    "solver.method",
    "solver.segments",
    "solver.model",
    "solver.strategy",
    "solver.tolerance",
    "solver.max_iterations",
    "solver.integration_tolerance",
    "solver.max_steps",
    "solver.output_points",
    "solver.initial_curvature",
    "rod.colour",
    "energy.shear",
    "energy.parameters.quartic",
    "energy.parameters.x",
    "clamp.angle",
    "clamp.hinge",
    "support.translation",
    "support.rotation",
    "support.axis",
    "support.position",
    "support.d3",
    "continuation.step",
    "arm.coefficients",
    "arm.alpha",
];

const VALUES: [&str; 30] = [
    "0",
    "-1",
    "1",
    "2.5",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "-inf",
    "\"x\"",
    "true",
    "[]",
    "[1]",
    "[1, 2]",
    "[1, 2, 3]",
    "[0, 0, 0]",
    "[nan, 0, 0]",
    "[1, 2, 3, 4]",
    "[\"a\", 1, 2]",
    "{polynomial = []}",
    "{polynomial = [1, -5]}",
    "{s = [0, 1], values = [1]}",
    "{s = [1, 0], values = [1, 2]}",
    "{s = [0, 1], values = [1, 2]}",
    "[1, {polynomial = [1, 2]}, 1]",
    "[1, {s = [0, 0.5, 1], values = [1, -1, 1]}, 1]",
    "\"multiple-shooting\"",
    "\"planar\"",
    "{a = 1}",
];

fn cases() -> u32 {
    std::env::var("COSSERAT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100_000)
}

use std::sync::atomic::{AtomicUsize, Ordering};

/// Accepted and rejected inputs, to show that both paths are exercised.
static ACCEPTED: AtomicUsize = AtomicUsize::new(0);
static REJECTED: AtomicUsize = AtomicUsize::new(0);

/// The reader's verdict must be a Problem or an error that names where.
fn check(text: &str, overrides: &[String]) -> Result<(), TestCaseError> {
    let outcome = std::panic::catch_unwind(|| Problem::from_str_with(text, overrides));
    let result =
        outcome.map_err(|_| TestCaseError::fail(format!("panic on:\n{text}\n{overrides:?}")))?;
    match result {
        Ok(p) => {
            ACCEPTED.fetch_add(1, Ordering::Relaxed);
            prop_assert!(p.rod.length().is_finite() && p.rod.length() > 0.0);
            prop_assert!(p.options.output_points >= 2);
        }
        Err(e) => {
            REJECTED.fetch_add(1, Ordering::Relaxed);
            let m = e.to_string();
            let named =
                m.contains("line ") || m.contains('`') || m.contains("--set") || m.contains(':');
            prop_assert!(named, "rejection names nothing: {m}");
        }
    }
    Ok(())
}

/// Byte-level edits: delete, insert from a TOML alphabet, or replace.
#[test]
fn byte_mutations_never_panic() {
    let alphabet: Vec<char> = "[]{}=,.\"'#\n 0123456789-+einfaxyz_".chars().collect();
    let strategy = (
        0..bases().len(),
        prop::collection::vec(
            (
                any::<prop::sample::Index>(),
                0..3u8,
                any::<prop::sample::Index>(),
            ),
            1..6,
        ),
    );
    runner(cases() / 3)
        .run(&strategy, |(base, edits)| {
            let mut chars: Vec<char> = bases()[base].chars().collect();
            for (at, op, pick) in edits {
                let i = at
                    .index(chars.len().max(1))
                    .min(chars.len().saturating_sub(1));
                let c = *pick.get(&alphabet);
                match op {
                    0 if !chars.is_empty() => {
                        chars.remove(i);
                    }
                    1 => chars.insert(i, c),
                    _ if !chars.is_empty() => chars[i] = c,
                    _ => {}
                }
            }
            check(&chars.into_iter().collect::<String>(), &[])
        })
        .unwrap();
}

/// Whole values replaced through `--set`, including non-physical ones.
#[test]
fn value_overrides_never_panic() {
    let strategy = (
        0..bases().len(),
        prop::collection::vec((0..KEYS.len(), 0..VALUES.len()), 1..4),
    );
    runner(cases() / 3)
        .run(&strategy, |(base, sets)| {
            let overrides: Vec<String> = sets
                .iter()
                .map(|&(k, v)| format!("{}={}", KEYS[k], VALUES[v]))
                .collect();
            check(&bases()[base], &overrides)
        })
        .unwrap();
    let (a, r) = (
        ACCEPTED.load(Ordering::Relaxed),
        REJECTED.load(Ordering::Relaxed),
    );
    assert!(
        a > 0 && r > 0,
        "accepted {a}, rejected {r}: a generator is degenerate"
    );
}

/// Arbitrary override strings (malformed keys, empty values, unicode).
#[test]
fn arbitrary_override_strings_never_panic() {
    let strategy = (0..bases().len(), prop::collection::vec(".{0,24}", 1..3));
    runner(cases() - 2 * (cases() / 3))
        .run(&strategy, |(base, overrides)| {
            check(&bases()[base], &overrides)
        })
        .unwrap();
}
