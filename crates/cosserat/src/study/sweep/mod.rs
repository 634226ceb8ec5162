//! Sweeps: a problem's analysis at every point of a grid over problem-file
//! keys (the `[sweep]` table, [`Sweep`]), in parallel, with
//! results that do not depend on the number of threads.
//!
//! A grid point is the base problem with the point's `--set` overrides.
//! Its job is the problem's analysis: for an `[arm]` problem the longest
//! arm (paper Sec. 3: R*, γ_crit, the shape coefficients c, the curvature
//! fit b of (59), optionally R0 of the straight arm), for any other
//! problem the equilibrium ([`crate::bvp::solve`]).
//!
//! Determinism: the grid is cut into *lines* along its last axis. With
//! warm starts, a point starts from its predecessor on the line (the
//! neighbour's optimum, so that a family of local optima is followed
//! across the grid, paper Sec. 4.2) and the first point of a line is
//! searched cold; lines are independent, so any number of threads, shards
//! or resumptions computes the same numbers. Results are [`Record`]s:
//! named columns, written in grid order.

mod arm_job;
pub mod contour;
mod grid;
mod schedule;
mod solve_job;

pub use arm_job::{distinct_optima, shape_distance, ArmJob};
pub use grid::{grid_index, Sweep, SweepAxis, MAX_POINTS};
pub use schedule::{run, PointProblem, Shard, SweepPlan};
pub use solve_job::SolveJob;

use std::collections::BTreeMap;

use crate::study::Problem;

/// One grid point's results: numeric columns (a fixed-width row each, NaN
/// where a value does not exist) and text labels (statuses).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Record {
    /// Flat grid index (row-major, the last axis fastest).
    pub index: usize,
    /// Numeric columns by name, e.g. `family_0/reach`.
    pub numbers: BTreeMap<String, Vec<f64>>,
    /// Labels by name, e.g. `family_0/status`.
    pub labels: BTreeMap<String, String>,
}

impl Record {
    /// A record for point `index` with no results yet.
    pub fn new(index: usize) -> Record {
        Record {
            index,
            ..Default::default()
        }
    }

    /// Sets a numeric column.
    pub fn set(&mut self, name: &str, values: Vec<f64>) {
        self.numbers.insert(name.to_string(), values);
    }

    /// Sets a label.
    pub fn label(&mut self, name: &str, value: &str) {
        self.labels.insert(name.to_string(), value.to_string());
    }

    /// The first value of a numeric column.
    pub fn number(&self, name: &str) -> Option<f64> {
        self.numbers.get(name).and_then(|v| v.first().copied())
    }
}

/// What a sweep computes at one grid point.
pub trait Job: Sync {
    /// "arm" or "solve": what the columns mean.
    fn kind(&self) -> &'static str;

    /// The results at point `index` of the problem `problem`; `previous`
    /// is the predecessor on the line (a warm start), if any. Once `stop()`
    /// turns true the job may return early with an incomplete record,
    /// which the scheduler then discards (the point is computed again on
    /// `--resume`).
    fn run(
        &self,
        index: usize,
        problem: &Problem,
        previous: Option<&Record>,
        stop: &dyn Fn() -> bool,
    ) -> Record;
}
