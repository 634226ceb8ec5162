//! Which points a run computes and in what order: lines along the last
//! axis (warm starts run down a line), lines dealt to shards round-robin,
//! lines run in parallel on a rayon pool. A point's inputs are its problem
//! and its predecessor's record only, so the numbers do not depend on the
//! thread count, the shard count or on resumption.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;

use super::Sweep;
use super::{Job, Record};
use crate::study::Problem;

/// Shard `index` of `count` (0 ≤ index < count): the lines whose number
/// modulo `count` is `index`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, from 0.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole grid.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Reads `i/n`.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || format!("--shard {text}: expected i/n with 0 ≤ i < n, e.g. 0/4");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The problem at a flat grid point, or why there is none (the message is
/// kept as the point's `error` label). The caller builds it, typically by
/// reading the base problem text with the point's overrides
/// ([`Sweep::overrides`]); the sweep itself never reads problem files.
pub type PointProblem<'a> = dyn Fn(usize) -> Result<Problem, String> + Sync + 'a;

/// A sweep of a base problem.
#[derive(Clone)]
pub struct SweepPlan<'a> {
    /// The problem at each grid point.
    pub problem_at: &'a PointProblem<'a>,
    /// The grid.
    pub sweep: &'a Sweep,
    /// The part of the grid this run computes.
    pub shard: Shard,
}

impl SweepPlan<'_> {
    /// Points per line: the last axis's length with warm starts, else 1
    /// (every point on its own).
    fn line_length(&self) -> usize {
        if self.sweep.warm_start {
            self.sweep.axes.last().map_or(1, |a| a.values.len())
        } else {
            1
        }
    }

    /// This shard's lines, each in order.
    pub fn lines(&self) -> Vec<Vec<usize>> {
        let len = self.line_length();
        (0..self.sweep.points() / len)
            .filter(|l| l % self.shard.count == self.shard.index)
            .map(|l| (l * len..(l + 1) * len).collect())
            .collect()
    }

    /// The points this shard computes, in grid order.
    pub fn members(&self) -> Vec<usize> {
        self.lines().into_iter().flatten().collect()
    }

    /// The problem at grid point `i`.
    pub fn problem(&self, i: usize) -> Result<Problem, String> {
        (self.problem_at)(i)
    }
}

/// Runs `job` on the points of `plan` not in `done`, on `threads` threads
/// (0: all cores). After every point `on_point` sees all records so far
/// (in no particular order; it may save a checkpoint). Stops starting new
/// points once `stop` is set. Returns every record, in grid order.
pub fn run(
    plan: &SweepPlan,
    job: &dyn Job,
    threads: usize,
    done: Vec<Record>,
    stop: &AtomicBool,
    on_point: &(dyn Fn(&[Record]) + Sync),
) -> Result<Vec<Record>, rayon::ThreadPoolBuildError> {
    let finished: std::collections::BTreeSet<usize> = done.iter().map(|r| r.index).collect();
    let records = Mutex::new(done);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let lines = plan.lines();
    pool.install(|| {
        lines.par_iter().with_max_len(1).for_each(|line| {
            let mut previous: Option<Record> = None;
            for &i in line {
                if stop.load(Ordering::SeqCst) {
                    return;
                }
                if finished.contains(&i) {
                    let all = records.lock().expect("no worker panics");
                    previous = all.iter().find(|r| r.index == i).cloned();
                    continue;
                }
                let stopped = || stop.load(Ordering::SeqCst);
                let record = match plan.problem(i) {
                    Ok(problem) => job.run(i, &problem, previous.as_ref(), &stopped),
                    Err(e) => {
                        let mut r = Record::new(i);
                        r.label("error", &e);
                        r
                    }
                };
                // A point finished after the stop may be incomplete: it is
                // not kept, so that a resumed sweep computes it in full.
                if stopped() {
                    return;
                }
                let mut all = records.lock().expect("no worker panics");
                all.push(record.clone());
                on_point(&all);
                previous = Some(record);
            }
        });
    });
    let mut all = records.into_inner().expect("no worker panics");
    all.sort_by_key(|r| r.index);
    Ok(all)
}
