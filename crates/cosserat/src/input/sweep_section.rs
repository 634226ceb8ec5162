//! The `[sweep]` table: a grid over any keys that `--set` accepts, for
//! `cosserat sweep`.
//!
//! ```toml
//! [sweep]
//! axes = [
//!   { key = "energy.stiffness[0]", linspace = [0.25, 7.0, 28] },
//!   { key = "energy.stiffness[2]", logspace = [0.1, 10.0, 5] },
//!   { key = "arm.alpha", values = [0, 30, 60] },
//! ]
//! ```
//!
//! `linspace = [a, b, n]`: n equally spaced values from a to b (both
//! included); `logspace = [a, b, n]`: n geometrically spaced values from a
//! to b (the endpoints are values, not exponents); `values`: the list.
//! The grid is the Cartesian product, row-major (the last axis fastest).

use serde::{Deserialize, Serialize};

use super::problem::{invalid, ProblemError};
use crate::study::sweep::{Sweep, SweepAxis, MAX_POINTS};

/// `[sweep]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepSection {
    /// The axes of the grid.
    pub axes: Vec<AxisSpec>,
    /// Families of local optima an arm sweep follows (1 or 2); see
    /// `cosserat::study::sweep`.
    #[serde(default = "default_families")]
    pub families: usize,
    /// Start each point of an arm sweep from its predecessor along the last
    /// axis (a warm start); the first point of each line is searched cold.
    #[serde(default = "default_true")]
    pub warm_start: bool,
    /// Halton samples of the global stage at a warm-started point.
    #[serde(default = "default_warm_samples")]
    pub warm_samples: usize,
    /// Nelder–Mead iterations of a warm polish.
    #[serde(default = "default_warm_iterations")]
    pub warm_iterations: u64,
}

fn default_families() -> usize {
    1
}
fn default_true() -> bool {
    true
}
fn default_warm_samples() -> usize {
    0
}
fn default_warm_iterations() -> u64 {
    400
}

/// One axis as written.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    /// A key as `--set` takes it, e.g. `energy.stiffness[0]`.
    pub key: String,
    /// Explicit values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<f64>>,
    /// `[start, stop, count]`, equally spaced.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::strict::spacing"
    )]
    pub linspace: Option<(f64, f64, usize)>,
    /// `[start, stop, count]`, geometrically spaced (start, stop > 0).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::strict::spacing"
    )]
    pub logspace: Option<(f64, f64, usize)>,
}

impl SweepSection {
    /// Checks the table; every message names the field.
    pub fn build(&self) -> Result<Sweep, ProblemError> {
        if self.axes.is_empty() {
            return Err(invalid("sweep.axes", "needs at least one axis"));
        }
        let mut axes: Vec<SweepAxis> = vec![];
        for (i, spec) in self.axes.iter().enumerate() {
            let axis = spec.build(&format!("sweep.axes[{i}]"))?;
            if axes.iter().any(|a| a.key == axis.key) {
                return Err(invalid(
                    format!("sweep.axes[{i}].key"),
                    format!("`{}` is swept twice", axis.key),
                ));
            }
            axes.push(axis);
        }
        let points = axes
            .iter()
            .try_fold(1usize, |n, a| n.checked_mul(a.values.len()))
            .filter(|n| *n <= MAX_POINTS);
        if points.is_none() {
            return Err(invalid(
                "sweep.axes",
                format!("the grid has more than {MAX_POINTS} points"),
            ));
        }
        if !(1..=2).contains(&self.families) {
            return Err(invalid(
                "sweep.families",
                format!("must be 1 or 2, got {}", self.families),
            ));
        }
        if self.warm_iterations < 1 {
            return Err(invalid("sweep.warm_iterations", "must be at least 1"));
        }
        Ok(Sweep {
            axes,
            families: self.families,
            warm_start: self.warm_start,
            warm_samples: self.warm_samples,
            warm_iterations: self.warm_iterations,
        })
    }
}

impl AxisSpec {
    fn build(&self, field: &str) -> Result<SweepAxis, ProblemError> {
        let key = self.key.trim();
        if key.is_empty() || key.contains('=') || key.split('.').next() == Some("sweep") {
            return Err(invalid(
                format!("{field}.key"),
                format!("`{key}` is not a key of the problem outside [sweep]"),
            ));
        }
        let values = match (&self.values, self.linspace, self.logspace) {
            (Some(v), None, None) => v.clone(),
            (None, Some((a, b, n)), None) => spaced(&format!("{field}.linspace"), a, b, n)?,
            (None, None, Some((a, b, n))) => {
                let f = format!("{field}.logspace");
                if !(a > 0.0 && b > 0.0) {
                    return Err(invalid(f, format!("needs positive ends, got {a}, {b}")));
                }
                spaced(&f, a.ln(), b.ln(), n)?
                    .into_iter()
                    .map(f64::exp)
                    .collect()
            }
            _ => {
                return Err(invalid(
                    field,
                    "give exactly one of `values`, `linspace` or `logspace`",
                ))
            }
        };
        if values.is_empty() {
            return Err(invalid(
                format!("{field}.values"),
                "needs at least one value",
            ));
        }
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(invalid(
                format!("{field}.values"),
                format!("must be finite, got {v}"),
            ));
        }
        Ok(SweepAxis {
            key: key.to_string(),
            values,
        })
    }
}

/// n equally spaced values from a to b, both ends exact.
fn spaced(field: &str, a: f64, b: f64, n: usize) -> Result<Vec<f64>, ProblemError> {
    if !(a.is_finite() && b.is_finite()) || n < 1 || (n == 1 && a != b) {
        return Err(invalid(
            field,
            format!(
                "needs finite ends and a count ≥ 2 (or 1 with equal ends), got [{a}, {b}, {n}]"
            ),
        ));
    }
    if n > MAX_POINTS {
        // Checked before allocating: a count of 5e11 would abort the process.
        return Err(invalid(
            field,
            format!("{n} values exceed the grid limit of {MAX_POINTS} points"),
        ));
    }
    if n == 1 {
        return Ok(vec![a]);
    }
    let step = (b - a) / (n - 1) as f64;
    Ok((0..n)
        .map(|i| if i + 1 == n { b } else { a + step * i as f64 })
        .collect())
}
