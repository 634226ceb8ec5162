//! The accuracy of a benchmarked result, from the validation cases
//! (validation/*.toml): the case whose problem file is the benchmarked
//! one, whose analysis is the benchmark's, whose methods include the
//! benchmarked method, and one of whose points reads to the same problem
//! (the method keys `solver.method` and `solver.stages` aside) gives the
//! references and tolerances. Without such a case the accuracy is `none`:
//! a reference is never guessed from what a problem looks like.

use std::collections::BTreeMap;
use std::path::Path;

use cosserat::bvp::Method;
use cosserat::input::Problem;

use crate::validate::{self, error_of, Case, Point, Tolerance};

/// The analysis of a validation case a benchmark compares with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Analysis {
    /// An equilibrium's tip quantities.
    Solve,
    /// A fixed shape's critical load.
    CriticalLoad,
    /// The longest arm's reach.
    Optimize,
}

impl Analysis {
    /// The name a case file gives it (`analysis = "…"`).
    pub fn name(self) -> &'static str {
        match self {
            Analysis::Solve => "solve",
            Analysis::CriticalLoad => "critical-load",
            Analysis::Optimize => "optimize",
        }
    }
}

/// One computed quantity beside its reference.
#[derive(Debug, Clone)]
pub struct Accuracy {
    /// The validation case and point the reference comes from.
    pub case: String,
    /// The quantity (tip_x, critical_load, reach, …).
    pub quantity: String,
    /// The benchmarked value (None when the run did not produce it).
    pub computed: Option<f64>,
    /// The reference value.
    pub reference: f64,
    /// `closed-form`, `published` or `converged-study`.
    pub kind: String,
    /// The case's tolerance (None for an informational check).
    pub tolerance: Option<Tolerance>,
}

impl Accuracy {
    /// |computed − reference|.
    pub fn error(&self) -> Option<f64> {
        self.computed
            .map(|c| error_of(&self.quantity, c, self.reference))
    }

    /// Whether the computed value is within the tolerance (None for an
    /// informational check).
    pub fn within(&self) -> Option<bool> {
        let t = self.tolerance?;
        Some(self.error().is_some_and(|e| t.admits(e, self.reference)))
    }
}

/// The method name a case lists for a solver method (`fe` for analyses
/// with no BVP method).
pub fn method_name(method: Method) -> String {
    match method {
        Method::Shooting => "shooting".into(),
        Method::MultipleShooting { .. } => "multiple-shooting".into(),
        Method::Collocation { stages } => format!("collocation-{stages}"),
    }
}

/// The comparisons of the benchmarked result with the references of the
/// validation case point that is the same problem; empty when there is
/// none. `values(length_scale)` gives the computed quantities in the
/// case's units.
pub fn compare(
    path: &Path,
    problem: &Problem,
    analysis: Analysis,
    method: &str,
    values: &dyn Fn(f64) -> BTreeMap<String, Option<f64>>,
) -> Vec<Accuracy> {
    let Ok(cases) = validate::load_cases(&validate::default_dir()) else {
        return Vec::new();
    };
    let Some(wanted) = physics(&problem.text) else {
        return Vec::new();
    };
    for case in cases.iter().filter(|c| {
        c.file.analysis == analysis.name()
            && c.file.scan.is_none()
            && c.file.methods.iter().any(|m| m == method)
    }) {
        if let Some((point, params)) = matching_point(case, path, &wanted) {
            let computed = values(case.file.length_scale);
            return references(case, point, &params, &computed);
        }
    }
    Vec::new()
}

/// The checks of `case` at `point` with the computed values.
fn references(
    case: &Case,
    point: &Point,
    params: &BTreeMap<String, f64>,
    computed: &BTreeMap<String, Option<f64>>,
) -> Vec<Accuracy> {
    case.file
        .check
        .iter()
        .filter(|c| c.points.as_ref().is_none_or(|l| l.contains(&point.label)))
        .filter_map(|c| {
            let reference = match (&c.reference.formula, c.reference.value) {
                (Some(f), _) => validate::reference::evaluate(f, params).ok()?,
                (None, v) => v?,
            };
            Some(Accuracy {
                case: format!("{} ({})", case.name, point.label),
                quantity: c.quantity.clone(),
                computed: computed.get(&c.quantity).copied().flatten(),
                reference,
                kind: c.reference.kind.clone(),
                tolerance: if c.informational { None } else { c.tolerance },
            })
        })
        .collect()
}

/// The point of `case` (not skipped) whose problem is `wanted`, with its
/// parameters; None when the case's problem file is another file.
fn matching_point<'c>(
    case: &'c Case,
    path: &Path,
    wanted: &toml::Table,
) -> Option<(&'c Point, BTreeMap<String, f64>)> {
    let file = case
        .path
        .parent()
        .unwrap_or(Path::new("."))
        .join(&case.file.problem);
    if file.canonicalize().ok()? != path.canonicalize().ok()? {
        return None;
    }
    case.file
        .point
        .iter()
        .filter(|p| p.skip.is_none())
        .find_map(|p| {
            let params = validate::point_params(&case.file, p).ok()?;
            let set = validate::fill(&case.file.overrides, &params);
            let q = crate::energies::read_problem(&file, &set).ok()?;
            (physics(&q.text).as_ref() == Some(wanted)).then_some((p, params))
        })
}

/// The problem text as a table without the keys that select the method
/// (those the validation runner sets per method): two texts with equal
/// tables are the same problem solved by possibly different methods.
fn physics(text: &str) -> Option<toml::Table> {
    let mut table: toml::Table = text.parse().ok()?;
    let method_keys: Vec<String> = validate::METHODS
        .iter()
        .flat_map(|m| validate::method_overrides(m))
        .filter_map(|o| o.split_once('=').map(|(k, _)| k.trim().to_string()))
        .collect();
    if let Some(solver) = table.get_mut("solver").and_then(toml::Value::as_table_mut) {
        for key in &method_keys {
            if let Some(name) = key.strip_prefix("solver.") {
                solver.remove(name);
            }
        }
        if solver.is_empty() {
            table.remove("solver");
        }
    }
    Some(table)
}
