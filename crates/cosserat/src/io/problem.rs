//! Problem files: a TOML description of a rod scene and how to solve it.
//!
//! Every table rejects unknown keys; syntax errors carry line and column;
//! physical validation names the offending field. `--set key=value`
//! overrides are applied to the parsed document before it is read, so they
//! go through exactly the same checks. The reference of every key is in
//! docs/problem-files.md.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use nalgebra::Vector3;
use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::arm_section::ArmSection;
use super::continuation_section::ContinuationSection;
use super::strict;
use super::sweep_section::{Sweep, SweepSection};
use super::SupportSection;
use crate::bvp::newton::NewtonOptions;
use crate::bvp::{Method, SolverOptions, Strategy};
use crate::continuation::{ContinuationOptions, Family, Parameter};
use crate::model::{
    Clamp, DeadLoads, EnergyCatalog, EnergySpec, ModelChoice, ModelLevel, Profile, Rod, Shearable,
    StoredEnergy,
};
use crate::numerics::integrator::Tolerances;
use crate::optimize::{ArmProblem, ArmScene, SearchOptions};
use crate::stability::{FixedShape, StabilityOptions};

/// Why a problem could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ProblemError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The problem file.
        path: String,
        /// The error of the read.
        source: std::io::Error,
    },
    /// TOML syntax, an unknown or missing key, or a wrong type.
    #[error("{0}")]
    Parse(String),
    /// A `--set` override that cannot be applied.
    #[error("--set {assignment}: {message}")]
    Override {
        /// The `KEY=VALUE` as given.
        assignment: String,
        /// Why it cannot be applied.
        message: String,
    },
    /// A value that is well-formed but not physical or not consistent.
    #[error("{field}: {message}")]
    Invalid {
        /// The dotted key of the offending value (e.g. `rod.length`).
        field: String,
        /// What is wrong with it.
        message: String,
    },
}

pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> ProblemError {
    ProblemError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}

/// A problem file as written.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ProblemFile {
    /// The rod's geometry.
    pub rod: RodSection,
    /// The stored energy.
    pub energy: EnergySection,
    /// The clamp at s = 0.
    #[serde(default)]
    pub clamp: ClampSection,
    /// Dead loads.
    #[serde(default)]
    pub loads: LoadSection,
    /// What holds the tip (absent: a free tip).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub support: Option<SupportSection>,
    /// How to solve.
    #[serde(default)]
    pub solver: SolverSection,
    /// A loaded shape held fixed (paper Sec. 3): κ⁰ then follows from the
    /// load.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeSection>,
    /// How the second variation is discretized.
    #[serde(default)]
    pub stability: StabilitySection,
    /// What to continue, for `cosserat continue`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub continuation: Option<ContinuationSection>,
    /// The longest-arm optimization, for `cosserat optimize`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm: Option<ArmSection>,
    /// A grid over keys of this file, for `cosserat sweep`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep: Option<SweepSection>,
}

/// `[shape]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShapeSection {
    /// φ(s) (rad), from d3(0) towards d1(0), in the plane of d1(0), d3(0).
    pub turning_angle: ProfileSpec,
}

/// `[stability]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StabilitySection {
    /// Finite elements.
    #[serde(default = "default_elements")]
    pub elements: usize,
    /// Lagrange order (1 to 3).
    #[serde(default = "default_order")]
    pub order: usize,
    /// Lowest eigenvalues reported per block.
    #[serde(default = "default_eigenvalues")]
    pub eigenvalues: usize,
}

fn default_elements() -> usize {
    100
}
fn default_order() -> usize {
    2
}
fn default_eigenvalues() -> usize {
    4
}

impl Default for StabilitySection {
    fn default() -> Self {
        toml::from_str("").expect("every stability key has a default")
    }
}

/// `[rod]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RodSection {
    /// Reference length L (m).
    pub length: f64,
}

/// `[energy]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EnergySection {
    /// A name in the energy catalog: "linear", "quartic", or one a program
    /// registered ([`EnergyCatalog::register`]).
    #[serde(default = "default_energy_kind")]
    pub kind: String,
    /// B1, B2, B3 (N·m²), each a profile.
    #[serde(deserialize_with = "strict::array")]
    pub stiffness: [ProfileSpec; 3],
    /// κ⁰ body components (1/m), each a profile.
    #[serde(default, deserialize_with = "strict::array")]
    pub intrinsic_curvature: [ProfileSpec; 3],
    /// C (N·m⁴) of the quartic energy (shorthand for
    /// `parameters.quartic`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quartic: Option<f64>,
    /// Further numbers of a registered energy (`[energy.parameters]`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub parameters: BTreeMap<String, f64>,
    /// Shear and extension stiffnesses (k G A, k G A, E A) in N: a
    /// shearable, extensible Cosserat rod. Absent: unshearable and
    /// inextensible (Kirchhoff).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "strict::option"
    )]
    pub shear: Option<[f64; 3]>,
}

fn default_energy_kind() -> String {
    "linear".into()
}

