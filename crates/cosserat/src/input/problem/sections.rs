//! The tables of a problem file as written: serde structs with their
//! defaults, before any physical check.
//!
//! Every table denies unknown keys; a profile (a stiffness or curvature
//! along s) is a number, `{ polynomial = [c_0, c_1, …] }` (Σ c_k s^k) or
//! `{ s = […], values = […] }` (a piecewise linear table).

use std::collections::BTreeMap;

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use crate::input::arm_section::ArmSection;
use crate::input::continuation_section::ContinuationSection;
use crate::input::strict;
use crate::input::support_section::SupportSection;
use crate::input::sweep_section::SweepSection;

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
    /// Finite elements (default: [`crate::stability::StabilityOptions::default`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    /// Lagrange order (1 to 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
    /// Lowest eigenvalues reported per block.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eigenvalues: Option<usize>,
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
    /// W as a formula (`kind = "formula"`, `model::Formula`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<String>,
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
    /// The frame then turned about a fixed axis (after `angle`), by an
    /// angle that may run through any number of turns.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turn: Option<crate::input::TurnSection>,
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
            turn: None,
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
    /// Dead loads at interior points (`[[loads.point]]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub point: Vec<PointLoadSection>,
}

/// One `[[loads.point]]`: a dead force (and, reserved, a couple) at the
/// interior point `s` of the reference arclength, global components.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PointLoadSection {
    /// Reference arclength of the point, 0 < s < L (m).
    pub s: f64,
    /// Force (N).
    #[serde(default, deserialize_with = "strict::array")]
    pub force: [f64; 3],
    /// Couple (N·m): accepted only as zero for now (see
    /// docs/problem-files.md: a couple makes M jump, which the solvers do
    /// not carry yet).
    #[serde(default, deserialize_with = "strict::array")]
    pub couple: [f64; 3],
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
    /// Guess of the tip support's reaction force, global components (N).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "strict::option"
    )]
    pub initial_reaction: Option<[f64; 3]>,
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
