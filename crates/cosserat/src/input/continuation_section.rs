//! The `[continuation]` table of a problem file: which number to continue
//! and how (BifurcationKit's ContinuationPar, as TOML).

use serde::{Deserialize, Serialize};

use super::mesh::MeshKeys;
use super::problem::{invalid, within, ProblemError, NEWTON_TOLERANCE};
use crate::continuation::{ContinuationOptions, Measure, StopAt};

/// One entry of `continuation.link`: a numeric key of the rod's tables
/// set to `factor`·p + `offset` whenever the parameter is p.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LinkSection {
    /// The linked key, in the `--set` grammar (`support.turn.angle`).
    pub key: String,
    /// d(key)/dp.
    #[serde(default = "unit_factor")]
    pub factor: f64,
    /// The key's value at p = 0.
    #[serde(default)]
    pub offset: f64,
}

fn unit_factor() -> f64 {
    1.0
}

/// One entry of `continuation.stop_at`: a branch ends where the measure
/// `measure` (one of `continuation.measures`) reaches `value`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StopAtSection {
    /// The measure's name, as listed in `continuation.measures`.
    pub measure: String,
    /// The value the branch stops at.
    pub value: f64,
}

/// `[continuation]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContinuationSection {
    /// The key of the continued number: `load_scale`, `control_scale`, or
    /// any numeric key of `[rod]`, `[energy]`, `[clamp]`, `[support]`,
    /// `[loads]` in the `--set` grammar (`loads.tip_force[2]`,
    /// `support.position[2]`, `support.turn.angle`, `energy.parameters.quartic`).
    pub parameter: String,
    /// Keys set with the parameter (linked parameters): each to
    /// factor·p + offset, e.g. both end turns of a strip by one angle.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub link: Vec<LinkSection>,
    /// The value to start from.
    pub start: f64,
    /// [min, max]: a branch stops when the parameter leaves it.
    #[serde(deserialize_with = "super::strict::array")]
    pub bounds: [f64; 2],
    /// Initial arclength step.
    #[serde(default = "default_step")]
    pub step: f64,
    /// Smallest step.
    #[serde(default = "default_min_step")]
    pub min_step: f64,
    /// Largest step.
    #[serde(default = "default_max_step")]
    pub max_step: f64,
    /// Points per branch at most.
    #[serde(default = "default_max_points")]
    pub max_points: usize,
    /// Follow the first branch both ways from the start.
    #[serde(default)]
    pub both_directions: bool,
    /// Depth of recursive branch switching.
    #[serde(default = "default_depth")]
    pub switch_depth: usize,
    /// Stop a branch when the tip tangent has turned this far (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_angle_limit: Option<f64>,
    /// Finite elements of the tracked second variation (default:
    /// [`crate::stability::StabilityOptions::default`], as in every table).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    /// Their Lagrange order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
    /// Eigenvalues tracked per block.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eigenvalues: Option<usize>,
    /// Corrector tolerance (scaled residual).
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Collocation intervals of the continued discretization when
    /// `solver.method = "collocation"` (a fixed mesh; Gauss points per
    /// interval from `solver.stages`).
    #[serde(default = "default_intervals")]
    pub intervals: usize,
    /// What `cosserat plot` puts on the vertical axis by default: `tip_x`,
    /// `tip_y`, `tip_z`, `norm` or `tip_angle`.
    #[serde(default = "default_measure")]
    pub measure: String,
    /// Measures computed and stored at every point
    /// ([`crate::continuation::Measure`]): `force[2]@0`, `turning`, …
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub measures: Vec<String>,
    /// Stop values: a branch ends where one of `measures` reaches its
    /// value, landed on it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stop_at: Vec<StopAtSection>,
    /// `[continuation.curve]`: a stored fold or branch point followed in
    /// a second parameter (`cosserat continue --from … --point special/K
    /// --curve`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<CurveSection>,
    /// Equally spaced shape points stored per point (the clamp and the
    /// tip included).
    #[serde(default = "default_shape_points")]
    pub shape_points: usize,
    /// `[[continuation.stage]]`: later stages of the run, each continuing
    /// its own key from the last point of the stage before's first branch
    /// with that stage's key held (this table is stage 1).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stage: Vec<StageSection>,
}

