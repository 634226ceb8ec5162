//! `cosserat validate`: classical benchmarks run against every method.
//!
//! A case is data (`validation/<case>.toml`): a problem file, the
//! overrides to apply (with `{param}` placeholders filled from each point's
//! parameters), the analysis to run, the methods it applies to, and checks
//! — a quantity, a reference with its kind and source, a tolerance. One
//! generic runner runs every point of every case with every method that
//! applies and compares. References are closed forms evaluated in
//! [`mod@reference`] from their formulas, or published values typed with their
//! citation; never the solver's own output. The file format is described
//! in validation/README.md.

pub use cosserat::references as reference;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use serde::Deserialize;

use cosserat::bvp::{solve, Equilibrium};
use cosserat::io::Problem;
use cosserat::stability::critical_load;

/// The methods a case can name: the BVP discretizations, and `fe` for the
/// fixed-shape finite-element analysis (which has no BVP method).
pub const METHODS: [&str; 5] = [
    "shooting",
    "multiple-shooting",
    "collocation-2",
    "collocation-3",
    "fe",
];

/// Arguments of `cosserat validate`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ValidateArgs {
    /// Run only the quick subset (CI).
    #[arg(long)]
    pub quick: bool,
    /// Run only this method: shooting, multiple-shooting, collocation
    /// (both orders), collocation-2, collocation-3 or fe.
    #[arg(long)]
    pub method: Option<String>,
    /// Write the report (Markdown) to this file.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The directory of case files (default: ./validation, else the
    /// crate's own).
    #[arg(long)]
    pub cases: Option<PathBuf>,
    /// Run only the cases whose name contains this.
    #[arg(long)]
    pub case: Option<String>,
}

/// A case file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseFile {
    /// A one-line title.
    pub title: String,
    /// The problem file, relative to the case file.
    pub problem: String,
    /// `solve`, `critical-load`, `jacobian-singularity`, `stability-loss` or
    /// `optimize`.
    pub analysis: String,
    /// The methods the case applies to (see [`METHODS`]).
    pub methods: Vec<String>,
    /// `key=value` overrides; `{name}` is replaced by the point's parameter.
    #[serde(default)]
    pub overrides: Vec<String>,
    /// Parameters evaluated from closed forms (name = formula) with each
    /// point's parameters, before the overrides are filled.
    #[serde(default)]
    pub derive: BTreeMap<String, String>,
    /// Lengths in the problem are in this unit (the report multiplies
    /// positions by it).
    #[serde(default = "one")]
    pub length_scale: f64,
    /// What the reader should know: conventions, what is left out and why.
    #[serde(default)]
    pub note: String,
    /// The parameter scan of `jacobian-singularity` and `stability-loss`.
    #[serde(default)]
    pub scan: Option<Scan>,
    /// The points (parameter sets) of the case.
    pub point: Vec<Point>,
    /// The checks made at every point (or at the points they name).
    pub check: Vec<Check>,
}

fn one() -> f64 {
    1.0
}

/// A scan for a sign change of det J (the shooting Jacobian): the
/// parameter `parameter` runs from `lo` to `hi` in `steps` steps, the first
/// sign change is bisected.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scan {
    /// The name of the scanned parameter.
    pub parameter: String,
    /// Its first value.
    pub lo: f64,
    /// Its last value.
    pub hi: f64,
    /// Steps from `lo` to `hi`.
    pub steps: usize,
}

/// One point of a case.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Point {
    /// Its label in the report.
    pub label: String,
    /// Parameters: filled into the overrides and the closed forms.
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
    /// Part of the quick set.
    #[serde(default)]
    pub quick: bool,
    /// Run, but report as skipped with this reason (the comparison does
    /// not apply).
    #[serde(default)]
    pub skip: Option<String>,
}