/// A profile of s as written: a number, `{ polynomial = [...] }` or
/// `{ s = [...], values = [...] }`.
#[derive(Debug, Clone, Serialize, PartialEq)]
#[serde(untagged)]
pub enum ProfileSpec {
    /// A constant.
    Constant(f64),
    /// Polynomial coefficients in increasing powers of s.
    Polynomial {
        /// c_0, c_1, … of Σ c_k s^k.
        polynomial: Vec<f64>,
    },
    /// A piecewise-linear table.
    Table {
        /// Arc lengths s_k, strictly increasing.
        s: Vec<f64>,
        /// Values v_k at the s_k.
        values: Vec<f64>,
    },
}

impl Default for ProfileSpec {
    fn default() -> Self {
        ProfileSpec::Constant(0.0)
    }
}

impl<'de> Deserialize<'de> for ProfileSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ProfileVisitor;
        impl<'de> Visitor<'de> for ProfileVisitor {
            type Value = ProfileSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "a number, { polynomial = [c0, c1, ...] } or { s = [...], values = [...] }",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<ProfileSpec, E> {
                Ok(ProfileSpec::Constant(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<ProfileSpec, E> {
                Ok(ProfileSpec::Constant(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<ProfileSpec, E> {
                Ok(ProfileSpec::Constant(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ProfileSpec, A::Error> {
                #[derive(Deserialize)]
                #[serde(deny_unknown_fields)]
                struct Raw {
                    polynomial: Option<Vec<f64>>,
                    s: Option<Vec<f64>>,
                    values: Option<Vec<f64>>,
                }
                let raw = Raw::deserialize(de::value::MapAccessDeserializer::new(map))?;
                match (raw.polynomial, raw.s, raw.values) {
                    (Some(c), None, None) => Ok(ProfileSpec::Polynomial { polynomial: c }),
                    (None, Some(s), Some(values)) => Ok(ProfileSpec::Table { s, values }),
                    _ => Err(de::Error::custom(
                        "a profile table needs either `polynomial` or both `s` and `values`",
                    )),
                }
            }
        }
        d.deserialize_any(ProfileVisitor)
    }
}

/// `[clamp]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ClampSection {
    /// r(0) (m).
    #[serde(default, deserialize_with = "strict::array")]
    pub position: [f64; 3],
    /// d1(0), a unit vector.
    #[serde(default = "unit_x", deserialize_with = "strict::array")]
    pub d1: [f64; 3],
    /// d3(0), the tangent, a unit vector orthogonal to d1.
    #[serde(default = "unit_z", deserialize_with = "strict::array")]
    pub d3: [f64; 3],
    /// The frame (d1, d3) turned about d2 by this angle (rad), d3 towards
    /// d1: the clamp angle of the paper's Fig. 2.
    #[serde(default)]
    pub angle: f64,
    /// A hinge about d2 instead of a clamp (a pinned base; planar scenes).
    #[serde(default)]
    pub hinge: bool,
}

fn unit_x() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}

fn unit_z() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

impl Default for ClampSection {
    fn default() -> Self {
        ClampSection {
            position: [0.0; 3],
            d1: unit_x(),
            d3: unit_z(),
            angle: 0.0,
            hinge: false,
        }
    }
}

/// `[loads]`, global components.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LoadSection {
    /// Tip force (N).
    #[serde(default, deserialize_with = "strict::array")]
    pub tip_force: [f64; 3],
    /// Tip couple (N·m).
    #[serde(default, deserialize_with = "strict::array")]
    pub tip_couple: [f64; 3],
    /// Uniform force per unit length (N/m), e.g. self-weight ρAg.
    #[serde(default, deserialize_with = "strict::array")]
    pub distributed_force: [f64; 3],
}

/// `[solver]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SolverSection {
    /// "shooting", "multiple-shooting" or "collocation".
    #[serde(default = "default_method")]
    pub method: String,
    /// Segments of multiple shooting.
    #[serde(default = "default_segments")]
    pub segments: usize,
    /// Gauss points per interval of collocation (1 to 3; order 2·stages).
    #[serde(default = "default_stages")]
    pub stages: usize,
    /// Target of collocation's accumulated local error estimate (scaled
    /// state, max-norm).
    #[serde(default = "default_collocation_tolerance")]
    pub collocation_tolerance: f64,
    /// Intervals collocation's mesh adaptation may use at most.
    #[serde(default = "default_max_intervals")]
    pub max_intervals: usize,
    /// "auto", "planar" or "kirchhoff".
    #[serde(default = "default_auto")]
    pub model: String,
    /// "auto", "direct" or "ramp".
    #[serde(default = "default_auto")]
    pub strategy: String,
    /// Newton tolerance on the scaled residual.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Newton iteration budget.
    #[serde(default = "default_max_iterations")]
    pub max_iterations: usize,
    /// Relative and absolute tolerance of the integrator.
    #[serde(default = "default_integration_tolerance")]
    pub integration_tolerance: f64,
    /// Step budget of one integration.
    #[serde(default = "default_max_steps")]
    pub max_steps: usize,
    /// Output points along the rod.
    #[serde(default = "default_output_points")]
    pub output_points: usize,
    /// Guess of κ(0), body components (1/m).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "strict::option"
    )]
    pub initial_curvature: Option<[f64; 3]>,
}

fn default_method() -> String {
    "shooting".into()
}
fn default_stages() -> usize {
    3
}
fn default_collocation_tolerance() -> f64 {
    1e-10
}
fn default_max_intervals() -> usize {
    4096
}
fn default_segments() -> usize {
    8
}
fn default_auto() -> String {
    "auto".into()
}
fn default_tolerance() -> f64 {
    1e-10
}
fn default_max_iterations() -> usize {
    50
}
fn default_integration_tolerance() -> f64 {
    1e-12
}
fn default_max_steps() -> usize {
    100_000
}
fn default_output_points() -> usize {
    201
}

impl Default for SolverSection {
    fn default() -> Self {
        toml::from_str("").expect("every solver key has a default")
    }
}

/// A problem ready to solve.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The rod.
    pub rod: Rod,
    /// The model level and why.
    pub model: ModelChoice,
    /// The solver settings.
    pub options: SolverOptions,
    /// The effective problem text (with overrides applied), stored with
    /// results.
    pub text: String,
    /// The fixed loaded shape of a fixed-shape scene.
    pub shape: Option<FixedShape>,
    /// The discretization of the second variation.
    pub stability: StabilityOptions,
    /// The continued family and how to continue it.
    pub continuation: Option<(Family, ContinuationOptions)>,
    /// The arm optimization, its search, and whether to compute R̂0.
    pub arm: Option<(ArmProblem, SearchOptions, bool)>,
    /// The arm's loads and actuator limit, and the size of its reach map.
    pub arm_scene: Option<(ArmScene, usize)>,
    /// The grid of a `[sweep]` table.
    pub sweep: Option<Sweep>,
}