/// `[[continuation.stage]]`: a later stage of a chained run. It names its
/// key, start and bounds; the step settings it leaves out are those of
/// `[continuation]`, and what one diagram must share (measures, the
/// tracked eigenvalues, shapes, the collocation mesh) is not a stage's to
/// change.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StageSection {
    /// The continued key (as `continuation.parameter`).
    pub parameter: String,
    /// Its value at the stage's first point.
    pub start: f64,
    /// [min, max] of the key.
    #[serde(deserialize_with = "super::strict::array")]
    pub bounds: [f64; 2],
    /// Initial arclength step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
    /// Smallest step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_step: Option<f64>,
    /// Largest step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_step: Option<f64>,
    /// Points per branch at most.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_points: Option<usize>,
    /// Follow the stage's first branch both ways.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub both_directions: Option<bool>,
    /// Depth of recursive branch switching.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub switch_depth: Option<usize>,
    /// Stop a branch when the tip tangent has turned this far (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_angle_limit: Option<f64>,
    /// The stage's own stop values (the first stage's are not inherited).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stop_at: Vec<StopAtSection>,
    /// Corrector tolerance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
}

fn default_shape_points() -> usize {
    21
}

/// The most shape points per diagram point: a 400-point branch of 10 001
/// positions is 96 MB, a full-resolution picture of any rod these meshes
/// resolve.
pub const MAX_SHAPE_POINTS: usize = 10_001;

/// `[continuation.curve]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CurveSection {
    /// The second parameter's key (as `continuation.parameter`).
    pub parameter: String,
    /// Its value at the stored special point (the problem's own value).
    pub start: f64,
    /// [min, max] of the second parameter.
    #[serde(deserialize_with = "super::strict::array")]
    pub bounds: [f64; 2],
    /// First arclength step.
    #[serde(default = "default_step")]
    pub step: f64,
    /// Largest step.
    #[serde(default = "default_max_step")]
    pub max_step: f64,
    /// Points per direction at most.
    #[serde(default = "default_max_points")]
    pub max_points: usize,
}

/// `bounds` = [lo, hi] finite with lo < hi, and `start` inside them;
/// `table` names the keys (`continuation`, `continuation.curve`).
fn bounds_with_start(
    table: &str,
    [lo, hi]: [f64; 2],
    start: f64,
) -> Result<(f64, f64), ProblemError> {
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(invalid(
            format!("{table}.bounds"),
            format!("need finite lo < hi, got [{lo}, {hi}]"),
        ));
    }
    if !(start.is_finite() && (lo..=hi).contains(&start)) {
        return Err(invalid(
            format!("{table}.start"),
            format!("{start} is not inside the bounds"),
        ));
    }
    Ok((lo, hi))
}

impl CurveSection {
    /// The key and the curve options (the first parameter's bounds from
    /// `[continuation]`), validated.
    pub fn build(
        &self,
        first: &ContinuationOptions,
    ) -> Result<(String, f64, crate::continuation::CurveOptions), ProblemError> {
        let (lo, hi) = bounds_with_start("continuation.curve", self.bounds, self.start)?;
        let step = positive("continuation.curve.step", self.step)?;
        let max_step = positive("continuation.curve.max_step", self.max_step)?;
        if step > max_step {
            return Err(invalid("continuation.curve.step", "need step ≤ max_step"));
        }
        if self.max_points < 1 {
            return Err(invalid(
                "continuation.curve.max_points",
                "must be at least 1",
            ));
        }
        Ok((
            self.parameter.trim().to_string(),
            self.start,
            crate::continuation::CurveOptions {
                bounds: [first.bounds, (lo, hi)],
                step,
                min_step: first.min_step,
                max_step,
                max_points: self.max_points,
                tolerance: first.tolerance.max(1e-10),
            },
        ))
    }
}

fn default_step() -> f64 {
    0.05
}
fn default_min_step() -> f64 {
    1e-7
}
fn default_max_step() -> f64 {
    0.2
}
fn default_max_points() -> usize {
    400
}
fn default_depth() -> usize {
    1
}
fn default_intervals() -> usize {
    32
}
fn default_tolerance() -> f64 {
    1e-11
}
fn default_measure() -> String {
    "tip_x".into()
}

/// The measures `cosserat plot` knows.
pub const MEASURES: [&str; 5] = ["tip_x", "tip_y", "tip_z", "norm", "tip_angle"];

fn positive(field: &str, v: f64) -> Result<f64, ProblemError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!("must be a positive finite number, got {v}"),
        ))
    }
}

