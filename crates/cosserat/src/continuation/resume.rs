//! Resuming an interrupted continuation from what its diagram file kept:
//! every saved point is rebuilt from its unknowns and tangent (tip,
//! spectrum, Morse index recomputed, the eigenvalue tracker replayed along
//! the branch in order), the interrupted branch goes on from its last point
//! in its own direction with its own next step, and branch points not yet
//! switched are switched — in the order of an uninterrupted run, so that
//! the resumed diagram is the uninterrupted one, bit for bit.

use super::{
    drain, Branch, ContinuationError, Diagram, Pending, Point, Run, SpecialKind, SpecialPoint,
};
use super::{BranchEnd, ContinuationOptions, Family, RunState};
use crate::stability::Block;

/// One saved branch.
#[derive(Debug, Clone, PartialEq)]
pub struct SavedBranch {
    /// Parameter values.
    pub parameter: Vec<f64>,
    /// Unknowns of each point.
    pub unknowns: Vec<Vec<f64>>,
    /// Tangents (x, p) of each point, oriented along the travel.
    pub tangent: Vec<Vec<f64>>,
    /// The special point it was switched from.
    pub parent: Option<usize>,
    /// Why it ended (in progress and interrupted branches are resumed).
    pub stop_reason: BranchEnd,
    /// The direction of travel along the stored tangents (±1).
    pub direction: f64,
    /// The arclength step the next point would be tried with.
    pub next_step: f64,
    /// The key the branch continues (absent in files written before
    /// branches recorded it: the problem's `continuation.parameter`).
    pub parameter_name: Option<String>,
    /// The keys of earlier stages held on the branch, and their values
    /// (none on a first stage).
    pub held: Vec<(String, f64)>,
}

/// One saved special point.
#[derive(Debug, Clone, PartialEq)]
pub struct SavedSpecial {
    /// Fold or branch point.
    pub kind: SpecialKind,
    /// Its branch.
    pub branch: usize,
    /// The point index before it.
    pub index: usize,
    /// The block whose eigenvalue vanishes.
    pub block: Block,
    /// Symmetry-breaking.
    pub symmetry_breaking: bool,
    /// Relative det F_x and eigenvalue there.
    pub singularity: (f64, f64),
    /// Eigenvalues crossing zero there ([`SpecialPoint::multiplicity`]).
    pub multiplicity: usize,
    /// How it was located ([`SpecialPoint::location`]).
    pub location: super::Location,
    /// Its parameter's estimated error ([`SpecialPoint::parameter_error`]).
    pub parameter_error: Option<f64>,
    /// Parameter.
    pub parameter: f64,
    /// Unknowns.
    pub unknowns: Vec<f64>,
    /// Tangent.
    pub tangent: Vec<f64>,
}

/// What a diagram file keeps of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct SavedDiagram {
    /// Branches.
    pub branches: Vec<SavedBranch>,
    /// Special points.
    pub specials: Vec<SavedSpecial>,
    /// Why the run ended.
    pub stop_reason: RunState,
    /// Events detected but not located.
    pub warnings: Vec<String>,
}

impl SavedDiagram {
    /// Checks that the saved run is one a run of `family` could have made:
    /// sizes, references between branches and special points, directions.
    pub fn check(&self, family: &Family) -> Result<(), String> {
        let n = family.size();
        let row = |v: &[f64], width: usize, what: &str| {
            if v.len() == width && v.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(format!(
                    "{what}: expected {width} finite numbers, found {}",
                    v.len()
                ))
            }
        };
        for (i, b) in self.branches.iter().enumerate() {
            let m = b.parameter.len();
            if b.unknowns.len() != m || b.tangent.len() != m {
                return Err(format!("branch {i}: datasets of different lengths"));
            }
            for (x, t) in b.unknowns.iter().zip(&b.tangent) {
                row(x, n, &format!("branch {i} unknowns"))?;
                row(t, n + 1, &format!("branch {i} tangent"))?;
            }
            row(&b.parameter, m, &format!("branch {i} parameter"))?;
            if !(b.direction == 1.0 || b.direction == -1.0)
                || !(b.next_step.is_finite() && b.next_step > 0.0)
            {
                return Err(format!(
                    "branch {i}: no direction (±1) or next step (> 0): \
                     a file of an older cosserat, which cannot be resumed"
                ));
            }
            if b.parent.is_some_and(|p| p >= self.specials.len()) {
                return Err(format!(
                    "branch {i}: its parent special point does not exist"
                ));
            }
        }
        for (i, sp) in self.specials.iter().enumerate() {
            let points = self.branches.get(sp.branch).map(|b| b.parameter.len());
            if points.is_none_or(|m| sp.index >= m) {
                return Err(format!(
                    "special point {i}: its branch point does not exist"
                ));
            }
            row(&sp.unknowns, n, &format!("special point {i} unknowns"))?;
            row(&sp.tangent, n + 1, &format!("special point {i} tangent"))?;
        }
        Ok(())
    }
}