impl Problem {
    /// Reads a problem file and applies `key=value` overrides.
    pub fn from_path(path: &Path, overrides: &[String]) -> Result<Problem, ProblemError> {
        Problem::from_path_in(path, overrides, &EnergyCatalog::standard())
    }

    /// [`Problem::from_path`] with the energies of `catalog` (a program's
    /// own energies by name: examples/custom_energy.rs).
    pub fn from_path_in(
        path: &Path,
        overrides: &[String],
        catalog: &EnergyCatalog,
    ) -> Result<Problem, ProblemError> {
        let text = read_problem_file(path)?;
        Problem::from_str_in(&text, overrides, catalog)
    }

    /// Reads a problem from TOML text and applies `key=value` overrides.
    pub fn from_str_with(text: &str, overrides: &[String]) -> Result<Problem, ProblemError> {
        Problem::from_str_in(text, overrides, &EnergyCatalog::standard())
    }

    /// [`Problem::from_str_with`] with the energies of `catalog`.
    pub fn from_str_in(
        text: &str,
        overrides: &[String],
        catalog: &EnergyCatalog,
    ) -> Result<Problem, ProblemError> {
        if text.len() > MAX_PROBLEM_BYTES as usize {
            return Err(ProblemError::Parse(format!(
                "the problem text is {} bytes, more than the {MAX_PROBLEM_BYTES} a problem file \
                 may have; a problem file describes a rod, not data",
                text.len()
            )));
        }
        let text = apply_overrides(text, overrides)?;
        let file: ProblemFile = strict::parse(&text)?;
        let rod = build_rod(&file, catalog)?;
        let model = choose_model(&rod, &file.solver.model, file.energy.shear.is_some())?;
        if rod.clamp.hinge && model.level != ModelLevel::Planar {
            return Err(invalid(
                "clamp.hinge",
                format!(
                    "a hinged base needs the planar model, but the scene runs {}",
                    model.reason
                ),
            ));
        }
        let options = build_options(&file.solver)?;
        let shape = build_shape(&file)?;
        let stability = build_stability(&file.stability)?;
        eigenvalue_count("stability", &stability, &rod)?;
        let continuation = build_continuation(&file, &rod, &model, &options, shape.as_ref())?;
        let arm = file.arm.as_ref().map(|a| a.build(&rod)).transpose()?;
        let arm_scene = file
            .arm
            .as_ref()
            .map(|a| a.scene(&rod).map(|s| (s, a.map_samples)))
            .transpose()?;
        let sweep = file.sweep.as_ref().map(SweepSection::build).transpose()?;
        let problem = Problem {
            rod,
            model,
            options,
            text,
            shape,
            stability,
            continuation,
            arm,
            arm_scene,
            sweep,
        };
        // Before any command allocates: what the sizes ask for must fit.
        super::memory::check(&problem)?;
        Ok(problem)
    }
}

/// The largest problem file read: 1 MiB (the shipped ones are under 3 KiB).
pub const MAX_PROBLEM_BYTES: u64 = 1 << 20;

