//! `cosserat bench solve|stability|continue|optimize --csv`: every verb on
//! a shipped problem with `--repeat 2` writes a CSV whose columns parse,
//! with min ≤ median ≤ max and the accuracy against references computed
//! here (the Bisshopp–Drucker closed form, Timoshenko's 4.0126) or `none`
//! where no validation case is the problem; bad input exits 2 and writes
//! nothing. No timing is asserted.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::problems::shipped;
use common::run::{entries, run, scratch, stderr};

/// One CSV row as header name → field.
type Row = BTreeMap<String, String>;

/// Splits one CSV line (RFC 4180 quoting: "a,b" and "" inside quotes).
fn fields(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                out.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(String::new()),
            _ => out.last_mut().unwrap().push(c),
        }
    }
    out
}

/// The rows of a bench CSV, each with as many fields as the header.
fn read_csv(path: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = fields(lines.next().expect("a header"));
    lines
        .map(|l| {
            let f = fields(l);
            assert_eq!(f.len(), header.len(), "row {l}");
            header.iter().cloned().zip(f).collect()
        })
        .collect()
}

fn number(row: &Row, column: &str) -> f64 {
    let v = &row[column];
    v.parse()
        .unwrap_or_else(|_| panic!("{column} = `{v}` is not a number"))
}

/// Runs `bench VERB PROBLEM --repeat 2 --csv FILE ARGS…`; the rows, each
/// checked for its timing columns.
fn bench(verb: &str, problem: &str, args: &[&str]) -> Vec<Row> {
    let dir = scratch("bench", &format!("{verb}-{}", args.len()));
    let csv = dir.join("bench.csv");
    let csv_arg = csv.to_str().unwrap();
    let mut all = vec!["bench", verb, problem, "--repeat", "2", "--csv", csv_arg];
    all.extend_from_slice(args);
    let o = run(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = read_csv(&csv);
    assert!(!rows.is_empty());
    for row in &rows {
        assert_eq!(row["command"], verb);
        assert_eq!(row["runs"], "2");
        let (median, min, max) = (
            number(row, "median_s"),
            number(row, "min_s"),
            number(row, "max_s"),
        );
        assert!(
            0.0 < min && min <= median && median <= max,
            "{min} {median} {max}"
        );
        for column in [
            "newton_iterations",
            "integration_steps",
            "elements",
            "evaluations",
        ] {
            let v = &row[column];
            assert!(v == "none" || v.parse::<usize>().is_ok(), "{column} = {v}");
        }
    }
    assert_eq!(entries(&dir).len(), 1, "only the CSV is left");
    std::fs::remove_dir_all(dir).unwrap();
    rows
}

/// The rows' quantities with computed value, reference, and whether the
/// CSV says it is within the case's tolerance.
fn accuracy(rows: &[Row]) -> BTreeMap<String, (f64, f64, String)> {
    rows.iter()
        .map(|r| {
            (
                r["quantity"].clone(),
                (
                    number(r, "computed"),
                    number(r, "reference"),
                    r["within_tolerance"].clone(),
                ),
            )
        })
        .collect()
}

/// The cantilever at k = F L²/B2 = 3 against Bisshopp & Drucker's closed
/// form (tip x, z, angle), to the validation case's 1e-8 relative.
fn assert_cantilever_k3(rows: &[Row]) {
    let (x, z, angle) = cosserat::references::cantilever_tip(3.0);
    let acc = accuracy(rows);
    for (q, exact) in [("tip_x", x), ("tip_z", z), ("tip_angle", angle)] {
        let (computed, reference, within) = &acc[q];
        assert!((reference - exact).abs() <= 1e-15 * exact.abs(), "{q}");
        assert!((computed - exact).abs() <= 1e-8 * exact.abs(), "{q}");
        assert_eq!(within, "true", "{q}");
    }
}

#[test]
fn bench_solve_times_the_cantilever_and_reports_its_tip_error() {
    let rows = bench("solve", &shipped("cantilever_tip_load"), &[]);
    assert_cantilever_k3(&rows);
    assert!(number(&rows[0], "newton_iterations") >= 1.0);
}

#[test]
fn bench_solve_with_a_method_set_keeps_the_reference() {
    let rows = bench(
        "solve",
        &shipped("cantilever_tip_load"),
        &[
            "--set",
            "solver.method=\"collocation\"",
            "--set",
            "solver.stages=2",
        ],
    );
    assert_eq!(
        rows[0]["set"],
        "solver.method=\"collocation\" solver.stages=2"
    );
    assert_cantilever_k3(&rows);
}

/// Timoshenko & Gere (Sec. 6.3): F L²/√(B1 B3) = 4.0126 (published to
/// five digits).
#[test]
fn bench_stability_reports_timoshenkos_constant() {
    let rows = bench("stability", &shipped("timoshenko_ltb"), &[]);
    let acc = accuracy(&rows);
    let (computed, _, within) = &acc["critical_load"];
    assert!((computed - 4.0126).abs() < 5e-5, "{computed}");
    assert_eq!(within, "true");
}

#[test]
fn bench_continue_without_a_reference_says_none() {
    let rows = bench("continue", &shipped("euler_column"), &[]);
    assert_eq!(rows.len(), 1);
    for column in ["quantity", "computed", "reference", "abs_error"] {
        assert_eq!(rows[0][column], "none", "{column}");
    }
    assert!(number(&rows[0], "evaluations") > 0.0);
}

/// A small search (a problem no validation case is: accuracy `none`).
#[test]
fn bench_optimize_times_a_small_search() {
    let rows = bench(
        "optimize",
        &shipped("longest_arm"),
        &[
            "--set",
            "arm.samples=20",
            "--set",
            "arm.starts=1",
            "--set",
            "arm.iterations=20",
            "--set",
            "arm.elements=20",
            "--set",
            "arm.straight=false",
            "--set",
            "arm.coefficients=4",
            "--set",
            "arm.bounds=[[-4,4],[-2,2],[-0.5,0.5]]",
        ],
    );
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0]["quantity"], "none");
    assert_eq!(rows[0]["elements"], "20");
}

/// A missing problem, `--repeat 0`, a bad `--set`, a problem without what
/// the verb needs, an existing CSV without `--force`, the problem as the
/// CSV: exit 2, the directory as it was.
#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let dir = scratch("bench", "bad");
    let csv = dir.join("bench.csv");
    let csv_arg = csv.to_str().unwrap();
    let problem = shipped("cantilever_tip_load");
    let missing = dir.join("missing.toml");
    let column = shipped("euler_column");
    let missing = missing.to_str().unwrap();
    let cases: [&[&str]; 6] = [
        &["solve", missing],
        &["stability", &problem, "--repeat", "0"],
        &["solve", &problem, "--set", "rod.length=-1"],
        // No [continuation], no [arm], a [shape] with no equilibrium to solve.
        &["continue", &problem],
        &["optimize", &problem],
        &["solve", &column],
    ];
    for case in cases {
        let args = [&["bench"], case, &["--csv", csv_arg]].concat();
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            entries(&dir).is_empty(),
            "{args:?} left {:?}",
            entries(&dir)
        );
    }
    std::fs::write(&csv, "kept").unwrap();
    let o = run(&[
        "bench", "solve", &problem, "--repeat", "1", "--csv", csv_arg,
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "kept");
    let o = run(&[
        "bench", "solve", &problem, "--repeat", "1", "--csv", &problem,
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(entries(&dir).len(), 1);
    std::fs::remove_dir_all(dir).unwrap();
}