/// Continues a saved run to its end.
pub fn resume(
    family: &Family,
    opts: &ContinuationOptions,
    saved: &SavedDiagram,
    monitor: &mut dyn FnMut(super::Progress, &Diagram) -> bool,
) -> Result<Diagram, ContinuationError> {
    saved
        .check(family)
        .map_err(|message| ContinuationError::Start {
            p: opts.start,
            message: format!("the saved diagram cannot be resumed: {message}"),
        })?;
    let mut run = Run::new(family, opts);
    let mut diagram = Diagram {
        branches: vec![],
        special_points: vec![],
        eigenvalue_names: run.tracker.names(),
        measure_names: run.opts.measures.iter().map(super::Measure::name).collect(),
        nodes: run.tracker.nodes(),
        stop_reason: RunState::InProgress,
        warnings: saved.warnings.clone(),
    };
    for s in &saved.specials {
        diagram.special_points.push(rebuild_special(&run, s)?);
    }
    // Each branch replayed in order: the tracker ends holding the modes of
    // the last point, as in the run that was interrupted.
    for b in &saved.branches {
        run.tracker.reset();
        let mut points = Vec::with_capacity(b.parameter.len());
        for ((p, x), t) in b.parameter.iter().zip(&b.unknowns).zip(&b.tangent) {
            points.push(run.point(x.clone(), *p, t.clone())?);
        }
        run.total_points += points.len().saturating_sub(1);
        diagram.branches.push(Branch {
            points,
            parent: b.parent,
            stop_reason: b.stop_reason.clone(),
            direction: b.direction,
            next_step: b.next_step,
        });
    }
    for (i, b) in saved.branches.iter().enumerate() {
        if let Some(sp) = b.parent {
            diagram.special_points[sp].children.push(i);
        }
    }
    // The interrupted branch goes on from its last point.
    if let Some(last) = diagram.branches.len().checked_sub(1) {
        if diagram.branches[last].stop_reason.resumable()
            && !diagram.branches[last].points.is_empty()
        {
            let sign = diagram.branches[last].direction;
            let outcome = run.walk(sign, last, &mut diagram, monitor);
            diagram.branches[last].stop_reason = outcome.stop_reason.clone();
            if outcome.interrupted {
                diagram.stop_reason = RunState::Interrupted;
                return Ok(diagram);
            }
        }
    }
    // Branch points not switched yet, and the backward half of the start.
    let mut queue: Vec<Pending> = vec![];
    let roots = diagram
        .branches
        .iter()
        .filter(|b| b.parent.is_none())
        .count();
    if opts.both_directions && roots == 1 {
        if let Some(first) = diagram.branches.first().and_then(|b| b.points.first()) {
            queue.push((first.clone(), -1.0, None, 0));
        }
    }
    // Switches that did not run yet: each special point's new branches,
    // less those whose first point a saved child already starts from.
    for sp in 0..diagram.special_points.len() {
        let d = depth(&diagram, diagram.special_points[sp].branch);
        for start in run.switches(&diagram, &[sp], d) {
            let covered = diagram.special_points[sp].children.iter().any(|&c| {
                diagram.branches[c]
                    .points
                    .first()
                    .is_some_and(|p| same_point(p, &start.0))
            });
            if !covered {
                queue.push(start);
            }
        }
    }
    run.report_unswitched(&mut diagram);
    drain(&mut run, &mut diagram, queue, monitor);
    Ok(diagram)
}

/// Two points within 1e-8 of each other in (x, p).
fn same_point(a: &Point, b: &Point) -> bool {
    let dx: f64 = a
        .unknowns
        .iter()
        .zip(&b.unknowns)
        .map(|(x, y)| (x - y).powi(2))
        .sum();
    (dx + (a.parameter - b.parameter).powi(2)).sqrt() <= 1e-8
}

/// How many switches led to `branch`.
fn depth(diagram: &Diagram, mut branch: usize) -> usize {
    let mut d = 0;
    while let Some(sp) = diagram.branches[branch].parent {
        branch = diagram.special_points[sp].branch;
        d += 1;
    }
    d
}

/// A saved special point measured as when it was located: with a fresh
/// tracker, leaving the run's tracker alone.
pub(super) fn rebuild_special(
    run: &Run,
    s: &SavedSpecial,
) -> Result<SpecialPoint, ContinuationError> {
    let mut tracker = run.tracker.clone();
    tracker.reset();
    let spectrum = tracker.measure(run.family, &s.unknowns, s.parameter)?;
    let point = run.point_from(s.unknowns.clone(), s.parameter, s.tangent.clone(), spectrum)?;
    let (_, null_mode) = run
        .tracker
        .nearest_zero(run.family, &s.unknowns, s.parameter, s.block)?;
    Ok(SpecialPoint {
        kind: s.kind,
        branch: s.branch,
        index: s.index,
        point,
        block: s.block,
        null_mode,
        symmetry_breaking: s.symmetry_breaking,
        children: vec![],
        singularity: s.singularity,
        multiplicity: s.multiplicity,
        location: s.location,
        parameter_error: s.parameter_error,
    })
}