/// The text of a problem file, refusing before reading anything what is not
/// a regular file (a directory; a device such as /dev/zero or a FIFO would
/// be read without end, or block) or is larger than [`MAX_PROBLEM_BYTES`];
/// at most that many bytes are read even if the file grows meanwhile.
fn read_problem_file(path: &Path) -> Result<String, ProblemError> {
    use std::io::Read;
    let fail = |message: String| ProblemError::Read {
        path: path.display().to_string(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, message),
    };
    let io = |source: std::io::Error| ProblemError::Read {
        path: path.display().to_string(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(fail(
            "is a directory; give a problem file (TOML), e.g. problems/cantilever_tip_load.toml"
                .into(),
        ));
    }
    if !meta.is_file() {
        return Err(fail(
            "is not a regular file (a device, FIFO or socket would be read without end); give a \
             problem file (TOML)"
                .into(),
        ));
    }
    if meta.len() > MAX_PROBLEM_BYTES {
        return Err(fail(format!(
            "is {} bytes, more than the {MAX_PROBLEM_BYTES} (1 MiB) a problem file may have; is \
             it the right file?",
            meta.len()
        )));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_PROBLEM_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_PROBLEM_BYTES {
        return Err(fail(format!(
            "grew beyond {MAX_PROBLEM_BYTES} bytes (1 MiB) while being read"
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        fail(format!(
            "is not UTF-8 text (byte {}); a problem file is TOML text",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// The text with every `a.b.c=value` applied; the value is read as a TOML
/// value (number, boolean, array, inline table, quoted string), else as a
/// bare string.
fn apply_overrides(text: &str, overrides: &[String]) -> Result<String, ProblemError> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| ProblemError::Parse(e.to_string()))?;
    for assignment in overrides {
        let fail = |message: &str| ProblemError::Override {
            assignment: assignment.clone(),
            message: message.into(),
        };
        let (key, raw) = assignment
            .split_once('=')
            .ok_or_else(|| fail("expected key=value"))?;
        let path: Vec<&str> = key.trim().split('.').map(str::trim).collect();
        if path.iter().any(|p| p.is_empty()) {
            return Err(fail("empty key"));
        }
        let value = parse_value(raw.trim());
        let (last, parents) = path.split_last().expect("non-empty path");
        let mut table = &mut doc;
        for part in parents {
            let entry = table
                .entry(part.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            table = entry
                .as_table_mut()
                .ok_or_else(|| fail(&format!("`{part}` is not a table")))?;
        }
        match indexed(last) {
            Some((name, i)) => {
                let list = table
                    .get_mut(name)
                    .and_then(toml::Value::as_array_mut)
                    .ok_or_else(|| fail(&format!("`{name}` is not an array")))?;
                let len = list.len();
                *list
                    .get_mut(i)
                    .ok_or_else(|| fail(&format!("`{name}` has {len} elements, no [{i}]")))? =
                    value;
            }
            None => {
                table.insert(last.to_string(), value);
            }
        }
    }
    toml::to_string(&doc).map_err(|e| ProblemError::Parse(e.to_string()))
}

/// `name[i]` → (name, i): one element of an array, as in
/// `--set energy.stiffness[0]=4` (what `[sweep]` axes and continuation
/// parameters are named).
fn indexed(part: &str) -> Option<(&str, usize)> {
    let (name, rest) = part.split_once('[')?;
    let i = rest.strip_suffix(']')?.trim().parse().ok()?;
    Some((name.trim(), i))
}

fn parse_value(raw: &str) -> toml::Value {
    format!("v = {raw}")
        .parse::<toml::Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(raw.to_string()))
}

fn finite(field: &str, v: f64) -> Result<f64, ProblemError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be a finite number, got {v}")))
    }
}

fn vector(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, ProblemError> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{field}[{i}]"), *x)?;
    }
    Ok(Vector3::from(v))
}

/// The magnitudes a material or load number may have: 0, or 1e-100 to
/// 1e100. Products of three such numbers (a load times a length squared
/// over a stiffness, B/h · κ²) stay inside the floating-point range
/// (1e±308); beyond it a critical load came out NaN or "none" with exit
/// code 0.
pub const MAGNITUDE_RANGE: (f64, f64) = (1e-100, 1e100);

fn magnitude(field: &str, v: f64) -> Result<f64, ProblemError> {
    let v = finite(field, v)?;
    let a = v.abs();
    if a == 0.0 || (MAGNITUDE_RANGE.0..=MAGNITUDE_RANGE.1).contains(&a) {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!(
                "{v:e} is outside the magnitudes [{:e}, {:e}] (or 0) that keep products of the \
                 problem's numbers inside the floating-point range; change the units",
                MAGNITUDE_RANGE.0, MAGNITUDE_RANGE.1
            ),
        ))
    }
}

/// A vector of loads or curvatures: finite, each component within
/// [`MAGNITUDE_RANGE`] or zero.
fn load_vector(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, ProblemError> {
    for (i, x) in v.iter().enumerate() {
        magnitude(&format!("{field}[{i}]"), *x)?;
    }
    Ok(Vector3::from(v))
}

fn profile(field: &str, spec: &ProfileSpec) -> Result<Profile, ProblemError> {
    let p = match spec {
        ProfileSpec::Constant(c) => Profile::Constant(*c),
        ProfileSpec::Polynomial { polynomial } => {
            if polynomial.is_empty() {
                return Err(invalid(
                    field,
                    "a polynomial needs at least one coefficient",
                ));
            }
            Profile::Polynomial(polynomial.clone())
        }
        ProfileSpec::Table { s, values } => {
            if s.len() < 2 || s.len() != values.len() {
                return Err(invalid(
                    field,
                    format!(
                        "a table needs at least two points and as many values as s ({} s, {} values)",
                        s.len(),
                        values.len()
                    ),
                ));
            }
            if !s.windows(2).all(|w| w[1] > w[0]) {
                return Err(invalid(format!("{field}.s"), "must be strictly increasing"));
            }
            Profile::Table {
                s: s.clone(),
                values: values.clone(),
            }
        }
    };
    if !p.is_finite() {
        return Err(invalid(field, "must contain finite numbers only"));
    }
    let numbers: Vec<f64> = match spec {
        ProfileSpec::Constant(c) => vec![*c],
        ProfileSpec::Polynomial { polynomial } => polynomial.clone(),
        ProfileSpec::Table { s, values } => s.iter().chain(values).copied().collect(),
    };
    for v in numbers {
        magnitude(field, v)?;
    }
    Ok(p)
}

fn build_rod(file: &ProblemFile, catalog: &EnergyCatalog) -> Result<Rod, ProblemError> {
    let length = finite("rod.length", file.rod.length)?;
    if length <= 0.0 {
        return Err(invalid(
            "rod.length",
            format!(
                "must be positive, got {length} (accepted: [{:e}, {:e}] in the file's length \
                 unit)",
                LENGTH_RANGE.0, LENGTH_RANGE.1
            ),
        ));
    }
    if !(LENGTH_RANGE.0..=LENGTH_RANGE.1).contains(&length) {
        return Err(invalid(
            "rod.length",
            format!(
                "{length} is outside [{:e}, {:e}]: positions (of order L) and curvatures (of \
                 order 1/L) are integrated with one absolute tolerance, so a length far from 1 \
                 loses digits (at 1e-320 the finite elements divide by zero); choose the length \
                 unit so that L is near 1 (any consistent units work)",
                LENGTH_RANGE.0, LENGTH_RANGE.1
            ),
        ));
    }
    let mut energy = build_energy(&file.energy, length, catalog)?;
    if let Some(shear) = file.energy.shear {
        // A level forced below Cosserat takes the unshearable limit.
        if !matches!(
            file.solver.model.as_str(),
            "planar" | "kirchhoff" | "spatial"
        ) {
            energy = Arc::new(Shearable {
                bending: energy,
                shear: shear_stiffness(shear)?,
            });
        }
    }
    let clamp = build_clamp(&file.clamp)?;
    let support = file
        .support
        .as_ref()
        .map(|s| s.build(&clamp, length))
        .transpose()?;
    Ok(Rod {
        length,
        energy,
        clamp,
        loads: DeadLoads {
            tip_force: load_vector("loads.tip_force", file.loads.tip_force)?,
            tip_couple: load_vector("loads.tip_couple", file.loads.tip_couple)?,
            distributed_force: load_vector(
                "loads.distributed_force",
                file.loads.distributed_force,
            )?,
        },
        support,
    })
}

/// S = (k G A, k G A, E A): positive and finite.
fn shear_stiffness(shear: [f64; 3]) -> Result<nalgebra::Vector3<f64>, ProblemError> {
    for (i, v) in shear.iter().enumerate() {
        let field = format!("energy.shear[{i}]");
        let v = magnitude(&field, *v)?;
        if v <= 0.0 {
            return Err(invalid(field, format!("must be positive, got {v}")));
        }
    }
    Ok(nalgebra::Vector3::from(shear))
}

/// The energy named by `energy.kind` in `catalog`, from the validated
/// profiles and parameters (`energy.quartic` is a shorthand for
/// `energy.parameters.quartic`).
fn build_energy(
    e: &EnergySection,
    length: f64,
    catalog: &EnergyCatalog,
) -> Result<Arc<dyn StoredEnergy>, ProblemError> {
    let mut spec = EnergySpec {
        stiffness: Default::default(),
        intrinsic_curvature: Default::default(),
        parameters: Default::default(),
    };
    let mut softest: Option<(f64, String)> = None;
    let mut stiffest: Option<(f64, String)> = None;
    for i in 0..3 {
        let field = format!("energy.stiffness[{i}]");
        spec.stiffness[i] = profile(&field, &e.stiffness[i])?;
        // Exact where the profile allows (Profile::extremes_on): a table at
        // its knots, a polynomial at the roots of its derivative, with a
        // certified lower bound.
        let x = spec.stiffness[i].extremes_on(length);
        if x.min.is_nan() || x.min <= 0.0 {
            return Err(invalid(
                field,
                format!(
                    "must be positive on [0, L], but its minimum is {:.6e} at s = {}; make the \
                     profile positive on the whole rod",
                    x.min, x.argmin
                ),
            ));
        }
        if x.min_lower <= 0.0 {
            return Err(invalid(
                field,
                format!(
                    "its minimum {:.6e} at s = {} is within rounding ({:.1e}) of zero, so it cannot be \
                     certified positive; make the profile clearly positive",
                    x.min,
                    x.argmin,
                    x.min - x.min_lower
                ),
            ));
        }
        if softest.as_ref().is_none_or(|(v, _)| x.min < *v) {
            softest = Some((x.min, field.clone()));
        }
        if stiffest.as_ref().is_none_or(|(v, _)| x.max > *v) {
            stiffest = Some((x.max, field.clone()));
        }
        spec.intrinsic_curvature[i] = profile(
            &format!("energy.intrinsic_curvature[{i}]"),
            &e.intrinsic_curvature[i],
        )?;
    }
    if let (Some((lo, soft)), Some((hi, stiff))) = (softest, stiffest) {
        if hi / lo > MAX_STIFFNESS_RATIO {
            return Err(invalid(
                soft,
                format!(
                    "the stiffness ratio {:.3e} ({stiff} up to {hi:e}, this down to {lo:e}) \
                     exceeds {MAX_STIFFNESS_RATIO:.3e} = 1/(4ε): the softer stiffness is then \
                     below four rounding units of the stiffer one in the sums of the equations \
                     and the second variation, and is lost; a stiffness that large is the \
                     constraint limit — keep the ratio below it",
                    hi / lo
                ),
            ));
        }
    }
    for (name, value) in &e.parameters {
        let v = magnitude(&format!("energy.parameters.{name}"), *value)?;
        spec.parameters.insert(name.clone(), v);
    }
    if let Some(c) = e.quartic {
        let c = magnitude("energy.quartic", c)?;
        if spec.parameters.insert("quartic".into(), c).is_some() {
            return Err(invalid(
                "energy.quartic",
                "given twice (also as energy.parameters.quartic)",
            ));
        }
    }
    let shorthand = e.quartic.is_some();
    match catalog.build(&e.kind, &spec) {
        Some(Ok(energy)) => Ok(energy),
        Some(Err(err)) => {
            let field = if shorthand && err.field == "energy.parameters.quartic" {
                "energy.quartic".to_owned()
            } else {
                err.field
            };
            Err(invalid(field, err.message))
        }
        None => Err(invalid(
            "energy.kind",
            format!(
                "unknown energy `{}`; registered: {}",
                e.kind,
                catalog.names().join(", ")
            ),
        )),
    }
}

/// The accepted rod lengths (in the file's length unit).
pub const LENGTH_RANGE: (f64, f64) = (1e-6, 1e6);

/// The largest ratio of the stiffest to the softest bending or torsional
/// stiffness anywhere on the rod: 1/(4ε) ≈ 1.1e15.
pub const MAX_STIFFNESS_RATIO: f64 = 0.25 / f64::EPSILON;

/// Orthonormality tolerance of the clamp frame.
const FRAME_TOLERANCE: f64 = 1e-9;

fn build_clamp(c: &ClampSection) -> Result<Clamp, ProblemError> {
    let position = vector("clamp.position", c.position)?;
    let d1 = vector("clamp.d1", c.d1)?;
    let d3 = vector("clamp.d3", c.d3)?;
    for (name, d) in [("clamp.d1", d1), ("clamp.d3", d3)] {
        if (d.norm() - 1.0).abs() > FRAME_TOLERANCE {
            return Err(invalid(
                name,
                format!("must be a unit vector, |{name}| = {}", d.norm()),
            ));
        }
    }
    if d1.dot(&d3).abs() > FRAME_TOLERANCE {
        return Err(invalid(
            "clamp.d3",
            format!("must be orthogonal to clamp.d1, d1·d3 = {}", d1.dot(&d3)),
        ));
    }
    let angle = finite("clamp.angle", c.angle)?;
    let clamp = Clamp::new(position, d1, d3);
    Ok(Clamp {
        frame: clamp.turned_frame(angle),
        hinge: c.hinge,
        ..clamp
    })
}

/// The model level: automatic, or forced by `solver.model`. `sheared` says
/// whether the file gave shear stiffnesses (dropped by `build_rod` when a
/// lower level is forced, which the reason then says).
fn choose_model(rod: &Rod, model: &str, sheared: bool) -> Result<ModelChoice, ProblemError> {
    let level = match model {
        "auto" => return Ok(ModelChoice::for_rod(rod)),
        "planar" => ModelLevel::Planar,
        "kirchhoff" | "spatial" => ModelLevel::Kirchhoff,
        "cosserat" => ModelLevel::Cosserat,
        other => {
            return Err(invalid(
                "solver.model",
                format!(
                    "unknown model `{other}`; expected \"auto\", \"planar\", \"kirchhoff\" \
                     or \"cosserat\""
                ),
            ))
        }
    };
    let mut choice = ModelChoice::forced(rod, level).map_err(|m| invalid("solver.model", m))?;
    if sheared && level != ModelLevel::Cosserat {
        choice.reason += "; energy.shear ignored (the unshearable, inextensible limit)";
    }
    Ok(choice)
}

/// The family of a `[continuation]` table, discretized by the solver's
/// shooting method at the scene's model level.
fn build_continuation(
    file: &ProblemFile,
    rod: &Rod,
    model: &ModelChoice,
    options: &SolverOptions,
    shape: Option<&FixedShape>,
) -> Result<Option<(Family, ContinuationOptions)>, ProblemError> {
    let Some(section) = &file.continuation else {
        return Ok(None);
    };
    let (parameter, opts) = section.build()?;
    eigenvalue_count("continuation", &opts.stability, rod)?;
    let (segments, stages) = match options.method {
        Method::Shooting => (1, None),
        Method::MultipleShooting { segments } => (segments, None),
        Method::Collocation { stages } => {
            if !(1..=10_000).contains(&section.intervals) {
                return Err(invalid(
                    "continuation.intervals",
                    format!("must be between 1 and 10000, got {}", section.intervals),
                ));
            }
            (section.intervals, Some(stages))
        }
    };
    if let Some(shape) = shape {
        // A fixed shape's κ⁰ follows from the load; continuation needs a
        // rod with one κ⁰: only shapes on which the loads make no moment
        // (κ⁰ = φ', e.g. a straight column under an axial load) qualify.
        let fe_points: Vec<f64> = (0..=64).map(|i| rod.length * i as f64 / 64.0).collect();
        let moment = shape
            .samples(rod, &fe_points)
            .map_err(|e| invalid("shape", e.to_string()))?
            .iter()
            .map(|p| p.moment.norm())
            .fold(0.0, f64::max);
        if moment > 1e-12 * rod.moment_scale()
            || !matches!(shape.turning_angle, Profile::Constant(_))
        {
            return Err(invalid(
                "shape",
                "continuation from a fixed shape needs a straight shape on which the loads make no moment",
            ));
        }
    }
    let mut base = rod.clone();
    if parameter == Parameter::ClampAngle {
        // The parameter is the absolute angle: start from the unturned frame.
        base.clamp.frame = rod.clamp.turned_frame(-file.clamp.angle);
    }
    let family = match stages {
        None => Family::new(base, parameter, model.level, segments, options.integration),
        Some(m) => Family::collocation(
            base,
            parameter,
            model.level,
            segments,
            m,
            options.integration,
        ),
    };
    // A parameter the energy cannot vary (a varying profile, an energy
    // without that profile) is refused here, not at the first point.
    family
        .rod_at(opts.start)
        .map_err(|e| invalid("continuation.parameter", e.to_string()))?;
    Ok(Some((family, opts)))
}

fn build_shape(file: &ProblemFile) -> Result<Option<FixedShape>, ProblemError> {
    let Some(shape) = &file.shape else {
        return Ok(None);
    };
    let turning_angle = profile("shape.turning_angle", &shape.turning_angle)?;
    if file.energy.kind != "linear" {
        return Err(invalid(
            "shape",
            "a fixed-shape scene needs energy.kind = \"linear\" (K is then linear in the load)",
        ));
    }
    if file
        .energy
        .intrinsic_curvature
        .iter()
        .any(|p| *p != ProfileSpec::Constant(0.0))
    {
        return Err(invalid(
            "energy.intrinsic_curvature",
            "a fixed-shape scene derives κ⁰ from the shape and the load (paper (43)); remove it",
        ));
    }
    if file.loads.tip_couple != [0.0; 3] {
        return Err(invalid(
            "loads.tip_couple",
            "a fixed-shape scene takes forces only",
        ));
    }
    Ok(Some(FixedShape { turning_angle }))
}

/// The fewest unknowns a block of the second variation can have: the
/// in-plane block has one rotation per node but the clamped one
/// (elements × order), and a tip support removes up to six more
/// (three held translations, three held rotations).
pub(crate) fn fewest_block_unknowns(opts: &StabilityOptions, rod: &Rod) -> usize {
    let nodes = opts.elements.saturating_mul(opts.order);
    if rod.support.is_some() {
        nodes.saturating_sub(6)
    } else {
        nodes
    }
}

/// The eigenvalues asked per block exist on the mesh (a count beyond the
/// block's unknowns made the continuation tracker index past its columns).
fn eigenvalue_count(table: &str, opts: &StabilityOptions, rod: &Rod) -> Result<(), ProblemError> {
    let most = fewest_block_unknowns(opts, rod);
    if opts.eigenvalues > most {
        return Err(invalid(
            format!("{table}.eigenvalues"),
            format!(
                "{} eigenvalues per block, but the smallest block of {} elements of order {} \
                 has {most} unknowns{}: lower {table}.eigenvalues to at most {most} or raise \
                 {table}.elements",
                opts.eigenvalues,
                opts.elements,
                opts.order,
                if rod.support.is_some() {
                    " (elements × order, less six held by the support)"
                } else {
                    " (elements × order)"
                },
            ),
        ));
    }
    Ok(())
}

fn build_stability(s: &StabilitySection) -> Result<StabilityOptions, ProblemError> {
    if s.elements < 1 {
        return Err(invalid("stability.elements", "must be at least 1"));
    }
    if !(1..=3).contains(&s.order) {
        return Err(invalid(
            "stability.order",
            format!("must be 1, 2 or 3, got {}", s.order),
        ));
    }
    if s.eigenvalues < 1 {
        return Err(invalid("stability.eigenvalues", "must be at least 1"));
    }
    Ok(StabilityOptions {
        elements: s.elements,
        order: s.order,
        eigenvalues: s.eigenvalues,
    })
}

/// The meaningful range of a tolerance-like key and why (docs/problem-files.md
/// lists each).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Range {
    /// Smallest value accepted.
    pub lo: f64,
    /// Largest value accepted.
    pub hi: f64,
    /// Why the range ends there and what to choose instead.
    pub why: &'static str,
}

/// Newton's tolerance on the scaled residual (`solver.tolerance`,
/// `continuation.tolerance`): the correction must then be below √τ, so
/// above 1e-6 a "converged" shape may be wrong in its third digit (at τ = 1
/// any iterate passes); below 1e-15 (≈ 5 ε) round-off alone keeps the
/// scaled residual above it.
pub(crate) const NEWTON_TOLERANCE: Range = Range {
    lo: 1e-15,
    hi: 1e-6,
    why: "the scaled residual Newton must reach; above 1e-6 a converged shape may be \
          wrong in its third digit, below 1e-15 round-off cannot reach it; e.g. 1e-10",
};

/// The integrator's relative and absolute tolerance: the shooting
/// residual, and so the shape, is only as accurate as the integration.
pub(crate) const INTEGRATION_TOLERANCE: Range = Range {
    lo: 1e-14,
    hi: 1e-6,
    why: "the shape is only as accurate as the integration; above 1e-6 fewer than six \
          digits are right, below 1e-14 DOP853's steps underflow in round-off; e.g. 1e-12",
};

/// Collocation's target for its accumulated local error estimate.
pub(crate) const COLLOCATION_TOLERANCE: Range = Range {
    lo: 1e-14,
    hi: 1e-6,
    why: "the mesh is refined until the error estimate is below it; above 1e-6 fewer than \
          six digits are right, below 1e-14 round-off in the estimate dominates; e.g. 1e-10",
};

/// A tolerance-like number within its range.
pub(crate) fn within(field: &str, v: f64, range: Range) -> Result<f64, ProblemError> {
    if v.is_finite() && (range.lo..=range.hi).contains(&v) {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!(
                "{v} is outside [{:e}, {:e}] ({})",
                range.lo, range.hi, range.why
            ),
        ))
    }
}