/// One comparison.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Check {
    /// tip_x, tip_y, tip_z, tip_angle, tip_chord (solve); critical_load,
    /// chi (critical-load); branch_point (jacobian-singularity,
    /// stability-loss).
    pub quantity: String,
    /// The reference value.
    pub reference: Reference,
    /// The tolerance (absent for informational checks).
    #[serde(default)]
    pub tolerance: Option<Tolerance>,
    /// Only at the points with these labels (default: all).
    #[serde(default)]
    pub points: Option<Vec<String>>,
    /// Reported, never failed.
    #[serde(default)]
    pub informational: bool,
}

/// Where a reference value comes from.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// `closed-form` (evaluated by the runner from `formula`), `published`
    /// (a table value, `value`), or `converged-study` (`value`, made
    /// independently of this code).
    pub kind: String,
    /// The closed form (for `closed-form`), in the parameters of the point.
    #[serde(default)]
    pub formula: Option<String>,
    /// The value (for `published` and `converged-study`).
    #[serde(default)]
    pub value: Option<f64>,
    /// The citation.
    pub source: String,
}

/// Pass when |computed − reference| ≤ absolute, or ≤ relative·|reference|.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tolerance {
    /// Relative tolerance: pass when |computed − reference| ≤
    /// relative·|reference|.
    #[serde(default)]
    pub relative: Option<f64>,
    /// Absolute tolerance, used when no relative one is given.
    #[serde(default)]
    pub absolute: Option<f64>,
}

/// A case with its name (the file stem) and location.
#[derive(Debug, Clone)]
pub struct Case {
    /// The file stem.
    pub name: String,
    /// The case file.
    pub path: PathBuf,
    /// Its parsed contents.
    pub file: CaseFile,
}

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

/// A case file or option that cannot be used (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

/// What the runner runs.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Only the points marked `quick`.
    pub quick: bool,
    /// Only this method (`collocation` selects both orders).
    pub method: Option<String>,
    /// Only cases whose name contains this.
    pub case: Option<String>,
}

/// The default case directory: ./validation if it holds case files, else
/// the crate's own.
pub fn default_dir() -> PathBuf {
    let local = PathBuf::from("validation");
    if local.join("cantilever_tip_load.toml").is_file() {
        local
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../validation")
    }
}

/// Reads every `*.toml` in `dir` (sorted by name) and checks it.
pub fn load_cases(dir: &Path) -> Result<Vec<Case>, InputError> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| InputError(format!("cannot read {}: {e}", dir.display())))?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml") && p.is_file())
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(InputError(format!("no case files in {}", dir.display())));
    }
    paths.iter().map(|p| load_case(p)).collect()
}