impl ContinuationSection {
    /// `stop_at` as the run's stops: each measure one of `measures` (named
    /// as there), each value finite, no measure and value twice.
    fn checked_stops(&self, measures: &[Measure]) -> Result<Vec<StopAt>, ProblemError> {
        let mut stops: Vec<StopAt> = vec![];
        for (i, entry) in self.stop_at.iter().enumerate() {
            let field = format!("continuation.stop_at[{i}]");
            let named = Measure::parse(&entry.measure).map_err(|e| invalid(&field, e))?;
            let measure = measures.iter().position(|m| *m == named).ok_or_else(|| {
                invalid(
                    &field,
                    format!(
                        "stops on `{}`, which continuation.measures does not list: add it there \
                         (the stop reads the measure every point computes)",
                        entry.measure
                    ),
                )
            })?;
            if !entry.value.is_finite() {
                return Err(invalid(&field, "the value must be a finite number"));
            }
            let stop = StopAt {
                measure,
                value: entry.value,
            };
            if stops.contains(&stop) {
                return Err(invalid(&field, "repeats an earlier stop"));
            }
            stops.push(stop);
        }
        Ok(stops)
    }

    fn checked_shape_points(&self) -> Result<usize, ProblemError> {
        if (2..=MAX_SHAPE_POINTS).contains(&self.shape_points) {
            Ok(self.shape_points)
        } else {
            Err(invalid(
                "continuation.shape_points",
                format!(
                    "must be between 2 (the clamp and the tip) and {MAX_SHAPE_POINTS}, got {}",
                    self.shape_points
                ),
            ))
        }
    }

    /// The parameter's key and the options, validated (the key itself is
    /// checked where the problem text is at hand: a library parameter, or
    /// any numeric key of the rod's tables).
    pub fn build(&self) -> Result<(String, ContinuationOptions), ProblemError> {
        let parameter = self.parameter.trim().to_string();
        let (lo, hi) = bounds_with_start("continuation", self.bounds, self.start)?;
        let step = positive("continuation.step", self.step)?;
        let min_step = positive("continuation.min_step", self.min_step)?;
        let max_step = positive("continuation.max_step", self.max_step)?;
        if !(min_step <= step && step <= max_step) {
            return Err(invalid(
                "continuation.step",
                "need min_step ≤ step ≤ max_step",
            ));
        }
        let stability = MeshKeys {
            table: "continuation",
            elements: self.elements,
            order: self.order,
            eigenvalues: self.eigenvalues,
            min_elements: 2,
        }
        .build()?;
        if self.max_points < 1 {
            return Err(invalid("continuation.max_points", "must be at least 1"));
        }
        let tip_angle_limit = match self.tip_angle_limit {
            // The tip angle is measured in [0°, 180°] (the angle between
            // two unit vectors): a limit above 180° would never stop a branch.
            Some(a) if a.is_finite() && a > 0.0 && a <= 180.0 => Some(a.to_radians()),
            Some(a) => {
                return Err(invalid(
                    "continuation.tip_angle_limit",
                    format!(
                        "{a} is outside (0, 180] degrees: the angle between the tip and clamp \
                         tangents is at most 180°, so a larger limit never stops a branch; \
                         remove the key for no limit"
                    ),
                ))
            }
            None => None,
        };
        let measures = self
            .measures
            .iter()
            .map(|m| Measure::parse(m).map_err(|e| invalid("continuation.measures", e)))
            .collect::<Result<Vec<_>, _>>()?;
        let mut names: Vec<String> = measures.iter().map(Measure::name).collect();
        names.sort();
        if names.windows(2).any(|w| w[0] == w[1]) {
            return Err(invalid("continuation.measures", "names a measure twice"));
        }
        let stops = self.checked_stops(&measures)?;
        if !MEASURES.contains(&self.measure.as_str())
            && !measures.iter().any(|m| m.name() == self.measure)
        {
            return Err(invalid(
                "continuation.measure",
                format!(
                    "unknown measure `{}`; expected one of {} or one of continuation.measures",
                    self.measure,
                    MEASURES.join(", ")
                ),
            ));
        }
        Ok((
            parameter,
            ContinuationOptions {
                start: self.start,
                bounds: (lo, hi),
                step,
                min_step,
                max_step,
                max_points: self.max_points,
                both_directions: self.both_directions,
                switch_depth: self.switch_depth,
                tip_angle_limit,
                stability,
                tolerance: within("continuation.tolerance", self.tolerance, NEWTON_TOLERANCE)?,
                event_tolerance: 1e-11,
                start_solver: None,
                measures,
                stops,
                shape_points: self.checked_shape_points()?,
            },
        ))
    }
}
