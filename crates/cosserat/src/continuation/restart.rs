//! Continuation from a given equilibrium instead of the problem's own
//! solve: a point of a stored diagram (`cosserat continue --from FILE
//! --point B/I`), or any unknowns a program has. The given unknowns start
//! Newton at the start value of the parameter, so the first point is an
//! equilibrium of the problem as posed (to the corrector's tolerance) and
//! the guess only chooses which one; with the stored direction of travel,
//! a branch restarted from one of its own points goes on as the
//! uninterrupted run did. A stored branch point restarts the switch onto
//! the branches that leave it ([`switch_from`]).

use super::driver::{check_start, follow_from};
use super::resume::rebuild_special;
use super::{
    drain, Branch, ContinuationError, ContinuationOptions, Diagram, Family, Point, Progress, Run,
    RunState, SavedDiagram, SpecialKind,
};

/// Where a continuation starts: the family's (scaled) unknowns at
/// `ContinuationOptions::start`, and the direction of travel to keep.
#[derive(Debug, Clone, PartialEq)]
pub struct StartPoint {
    unknowns: Vec<f64>,
    direction: Option<Vec<f64>>,
}

impl StartPoint {
    /// The start from `unknowns` (the family's scaled unknowns, as a
    /// diagram stores them), travelling along `direction` (a tangent
    /// (x, p) of the same size plus one) if given, else towards
    /// increasing p.
    pub fn new(unknowns: Vec<f64>, direction: Option<Vec<f64>>) -> Self {
        StartPoint {
            unknowns,
            direction,
        }
    }

    /// The unknowns.
    pub fn unknowns(&self) -> &[f64] {
        &self.unknowns
    }

    /// The direction of travel, if given.
    pub fn direction(&self) -> Option<&[f64]> {
        self.direction.as_deref()
    }
}

/// [`super::continuation`] from `start` instead of the problem's own
/// solve. Refused ([`ContinuationError::Start`]) when the unknowns are not
/// of this family's discretization or Newton at the start value does not
/// converge from them.
pub fn continuation_from(
    family: &Family,
    opts: &ContinuationOptions,
    start: &StartPoint,
    monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
) -> Result<Diagram, ContinuationError> {
    check_start(family, opts)?;
    let mut run = Run::new(family, opts);
    let first = run.start_point_from(start)?;
    Ok(follow_from(&mut run, first, monitor))
}

impl Run<'_> {
    /// The equilibrium at the start value reached by Newton from the given
    /// unknowns, its tangent oriented along the given direction.
    fn start_point_from(&mut self, start: &StartPoint) -> Result<Point, ContinuationError> {
        let p = self.opts.start;
        let n = self.family.size();
        let start_err = |message: String| ContinuationError::Start { p, message };
        if start.unknowns.len() != n {
            return Err(start_err(format!(
                "the given point has {} unknowns, this discretization {n} (another model level, \
                 method or mesh)",
                start.unknowns.len()
            )));
        }
        let x = self
            .newton_at_fixed_p(start.unknowns.clone(), p)
            .map_err(|e| start_err(format!("from the given point: {e}")))?;
        let forward = match &start.direction {
            Some(d) if d.len() == n + 1 => d.clone(),
            _ => {
                let mut f = vec![0.0; n];
                f.push(1.0);
                f
            }
        };
        let tangent = self.start_tangent(&x, p, &forward)?;
        self.tracker.reset();
        self.point(x, p, tangent)
    }
}

/// The branches that leave branch point `special` of a stored diagram,
/// followed as a new diagram: its branch 0 is the stored branch the point
/// lies on (replayed from its unknowns), its special point 0 the stored
/// one (re-measured), and the switched branches are that point's children
/// — so the new diagram stands alone. Refused for a fold (nothing to
/// switch onto) or a diagram another family made.
pub fn switch_from(
    family: &Family,
    opts: &ContinuationOptions,
    saved: &SavedDiagram,
    special: usize,
    monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
) -> Result<Diagram, ContinuationError> {
    let refuse = |message: String| ContinuationError::Start {
        p: opts.start,
        message,
    };
    saved
        .check(family)
        .map_err(|m| refuse(format!("the stored diagram does not fit this problem: {m}")))?;
    let stored = saved.specials.get(special).ok_or_else(|| {
        refuse(format!(
            "the diagram has {} special points, no {special}",
            saved.specials.len()
        ))
    })?;
    if stored.kind != SpecialKind::BranchPoint {
        return Err(refuse(format!(
            "special point {special} is a {}: only a branch point has branches to switch onto",
            stored.kind.name()
        )));
    }
    let mut run = Run::new(family, opts);
    let parent = &saved.branches[stored.branch];
    let mut points = Vec::with_capacity(parent.parameter.len());
    for ((p, x), t) in parent
        .parameter
        .iter()
        .zip(&parent.unknowns)
        .zip(&parent.tangent)
    {
        points.push(run.point(x.clone(), *p, t.clone())?);
    }
    let mut point = rebuild_special(&run, stored)?;
    point.branch = 0;
    let mut diagram = Diagram {
        branches: vec![Branch {
            points,
            parent: None,
            stop_reason: parent.stop_reason.clone(),
            direction: parent.direction,
            next_step: parent.next_step,
        }],
        special_points: vec![point],
        eigenvalue_names: run.tracker.names(),
        measure_names: opts.measures.iter().map(super::Measure::name).collect(),
        nodes: run.tracker.nodes(),
        stop_reason: RunState::InProgress,
        warnings: vec![],
    };
    let queue = run.switches(&diagram, &[0], 0);
    run.report_unswitched(&mut diagram);
    drain(&mut run, &mut diagram, queue, monitor);
    Ok(diagram)
}