/// Reads and checks one case file.
pub fn load_case(path: &Path) -> Result<Case, InputError> {
    let bad = |m: String| InputError(format!("{}: {m}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let file: CaseFile = toml::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let analysis = file.analysis.as_str();
    const ANALYSES: [&str; 5] = [
        "solve",
        "critical-load",
        "jacobian-singularity",
        "stability-loss",
        "optimize",
    ];
    if !ANALYSES.contains(&analysis) {
        return Err(bad(format!(
            "analysis `{analysis}`: expected one of {}",
            ANALYSES.join(", ")
        )));
    }
    if ["jacobian-singularity", "stability-loss"].contains(&analysis) {
        match &file.scan {
            Some(s) if s.lo < s.hi && s.steps >= 1 => {}
            _ => return Err(bad(format!("{analysis} needs a [scan] with lo < hi"))),
        }
    }
    for m in &file.methods {
        if !METHODS.contains(&m.as_str()) {
            return Err(bad(format!("unknown method `{m}`")));
        }
    }
    if !file.length_scale.is_finite() || file.length_scale <= 0.0 {
        return Err(bad("length_scale must be positive".into()));
    }
    for p in &file.point {
        point_params(&file, p).map_err(&bad)?;
    }
    let labels: Vec<&str> = file.point.iter().map(|p| p.label.as_str()).collect();
    for c in &file.check {
        let known = match analysis {
            "solve" => &["tip_x", "tip_y", "tip_z", "tip_angle", "tip_chord"][..],
            "critical-load" => &["critical_load", "chi"][..],
            "optimize" => &["reach", "straight_reach"][..],
            _ => &["branch_point"][..],
        };
        if !known.contains(&c.quantity.as_str()) {
            return Err(bad(format!(
                "quantity `{}` is not one of {known:?}",
                c.quantity
            )));
        }
        match (
            c.reference.kind.as_str(),
            &c.reference.formula,
            c.reference.value,
        ) {
            ("closed-form", Some(f), None) => {
                for p in &file.point {
                    if c.points.as_ref().is_none_or(|l| l.contains(&p.label)) {
                        let params = point_params(&file, p).map_err(&bad)?;
                        reference::evaluate(f, &params).map_err(&bad)?;
                    }
                }
            }
            ("published" | "converged-study", None, Some(_)) => {}
            (kind, _, _) => {
                return Err(bad(format!(
                    "reference of `{}`: kind `{kind}` needs `formula` (closed-form) or \
                     `value` (published, converged-study), not both",
                    c.quantity
                )))
            }
        }
        if c.tolerance.is_none() && !c.informational {
            return Err(bad(format!("check `{}` needs a tolerance", c.quantity)));
        }
        if let Some(t) = c.tolerance {
            if t.relative.is_none() == t.absolute.is_none() {
                return Err(bad(format!(
                    "check `{}`: give exactly one of tolerance.relative, tolerance.absolute",
                    c.quantity
                )));
            }
        }
        for l in c.points.iter().flatten() {
            if !labels.contains(&l.as_str()) {
                return Err(bad(format!("check `{}`: no point `{l}`", c.quantity)));
            }
        }
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Case {
        name,
        path: path.to_path_buf(),
        file,
    })
}

/// The point's parameters with the derived ones evaluated.
fn point_params(case: &CaseFile, point: &Point) -> Result<BTreeMap<String, f64>, String> {
    let mut params = point.params.clone();
    for (name, formula) in &case.derive {
        let v = reference::evaluate(formula, &point.params)?;
        params.insert(name.clone(), v);
    }
    Ok(params)
}

/// The `--set` overrides selecting a method.
fn method_overrides(method: &str) -> Vec<String> {
    match method {
        "shooting" => vec!["solver.method=\"shooting\"".into()],
        "multiple-shooting" => vec!["solver.method=\"multiple-shooting\"".into()],
        "collocation-2" => vec![
            "solver.method=\"collocation\"".into(),
            "solver.stages=2".into(),
        ],
        "collocation-3" => vec![
            "solver.method=\"collocation\"".into(),
            "solver.stages=3".into(),
        ],
        _ => vec![],
    }
}

fn method_selected(method: &str, filter: &Option<String>) -> bool {
    match filter.as_deref() {
        None => true,
        Some("collocation") => method.starts_with("collocation"),
        Some(f) => f == method,
    }
}

/// The overrides with `{name}` replaced by the parameters.
fn fill(templates: &[String], params: &BTreeMap<String, f64>) -> Vec<String> {
    templates
        .iter()
        .map(|t| {
            let mut s = t.clone();
            for (k, v) in params {
                s = s.replace(&format!("{{{k}}}"), &format!("{v:?}"));
            }
            s
        })
        .collect()
}

/// Whether `s` still holds a `{name}` placeholder.
fn has_placeholder(s: &str) -> bool {
    s.split('{').skip(1).any(|rest| {
        rest.split_once('}').is_some_and(|(name, _)| {
            !name.is_empty() && name.chars().all(|c| c.is_alphanumeric() || c == '_')
        })
    })
}

/// The computed quantities of one analysis.
struct Outcome {
    values: BTreeMap<String, Option<f64>>,
    time: f64,
    message: String,
}

fn tip_quantities(
    eq: &Equilibrium,
    problem: &Problem,
    scale: f64,
) -> BTreeMap<String, Option<f64>> {
    let tip = eq.tip();
    let clamp = &problem.rod.clamp;
    let d3 = tip.directors[2];
    let angle = d3.dot(&clamp.director(0)).atan2(d3.dot(&clamp.director(2)));
    let chord = (tip.position - clamp.position).norm();
    [
        ("tip_x", tip.position[0] * scale),
        ("tip_y", tip.position[1] * scale),
        ("tip_z", tip.position[2] * scale),
        ("tip_angle", angle),
        ("tip_chord", chord * scale),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), Some(v)))
    .collect()
}

