//! A timed benchmark's record: the run times (median, min, max), the work
//! of one run, the accuracy against the references where a validation
//! case gives them; printed, and written as CSV (one row per compared
//! quantity, or one row with accuracy `none`).

use std::fmt::Write as _;

use crate::bench_accuracy::Accuracy;

/// The CSV header of `cosserat bench solve|stability|continue|optimize --csv`.
pub const HEADER: &str = "command,problem,set,runs,median_s,min_s,max_s,newton_iterations,\
integration_steps,elements,evaluations,quantity,computed,reference,reference_kind,abs_error,\
tolerance,within_tolerance,reference_case";

/// The work of one run; None where the command has no such count.
#[derive(Debug, Clone, Copy, Default)]
pub struct Work {
    /// Newton iterations of the equilibrium solve.
    pub newton_iterations: Option<usize>,
    /// Accepted integrator steps (shooting) or collocation intervals.
    pub integration_steps: Option<usize>,
    /// Finite elements of the stability mesh (the finest one used).
    pub elements: Option<usize>,
    /// Points of a diagram, or objective evaluations of a search.
    pub evaluations: Option<usize>,
}

/// The wall times of the timed runs (after the warm-up), s.
#[derive(Debug, Clone)]
pub struct Times(Vec<f64>);

impl Times {
    /// The times of at least one run, sorted.
    pub fn new(mut runs: Vec<f64>) -> Option<Times> {
        if runs.is_empty() || runs.iter().any(|t| !t.is_finite()) {
            return None;
        }
        runs.sort_by(f64::total_cmp);
        Some(Times(runs))
    }

    /// The median (the mean of the middle two for an even count).
    pub fn median(&self) -> f64 {
        let n = self.0.len();
        if n % 2 == 1 {
            self.0[n / 2]
        } else {
            0.5 * (self.0[n / 2 - 1] + self.0[n / 2])
        }
    }

    /// The fastest run: the least disturbed by other load on the machine.
    pub fn min(&self) -> f64 {
        self.0[0]
    }

    /// The slowest run.
    pub fn max(&self) -> f64 {
        self.0[self.0.len() - 1]
    }

    /// The number of timed runs.
    pub fn runs(&self) -> usize {
        self.0.len()
    }
}

/// What one benchmark measured.
#[derive(Debug, Clone)]
pub struct Record {
    /// `solve`, `stability`, `continue` or `optimize`.
    pub command: &'static str,
    /// The problem file as given.
    pub problem: String,
    /// The `--set` overrides.
    pub set: Vec<String>,
    /// The timed runs.
    pub times: Times,
    /// The work of the last run.
    pub work: Work,
    /// The comparisons with references (empty: none known).
    pub accuracy: Vec<Accuracy>,
}

impl Record {
    /// The lines printed on the terminal.
    pub fn summary(&self) -> String {
        let t = &self.times;
        let mut out = format!(
            "time      median {:.3} ms, min {:.3} ms, max {:.3} ms over {} runs (after 1 warm-up)\n",
            t.median() * 1e3,
            t.min() * 1e3,
            t.max() * 1e3,
            t.runs()
        );
        let w = &self.work;
        let counts: Vec<String> = [
            (w.newton_iterations, "Newton iterations"),
            (w.integration_steps, "integration steps or intervals"),
            (w.elements, "elements"),
            (w.evaluations, "points or evaluations"),
        ]
        .iter()
        .filter_map(|(n, what)| n.map(|n| format!("{n} {what}")))
        .collect();
        if !counts.is_empty() {
            let _ = writeln!(out, "work      {} (last run)", counts.join(", "));
        }
        if self.accuracy.is_empty() {
            out.push_str("accuracy  none (no validation case is this problem)\n");
        }
        for a in &self.accuracy {
            let _ = writeln!(
                out,
                "accuracy  {} = {} against {:.12e} ({}, {}): error {}, {}",
                a.quantity,
                optional(a.computed.map(|c| format!("{c:.12e}"))),
                a.reference,
                a.kind,
                a.case,
                optional(a.error().map(|e| format!("{e:.2e}"))),
                within(a)
            );
        }
        out
    }

    /// The CSV text: the header and one row per comparison (one row with
    /// `none` in the accuracy columns when there is none).
    pub fn csv(&self) -> String {
        let t = &self.times;
        let w = &self.work;
        let count = |c: Option<usize>| optional(c.map(|c| c.to_string()));
        let timing = [
            self.command.to_string(),
            self.problem.clone(),
            self.set.join(" "),
            t.runs().to_string(),
            format!("{:e}", t.median()),
            format!("{:e}", t.min()),
            format!("{:e}", t.max()),
            count(w.newton_iterations),
            count(w.integration_steps),
            count(w.elements),
            count(w.evaluations),
        ];
        let none = || vec!["none".to_string(); 8];
        let accuracy: Vec<Vec<String>> = if self.accuracy.is_empty() {
            vec![none()]
        } else {
            self.accuracy
                .iter()
                .map(|a| {
                    vec![
                        a.quantity.clone(),
                        optional(a.computed.map(|c| format!("{c:e}"))),
                        format!("{:e}", a.reference),
                        a.kind.clone(),
                        optional(a.error().map(|e| format!("{e:e}"))),
                        tolerance(a),
                        optional(a.within().map(|b| b.to_string())),
                        a.case.clone(),
                    ]
                })
                .collect()
        };
        let mut out = format!("{HEADER}\n");
        for acc in accuracy {
            let fields: Vec<String> = timing.iter().chain(&acc).map(|f| field(f)).collect();
            let _ = writeln!(out, "{}", fields.join(","));
        }
        out
    }
}

/// `none` for a missing value.
fn optional(v: Option<String>) -> String {
    v.unwrap_or_else(|| "none".into())
}

/// `relative 1e-8`, `absolute 1e-5`, or `none` (informational).
fn tolerance(a: &Accuracy) -> String {
    match a.tolerance.map(|t| (t.relative, t.absolute)) {
        Some((Some(r), _)) => format!("relative {r:e}"),
        Some((None, Some(x))) => format!("absolute {x:e}"),
        _ => "none".into(),
    }
}

fn within(a: &Accuracy) -> String {
    match a.within() {
        Some(true) => format!("within {}", tolerance(a)),
        Some(false) => format!("OUTSIDE {}", tolerance(a)),
        None => "informational".into(),
    }
}

/// One CSV field (RFC 4180): quoted when it holds a comma, a quote or a
/// line break, quotes doubled. Written here rather than with the `csv`
/// crate: the one rule is four lines and the records are flat strings.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
