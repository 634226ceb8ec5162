//! The report: each row's verdict, the counts, the terminal table and the
//! markdown report with every reference's kind and source.

use std::fmt::Write as _;

use super::case::{Case, Tolerance};
use super::reference;
use super::runner::RunOptions;

/// The verdict of one row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Within the tolerance.
    Pass,
    /// Outside the tolerance, or no value computed.
    Fail,
    /// Informational: reported, never failed.
    Info,
    /// Skipped: the comparison does not apply at this point.
    Skip,
}

impl Status {
    /// The word printed in the report ("pass", "FAIL", "info", "skip").
    pub fn name(self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Fail => "FAIL",
            Status::Info => "info",
            Status::Skip => "skip",
        }
    }
}

/// One line of the report.
#[derive(Debug, Clone)]
pub struct Row {
    /// The case name.
    pub case: String,
    /// The point's label.
    pub point: String,
    /// The method the analysis ran with.
    pub method: String,
    /// The quantity compared.
    pub quantity: String,
    /// The reference value.
    pub reference: f64,
    /// Where the reference comes from (`closed-form`, `published`,
    /// `converged-study`).
    pub kind: String,
    /// The computed value (None when the analysis failed).
    pub computed: Option<f64>,
    /// Relative error (absolute when the reference is zero).
    pub relative_error: Option<f64>,
    /// |computed − reference|.
    pub absolute_error: Option<f64>,
    /// The tolerance of the check (None for informational checks).
    pub tolerance: Option<Tolerance>,
    /// Wall time of the analysis the row comes from, s.
    pub time: f64,
    /// The verdict.
    pub status: Status,
    /// The error or remark of the analysis.
    pub message: String,
}

fn sci(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.10}"),
        Some(v) if v.is_nan() => "none".into(),
        Some(v) => format!("{v}"),
        None => "none".into(),
    }
}

fn short(v: Option<f64>) -> String {
    match v {
        Some(v) => format!("{v:.1e}"),
        None => "—".into(),
    }
}

fn tolerance_text(t: Option<Tolerance>) -> String {
    match t {
        Some(Tolerance {
            relative: Some(r), ..
        }) => format!("rel {r:.0e}"),
        Some(Tolerance {
            absolute: Some(a), ..
        }) => format!("abs {a:.0e}"),
        _ => "—".into(),
    }
}

/// The error shown: relative against a relative tolerance, absolute
/// against an absolute one.
fn error_text(r: &Row) -> String {
    if !r.reference.is_finite() {
        return "—".into();
    }
    match r.tolerance {
        Some(Tolerance {
            absolute: Some(_), ..
        }) => format!("{} (abs)", short(r.absolute_error)),
        _ if r.reference == 0.0 => format!("{} (abs)", short(r.absolute_error)),
        _ => short(r.relative_error),
    }
}

/// (pass, fail, info, skip) counts.
pub fn counts(rows: &[Row]) -> [usize; 4] {
    let n = |s| rows.iter().filter(|r| r.status == s).count();
    [
        n(Status::Pass),
        n(Status::Fail),
        n(Status::Info),
        n(Status::Skip),
    ]
}

const HEADER: [&str; 11] = [
    "case",
    "point",
    "method",
    "quantity",
    "reference",
    "computed",
    "rel. error",
    "tolerance",
    "time",
    "status",
    "note",
];

fn cells(r: &Row) -> [String; 11] {
    [
        r.case.clone(),
        r.point.clone(),
        r.method.clone(),
        r.quantity.clone(),
        format!("{} ({})", sci(Some(r.reference)), r.kind),
        sci(r.computed),
        error_text(r),
        tolerance_text(r.tolerance),
        format!("{:.3} s", r.time),
        r.status.name().to_string(),
        r.message.clone(),
    ]
}

/// The table as aligned text (the note column only for rows that are not
/// passes).
pub fn text_table(rows: &[Row]) -> String {
    let all: Vec<[String; 11]> = rows.iter().map(cells).collect();
    let mut width = [0usize; 10];
    for (i, h) in HEADER.iter().take(10).enumerate() {
        width[i] = h.chars().count();
    }
    for c in &all {
        for i in 0..10 {
            width[i] = width[i].max(c[i].chars().count());
        }
    }
    let line = |c: &[String]| {
        let mut s = String::new();
        for i in 0..10 {
            let pad = width[i] - c[i].chars().count();
            s.push_str(&c[i]);
            s.push_str(&" ".repeat(pad + 2));
        }
        s.trim_end().to_string()
    };
    let mut out = String::new();
    let head: Vec<String> = HEADER
        .iter()
        .map(std::string::ToString::to_string)
        .collect();
    let _ = writeln!(out, "{}", line(&head));
    for (r, c) in rows.iter().zip(&all) {
        let _ = writeln!(out, "{}", line(c));
        if r.status == Status::Fail || r.status == Status::Skip {
            let _ = writeln!(out, "    ↳ {}", c[10]);
        }
    }
    out
}

/// The report: summary, table, and every case's sources and notes.
pub fn markdown(cases: &[Case], rows: &[Row], opts: &RunOptions) -> String {
    let [pass, fail, info, skip] = counts(rows);
    let mut s = String::new();
    let _ = writeln!(s, "# Validation report\n");
    let _ = writeln!(
        s,
        "Generated by `cosserat validate{}{}` (cosserat {}). Every reference is a closed form \
         evaluated by the runner (`crates/cosserat/src/references.rs`) or a published value typed with \
         its citation — never the code's own output. Case files: `validation/*.toml`.\n",
        if opts.quick { " --quick" } else { "" },
        opts.method
            .as_ref()
            .map(|m| format!(" --method {m}"))
            .unwrap_or_default(),
        env!("CARGO_PKG_VERSION"),
    );
    let _ = writeln!(
        s,
        "**{pass} pass, {fail} fail, {info} informational, {skip} skipped** ({} rows).\n",
        rows.len()
    );
    let _ = writeln!(s, "| {} |", HEADER.join(" | "));
    let _ = writeln!(s, "|{}", "---|".repeat(HEADER.len()));
    for r in rows {
        let c = cells(r).map(|x| x.replace('|', "\\|"));
        let _ = writeln!(s, "| {} |", c.join(" | "));
    }
    let _ = writeln!(s, "\n## Cases\n");
    for case in cases {
        if !rows.iter().any(|r| r.case == case.name) {
            continue;
        }
        let f = &case.file;
        let _ = writeln!(s, "### `{}` — {}\n", case.name, f.title);
        let _ = writeln!(
            s,
            "Problem `{}`, analysis `{}`, methods {}.\n",
            f.problem,
            f.analysis,
            f.methods.join(", ")
        );
        if !f.note.trim().is_empty() {
            let _ = writeln!(s, "{}\n", f.note.trim());
        }
        let mut seen = Vec::new();
        for c in &f.check {
            let what = match &c.reference.formula {
                Some(formula) => {
                    format!("closed form `{formula}`: {}", reference::describe(formula))
                }
                None => format!("{} value", c.reference.kind),
            };
            let line = format!(
                "- `{}` — {what}; source: {}{}",
                c.quantity,
                c.reference.source,
                if c.informational {
                    " (informational)"
                } else {
                    ""
                }
            );
            if !seen.contains(&line) {
                let _ = writeln!(s, "{line}");
                seen.push(line);
            }
        }
        let _ = writeln!(s);
    }
    s
}