fn run_analysis(
    case: &Case,
    point: &Point,
    method: &str,
) -> Result<Result<Outcome, String>, InputError> {
    let path = case
        .path
        .parent()
        .unwrap_or(Path::new("."))
        .join(&case.file.problem);
    let build = |params: &BTreeMap<String, f64>| {
        let mut set = fill(&case.file.overrides, params);
        if let Some(unfilled) = set.iter().find(|o| has_placeholder(o)) {
            return Err(InputError(format!(
                "{}: unfilled override `{unfilled}`",
                case.name
            )));
        }
        set.extend(method_overrides(method));
        Problem::from_path(&path, &set)
            .map_err(|e| InputError(format!("{}: {}: {e}", case.name, path.display())))
    };
    let params =
        point_params(&case.file, point).map_err(|e| InputError(format!("{}: {e}", case.name)))?;
    let mut params = params;
    if let Some(scan) = &case.file.scan {
        params.entry(scan.parameter.clone()).or_insert(scan.lo);
    }
    let start = Instant::now();
    let problem = build(&params)?;
    let outcome = match case.file.analysis.as_str() {
        "solve" => match solve(&problem.rod, &problem.model, &problem.options) {
            Ok(eq) => Ok(Outcome {
                values: tip_quantities(&eq, &problem, case.file.length_scale),
                time: 0.0,
                message: format!(
                    "{} model, {} Newton steps{}",
                    problem.model.level.name(),
                    eq.iterations,
                    if eq.load_steps > 0 {
                        format!(", {} ramp steps", eq.load_steps)
                    } else {
                        String::new()
                    }
                ),
            }),
            Err(e) => Err(e.to_string()),
        },
        "critical-load" => {
            let Some(shape) = &problem.shape else {
                return Err(InputError(format!(
                    "{}: critical-load needs a [shape] in the problem",
                    case.name
                )));
            };
            match critical_load(&problem.rod, shape, &problem.stability) {
                Ok(c) => Ok(Outcome {
                    values: [
                        ("critical_load".to_string(), c.gamma),
                        ("chi".to_string(), c.gamma.map(f64::sqrt)),
                    ]
                    .into_iter()
                    .collect(),
                    time: 0.0,
                    message: format!(
                        "{} elements of order {}",
                        problem.stability.elements, problem.stability.order
                    ),
                }),
                Err(e) => Err(e.to_string()),
            }
        }
        "optimize" => {
            let Some((arm, search, straight)) = &problem.arm else {
                return Err(InputError(format!(
                    "{}: optimize needs an [arm] in the problem",
                    case.name
                )));
            };
            match arm.optimize(search) {
                None => Err(format!(
                    "{}: no design with a finite critical load",
                    case.name
                )),
                Some(optimum) => {
                    let straight_reach = if *straight {
                        arm.straight().map(|s| s.reach)
                    } else {
                        None
                    };
                    Ok(Outcome {
                        values: [
                            ("reach".to_string(), Some(optimum.design.reach)),
                            ("straight_reach".to_string(), straight_reach),
                        ]
                        .into_iter()
                        .collect(),
                        time: 0.0,
                        message: format!("{} evaluations", optimum.evaluations),
                    })
                }
            }
        }
        "stability-loss" => {
            let scan = case.file.scan.as_ref().expect("checked on load");
            let lowest = |x: f64| -> Result<f64, String> {
                let mut params = params.clone();
                params.insert(scan.parameter.clone(), x);
                let problem = build(&params).map_err(|e| e.0)?;
                lowest_eigenvalue(&problem).map_err(|e| format!("{} = {x}: {e}", scan.parameter))
            };
            singularity(scan, lowest).map(|(found, message)| Outcome {
                values: [("branch_point".to_string(), found)].into_iter().collect(),
                time: 0.0,
                message: message.replace("det J", "the lowest eigenvalue of δ²V"),
            })
        }
        _ => {
            let scan = case.file.scan.as_ref().expect("checked on load");
            let det = |x: f64| -> Result<f64, String> {
                let mut params = params.clone();
                params.insert(scan.parameter.clone(), x);
                let problem = build(&params).map_err(|e| e.0)?;
                solve(&problem.rod, &problem.model, &problem.options)
                    .map(|eq| eq.jacobian.determinant())
                    .map_err(|e| format!("{} = {x}: {e}", scan.parameter))
            };
            singularity(scan, det).map(|(found, message)| Outcome {
                values: [("branch_point".to_string(), found)].into_iter().collect(),
                time: 0.0,
                message,
            })
        }
    };
    let time = start.elapsed().as_secs_f64();
    Ok(outcome.map(|o| Outcome { time, ..o }))
}