fn build_options(s: &SolverSection) -> Result<SolverOptions, ProblemError> {
    let method = match s.method.as_str() {
        "shooting" => Method::Shooting,
        "multiple-shooting" => {
            if s.segments < 1 {
                return Err(invalid("solver.segments", "must be at least 1"));
            }
            Method::MultipleShooting {
                segments: s.segments,
            }
        }
        "collocation" => {
            if !(1..=3).contains(&s.stages) {
                return Err(invalid("solver.stages", "must be 1, 2 or 3"));
            }
            Method::Collocation { stages: s.stages }
        }
        other => {
            return Err(invalid(
                "solver.method",
                format!(
                    "unknown method `{other}`; expected \"shooting\", \"multiple-shooting\" \
                     or \"collocation\""
                ),
            ))
        }
    };
    let defaults = crate::bvp::CollocationOptions::default();
    if s.max_intervals < defaults.intervals {
        return Err(invalid(
            "solver.max_intervals",
            format!("must be at least {}", defaults.intervals),
        ));
    }
    let collocation = crate::bvp::CollocationOptions {
        stages: s.stages,
        tolerance: within(
            "solver.collocation_tolerance",
            s.collocation_tolerance,
            COLLOCATION_TOLERANCE,
        )?,
        max_intervals: s.max_intervals,
        ..defaults
    };
    let strategy = match s.strategy.as_str() {
        "auto" => Strategy::Auto,
        "direct" => Strategy::Direct,
        "ramp" => Strategy::Ramp,
        other => {
            return Err(invalid(
                "solver.strategy",
                format!("unknown strategy `{other}`; expected \"auto\", \"direct\" or \"ramp\""),
            ))
        }
    };
    let tol = within(
        "solver.integration_tolerance",
        s.integration_tolerance,
        INTEGRATION_TOLERANCE,
    )?;
    if s.max_steps < 1 {
        return Err(invalid(
            "solver.max_steps",
            "must be at least 1 (the step budget of one integration; e.g. 100000)",
        ));
    }
    if s.output_points < 2 {
        return Err(invalid("solver.output_points", "must be at least 2"));
    }
    if s.max_iterations < 1 {
        return Err(invalid("solver.max_iterations", "must be at least 1"));
    }
    let initial_guess = match s.initial_curvature {
        Some(k) => Some(vector("solver.initial_curvature", k)?.as_slice().to_vec()),
        None => None,
    };
    Ok(SolverOptions {
        method,
        newton: NewtonOptions {
            tolerance: within("solver.tolerance", s.tolerance, NEWTON_TOLERANCE)?,
            max_iterations: s.max_iterations,
            ..Default::default()
        },
        integration: Tolerances {
            rtol: tol,
            atol: tol,
            max_steps: s.max_steps,
        },
        collocation,
        output_points: s.output_points,
        initial_guess,
        strategy,
    })
}
