//! The runner: every point of every case with every method that applies.
//!
//! Per point the case's overrides are filled with the point's parameters,
//! the method's overrides added, and the analysis run (`solve`,
//! `critical-load`, `optimize` or `stability-loss`, the last by bisecting
//! the first sign change of det J or of the lowest eigenvalue of the second
//! variation to round-off). Each check then compares the computed value c
//! with its reference r: |c − r| ≤ rel · |r| for a relative tolerance,
//! |c − r| ≤ abs for an absolute one; the relative error reported is
//! |c − r| / |r| (|c − r| when r = 0).

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use cosserat::bvp::{solve, Equilibrium};
use cosserat::input::Problem;
use cosserat::stability::critical_load;

use super::case::{Case, CaseFile, Check, InputError, Point, Scan};
use super::report::{Row, Status};
use super::{reference, METHODS};

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

/// The point's parameters with the derived ones evaluated.
pub(crate) fn point_params(
    case: &CaseFile,
    point: &Point,
) -> Result<BTreeMap<String, f64>, String> {
    let mut params = point.params.clone();
    for (name, formula) in &case.derive {
        let v = reference::evaluate(formula, &point.params)?;
        params.insert(name.clone(), v);
    }
    Ok(params)
}

/// The `--set` overrides selecting a method.
pub(crate) fn method_overrides(method: &str) -> Vec<String> {
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

fn method_selected(method: &str, filter: Option<&str>) -> bool {
    match filter {
        None => true,
        Some("collocation") => method.starts_with("collocation"),
        Some(f) => f == method,
    }
}

/// The overrides with `{name}` replaced by the parameters.
pub(crate) fn fill(templates: &[String], params: &BTreeMap<String, f64>) -> Vec<String> {
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

/// The tip quantities a `solve` case can check, positions times `scale`.
pub(crate) fn tip_quantities(
    eq: &Equilibrium,
    problem: &Problem,
    scale: f64,
) -> BTreeMap<String, Option<f64>> {
    let tip = eq.tip();
    let clamp = &problem.rod.clamp();
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
        crate::energies::read_problem(&path, &set)
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
        "solve" => solve_outcome(&problem, case),
        "critical-load" => critical_load_outcome(&problem, case)?,
        "optimize" => optimize_outcome(&problem, case)?,
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

/// The tip quantities of the problem's equilibrium.
fn solve_outcome(problem: &Problem, case: &Case) -> Result<Outcome, String> {
    match solve(&problem.rod, &problem.model, &problem.options) {
        Ok(eq) => Ok(Outcome {
            values: tip_quantities(&eq, problem, case.file.length_scale),
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
    }
}

/// The critical load of the problem's `[shape]`.
fn critical_load_outcome(
    problem: &Problem,
    case: &Case,
) -> Result<Result<Outcome, String>, InputError> {
    let Some(shape) = &problem.shape else {
        return Err(InputError(format!(
            "{}: critical-load needs a [shape] in the problem",
            case.name
        )));
    };
    let outcome = match critical_load(&problem.rod, shape, &problem.stability) {
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
                problem.stability.elements(),
                problem.stability.order()
            ),
        }),
        Err(e) => Err(e.to_string()),
    };
    Ok(outcome)
}

/// The optimal arm's reach (and the straight arm's, when asked).
fn optimize_outcome(problem: &Problem, case: &Case) -> Result<Result<Outcome, String>, InputError> {
    let Some((arm, search, straight)) = &problem.arm else {
        return Err(InputError(format!(
            "{}: optimize needs an [arm] in the problem",
            case.name
        )));
    };
    Ok(match arm.optimize(search) {
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
    })
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
                if !method_selected(method, opts.method.as_deref()) {
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
        Err(e) => row.message.clone_from(e),
        Ok(o) => {
            row.time = o.time;
            row.message.clone_from(&o.message);
            row.computed = o.values.get(&check.quantity).copied().flatten();
            if let Some(c) = row.computed {
                let abs = super::case::error_of(&check.quantity, c, reference);
                row.absolute_error = Some(abs);
                row.relative_error = Some(if reference == 0.0 {
                    abs
                } else {
                    abs / reference.abs()
                });
                row.status = match check.tolerance {
                    Some(t) if t.admits(abs, reference) => Status::Pass,
                    _ => Status::Fail,
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