/// The lowest eigenvalue of the second variation (every block, on the
/// tip support's constraints) at the problem's equilibrium: it crosses zero
/// where stability is lost, also where the BVP Jacobian's determinant only
/// touches zero (a pair of buckling modes, as in Greenhill's problem).
fn lowest_eigenvalue(problem: &Problem) -> Result<f64, String> {
    let eq = solve(&problem.rod, &problem.model, &problem.options).map_err(|e| e.to_string())?;
    let st = cosserat::stability::analyze(&problem.rod, &eq, &problem.options, &problem.stability)
        .map_err(|e| e.to_string())?;
    Ok(st
        .blocks
        .iter()
        .flat_map(|b| b.eigenvalues.iter().copied())
        .fold(f64::INFINITY, f64::min))
}

/// The first sign change of `f` (det J or an eigenvalue) over the scan,
/// bisected to round-off.
fn singularity(
    scan: &Scan,
    det: impl Fn(f64) -> Result<f64, String>,
) -> Result<(Option<f64>, String), String> {
    let step = (scan.hi - scan.lo) / scan.steps as f64;
    let mut a = scan.lo;
    let mut fa = det(a)?;
    for i in 1..=scan.steps {
        let b = scan.lo + step * i as f64;
        let fb = det(b)?;
        if fa * fb < 0.0 {
            let (mut lo, mut hi, f_lo) = (a, b, fa);
            while hi - lo > 1e-13 * hi.abs().max(1.0) {
                let mid = 0.5 * (lo + hi);
                let fm = det(mid)?;
                if fm * f_lo > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return Ok((
                Some(0.5 * (lo + hi)),
                format!(
                    "det J changes sign in [{a:.4}, {b:.4}] of {}",
                    scan.parameter
                ),
            ));
        }
        a = b;
        fa = fb;
    }
    Ok((
        None,
        format!(
            "det J keeps its sign for {} in [{}, {}] ({} steps)",
            scan.parameter, scan.lo, scan.hi, scan.steps
        ),
    ))
}

/// Runs the cases; an `InputError` for case data that cannot be used.
pub fn run(cases: &[Case], opts: &RunOptions) -> Result<Vec<Row>, InputError> {
    if let Some(m) = &opts.method {
        if m != "collocation" && !METHODS.contains(&m.as_str()) {
            return Err(InputError(format!(
                "unknown method `{m}`; expected one of {}, collocation",
                METHODS.join(", ")
            )));
        }
    }
    let mut rows = Vec::new();
    for case in cases {
        if opts.case.as_ref().is_some_and(|c| !case.name.contains(c)) {
            continue;
        }
        for point in &case.file.point {
            if opts.quick && !point.quick {
                continue;
            }
            for method in &case.file.methods {
                if !method_selected(method, &opts.method) {
                    continue;
                }
                let outcome = run_analysis(case, point, method)?;
                for check in &case.file.check {
                    if check
                        .points
                        .as_ref()
                        .is_some_and(|l| !l.contains(&point.label))
                    {
                        continue;
                    }
                    rows.push(compare(case, point, method, check, &outcome));
                }
            }
        }
    }
    Ok(rows)
}

fn compare(
    case: &Case,
    point: &Point,
    method: &str,
    check: &Check,
    outcome: &Result<Outcome, String>,
) -> Row {
    let reference = match &check.reference.formula {
        Some(f) => point_params(&case.file, point)
            .and_then(|p| reference::evaluate(f, &p))
            .unwrap_or(f64::NAN),
        None => check.reference.value.unwrap_or(f64::NAN),
    };
    let mut row = Row {
        case: case.name.clone(),
        point: point.label.clone(),
        method: method.to_string(),
        quantity: check.quantity.clone(),
        reference,
        kind: check.reference.kind.clone(),
        computed: None,
        relative_error: None,
        absolute_error: None,
        tolerance: check.tolerance,
        time: 0.0,
        status: Status::Fail,
        message: String::new(),
    };
    match outcome {
        Err(e) => row.message = e.clone(),
        Ok(o) => {
            row.time = o.time;
            row.message = o.message.clone();
            row.computed = o.values.get(&check.quantity).copied().flatten();
            if let Some(c) = row.computed {
                let abs = (c - reference).abs();
                row.absolute_error = Some(abs);
                row.relative_error = Some(if reference != 0.0 {
                    abs / reference.abs()
                } else {
                    abs
                });
                row.status = match check.tolerance {
                    Some(t) => {
                        let ok = match (t.relative, t.absolute) {
                            (Some(r), _) => abs <= r * reference.abs(),
                            (None, Some(a)) => abs <= a,
                            _ => false,
                        };
                        if ok {
                            Status::Pass
                        } else {
                            Status::Fail
                        }
                    }
                    None => Status::Fail,
                };
            }
        }
    }
    if check.informational {
        row.status = Status::Info;
    }
    if let Some(reason) = &point.skip {
        row.status = Status::Skip;
        row.message = format!("{reason} [{}]", row.message);
    }
    row
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
    let head: Vec<String> = HEADER.iter().map(|h| h.to_string()).collect();
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

/// `cosserat validate`: exit 0 when every row passes (or is informational
/// or skipped), 3 when one fails (a result below the asked quality), 2 on
/// bad input, 1 when the report cannot be written.
pub fn run_cli(args: ValidateArgs) -> ExitCode {
    let dir = args.cases.clone().unwrap_or_else(default_dir);
    let cases = match load_cases(&dir) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let opts = RunOptions {
        quick: args.quick,
        method: args.method.clone(),
        case: args.case.clone(),
    };
    let start = Instant::now();
    let rows = match run(&cases, &opts) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    print!("{}", text_table(&rows));
    let [pass, fail, info, skip] = counts(&rows);
    println!(
        "validate  {pass} pass, {fail} fail, {info} informational, {skip} skipped in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    if let Some(out) = &args.output {
        if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
            let _ = std::fs::create_dir_all(parent);
        }
        let report = markdown(&cases, &rows, &opts);
        if let Err(e) =
            cosserat::io::target::replace_atomically(out, |tmp| std::fs::write(tmp, &report))
        {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
        println!("written   {}", out.display());
    }
    if rows.is_empty() {
        eprintln!("error: no case matched");
        return ExitCode::from(2);
    }
    if fail > 0 {
        ExitCode::from(3)
    } else {
        ExitCode::SUCCESS
    }
}
