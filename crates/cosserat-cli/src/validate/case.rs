//! Case files (`validation/<case>.toml`): the serde structs, loading a
//! directory of them, and the checks made before anything runs (known
//! quantities, every closed-form reference evaluable at its points, exactly
//! one tolerance per check that is not informational).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::runner::point_params;
use super::{reference, METHODS};

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

/// The error of `computed` against `reference` for `quantity`. An angle
/// (`tip_angle`, in (−π, π]) is compared on the circle: −π and π are one
/// direction — a rod rolled into a half circle points its tip back along
/// the clamp, and the sign of its angle is the sign of a rounding error.
pub fn error_of(quantity: &str, computed: f64, reference: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = computed - reference;
    if quantity == "tip_angle" {
        ((d + PI).rem_euclid(TAU) - PI).abs()
    } else {
        d.abs()
    }
}

impl Tolerance {
    /// Whether an error `abs` (from [`error_of`]) is within this tolerance
    /// of `reference`.
    pub fn admits(&self, abs: f64, reference: f64) -> bool {
        match (self.relative, self.absolute) {
            (Some(r), _) => abs <= r * reference.abs(),
            (None, Some(a)) => abs <= a,
            _ => false,
        }
    }
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

/// A case file or option that cannot be used (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

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
    const ANALYSES: [&str; 5] = [
        "solve",
        "critical-load",
        "jacobian-singularity",
        "stability-loss",
        "optimize",
    ];
    let bad = |m: String| InputError(format!("{}: {m}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let file: CaseFile = toml::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let analysis = file.analysis.as_str();
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

#[cfg(test)]
mod angle_tests {
    use super::error_of;
    use std::f64::consts::PI;

    /// −π and π are one direction; other quantities are plain numbers.
    #[test]
    fn angles_are_compared_on_the_circle() {
        assert!(error_of("tip_angle", -PI, PI) < 1e-15);
        assert!((error_of("tip_angle", -PI + 0.1, PI) - 0.1).abs() < 1e-12);
        assert!((error_of("tip_angle", 0.5, 0.2) - 0.3).abs() < 1e-12);
        assert_eq!(error_of("tip_x", -PI, PI), 2.0 * PI);
    }
}
