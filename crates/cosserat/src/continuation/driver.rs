//! The driver: follows branches point after point (predictor–corrector
//! steps with step-size control), stops them for a reason, hands every
//! point to the monitor, and switches onto new branches at branch points.
//!
//! The step-size control is the engine's ([`super::engine::StepControl`]),
//! not Newton's: a corrector that fails halves the arclength step Δs (down
//! to the minimum), one that converges in at most 3 iterations lengthens
//! it by 1.5 (up to the maximum). The steps themselves are the engine's
//! ([`super::engine::step`]) on the rod's [`Family`].

use super::engine::StepControl;
use super::{
    tip_angle, Branch, BranchEnd, ContinuationError, ContinuationOptions, Diagram, Family, Point,
    PointError, Progress, RunState, Spectrum, Tracker,
};
use crate::bvp::{solve, SolverOptions, Strategy};
use crate::model::{ModelChoice, ModelLevel};
use crate::stability::Block;

/// Continues the family F(x, p) = 0 from `opts.start`: the equilibrium
/// there (the BVP solver with its load ramp, then Newton at fixed p), then
/// predictor–corrector steps along the branch (one or both ways), folds
/// and branch points located between points, and new branches switched
/// onto at branch points down to `opts.switch_depth`. The monitor hears
/// every point and may interrupt; an interrupted diagram keeps its points
/// and can be resumed ([`super::resume`]).
pub fn continuation(
    family: &Family,
    opts: &ContinuationOptions,
    monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
) -> Result<Diagram, ContinuationError> {
    check_start(family, opts)?;
    let mut run = Run::new(family, opts);
    let first = run.start_point()?;
    Ok(follow_from(&mut run, first, monitor))
}

/// The rod at the start value exists and its loads have a potential
/// (stability decides nothing otherwise).
pub(super) fn check_start(
    family: &Family,
    opts: &ContinuationOptions,
) -> Result<(), ContinuationError> {
    if let Some(stop) = opts.stops.iter().find(|s| s.measure >= opts.measures.len()) {
        return Err(ContinuationError::Start {
            p: opts.start,
            message: format!(
                "a stop value names measure {} of {}: a stop's measure must be one of the \
                 run's measures",
                stop.measure,
                opts.measures.len()
            ),
        });
    }
    let start = family.rod_at(opts.start).map_err(PointError::from)?;
    crate::stability::check_conservative(&start).map_err(|e| ContinuationError::Start {
        p: opts.start,
        message: e.to_string(),
    })
}

/// The diagram of a run from its first point: the first branch (both ways
/// if asked) and the branches switched onto from it.
pub(super) fn follow_from(
    run: &mut Run,
    first: Point,
    monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
) -> Diagram {
    let mut diagram = Diagram {
        branches: vec![],
        special_points: vec![],
        eigenvalue_names: run.tracker.names(),
        measure_names: run.opts.measures.iter().map(super::Measure::name).collect(),
        nodes: run.tracker.nodes(),
        stop_reason: RunState::InProgress,
        warnings: vec![],
    };
    // (start point, direction sign, parent special point, depth)
    let mut queue = vec![(first, 1.0, None::<usize>, 0usize)];
    if run.opts.both_directions {
        let mut back = queue[0].clone();
        back.1 = -1.0;
        queue.push(back);
    }
    drain(run, &mut diagram, queue, monitor);
    diagram
}

/// A branch to follow: start point, direction, parent special point, depth.
pub(super) type Pending = (Point, f64, Option<usize>, usize);

/// Follows queued branches, switching at their branch points to the
/// configured depth, until the queue is empty ("completed") or the monitor
/// interrupts ("interrupted").
pub(super) fn drain(
    run: &mut Run,
    diagram: &mut Diagram,
    mut queue: Vec<Pending>,
    monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
) {
    diagram.stop_reason = RunState::InProgress;
    while !queue.is_empty() {
        let (start, sign, parent, depth) = queue.remove(0);
        let index = diagram.branches.len();
        diagram.branches.push(Branch {
            points: vec![],
            parent,
            stop_reason: BranchEnd::InProgress,
            direction: sign,
            next_step: run.opts.step,
        });
        if let Some(sp) = parent {
            diagram.special_points[sp].children.push(index);
        }
        let outcome = run.follow(&start, sign, index, diagram, monitor);
        diagram.branches[index].stop_reason = outcome.stop_reason.clone();
        if !outcome.interrupted {
            run.check_mesh(diagram, index);
        }
        if outcome.interrupted {
            diagram.stop_reason = RunState::Interrupted;
            return;
        }
        queue.extend(run.switches(diagram, &outcome.special_points, depth));
        run.report_unswitched(diagram);
    }
    diagram.stop_reason = RunState::Completed;
}

impl Run<'_> {
    /// New branches from the given special points, if `depth` allows.
    pub(super) fn switches(
        &mut self,
        diagram: &Diagram,
        specials: &[usize],
        depth: usize,
    ) -> Vec<Pending> {
        if depth >= self.opts.switch_depth {
            return vec![];
        }
        let mut out = vec![];
        for &sp in specials {
            let special = diagram.special_points[sp].clone();
            let neighbour = diagram.branches[special.branch].points[special.index].clone();
            for (point, dir) in self.switch(&special, &neighbour) {
                out.push((point, dir, Some(sp), depth + 1));
            }
        }
        out
    }

    /// Moves the switch failures into the diagram's warnings (once each).
    pub(super) fn report_unswitched(&mut self, diagram: &mut Diagram) {
        for w in self.unswitched.drain(..) {
            if !diagram.warnings.contains(&w) {
                diagram.warnings.push(w);
            }
        }
    }
}

/// What following one branch produced.
pub(super) struct Outcome {
    pub(super) special_points: Vec<usize>,
    pub(super) stop_reason: BranchEnd,
    pub(super) interrupted: bool,
}

/// The state of one continuation run.
pub(super) struct Run<'a> {
    pub(super) family: &'a Family,
    pub(super) opts: &'a ContinuationOptions,
    pub(super) tracker: Tracker,
    pub(super) total_points: usize,
    /// Branch points whose switch started fewer branches than asked, and
    /// why (moved to the diagram's warnings).
    pub(super) unswitched: Vec<String>,
    /// The branch being walked is a continuum of symmetric copies: its
    /// steps use the slice corrector (decided once, at its last point when
    /// the walk begins; `slice.rs`).
    pub(super) sliced: bool,
}

impl<'a> Run<'a> {
    pub(super) fn new(family: &'a Family, opts: &'a ContinuationOptions) -> Self {
        let blocks = match family.level() {
            ModelLevel::Planar => vec![Block::InPlane, Block::OutOfPlane],
            ModelLevel::Kirchhoff | ModelLevel::Cosserat => vec![Block::Full],
        };
        Run {
            family,
            opts,
            tracker: Tracker::new(family, blocks, opts.stability)
                .with_shape_points(opts.shape_points),
            total_points: 0,
            unswitched: vec![],
            sliced: false,
        }
    }

    /// The equilibrium at the start value (the BVP solver with its load
    /// ramp), with its tangent oriented towards increasing p.
    pub(super) fn start_point(&mut self) -> Result<Point, ContinuationError> {
        let p = self.opts.start;
        let start_err = |message: String| ContinuationError::Start { p, message };
        let rod = self
            .family
            .rod_at(p)
            .map_err(|e| start_err(e.to_string()))?;
        let model = ModelChoice::forced(&rod, self.family.level()).map_err(start_err)?;
        let solver = SolverOptions {
            method: self.family.method(),
            ..self.opts.start_solver.clone().unwrap_or(SolverOptions {
                strategy: Strategy::Auto,
                ..Default::default()
            })
        };
        let raw = solve(&rod, &model, &solver)
            .map_err(|e| start_err(e.to_string()))?
            .unknowns;
        let x = self
            .family
            .start_unknowns(&raw, p)
            .map_err(|e| start_err(e.to_string()))?;
        let x = self
            .newton_at_fixed_p(x, p)
            .map_err(|e| start_err(e.to_string()))?;
        let mut forward = vec![0.0; x.len()];
        forward.push(1.0);
        let tangent = self.start_tangent(&x, p, &forward)?;
        self.tracker.reset();
        self.point(x, p, tangent)
    }

    /// A complete point: tangent given, eigenvalues tracked.
    pub(super) fn point(
        &mut self,
        x: Vec<f64>,
        p: f64,
        tangent: Vec<f64>,
    ) -> Result<Point, ContinuationError> {
        let spectrum = self.tracker.measure(self.family, &x, p)?;
        self.point_from(x, p, tangent, spectrum)
    }

    /// A complete point from its measured spectrum.
    pub(super) fn point_from(
        &self,
        x: Vec<f64>,
        p: f64,
        tangent: Vec<f64>,
        spectrum: Spectrum,
    ) -> Result<Point, ContinuationError> {
        let tip = spectrum.tip.clone();
        let tip_angle = tip_angle(
            &self
                .family
                .rod_at(p)
                .map_err(PointError::from)?
                .clamp()
                .frame,
            &tip,
        );
        Ok(Point {
            parameter: p,
            tangent,
            tip_angle,
            tip,
            morse_index: spectrum.morse_index,
            block_morse: spectrum.block_morse,
            stable: spectrum.morse_index == 0,
            eigenvalues: spectrum.values,
            norm: spectrum.curvature_norm,
            shape: spectrum.shape,
            measures: self.measures(&x, p)?,
            unknowns: x,
        })
    }

    pub(super) fn stop_reason(&self, point: &Point, count: usize) -> Option<BranchEnd> {
        let (lo, hi) = self.opts.bounds;
        if point.parameter < lo || point.parameter > hi {
            return Some(BranchEnd::LeftBounds {
                parameter: point.parameter,
                bounds: (lo, hi),
            });
        }
        if count > 1 && (point.parameter == lo || point.parameter == hi) {
            return Some(BranchEnd::ReachedBound(point.parameter));
        }
        if count >= self.opts.max_points {
            return Some(BranchEnd::MaxPoints(count));
        }
        // The point's own tip angle, measured against its clamp when the
        // point was made.
        match self.opts.tip_angle_limit {
            Some(limit) if point.tip_angle >= limit - super::landing::ANGLE_TOLERANCE => {
                Some(BranchEnd::TipAngle(point.tip_angle.to_degrees()))
            }
            _ => None,
        }
    }

    /// Why the loads at `p` have no potential (checked at every point, not
    /// only at the start: a continued load may grow a dead couple), or
    /// None when they have one. A rod that cannot be built at `p` is left
    /// to the point's own evaluation, which names it.
    fn not_conservative(&self, p: f64) -> Option<BranchEnd> {
        let rod = self.family.rod_at(p).ok()?;
        crate::stability::check_conservative(&rod)
            .err()
            .map(|e| BranchEnd::NotConservative {
                parameter: p,
                reason: e.to_string(),
            })
    }

    /// A step that leaves [min, max] is pulled back onto the bound it
    /// crossed (Newton at fixed p from the linear interpolant), so that a
    /// branch ends exactly at its bound — e.g. at the design load.
    pub(super) fn land_on_bound(
        &self,
        last: &Point,
        x: Vec<f64>,
        p: f64,
        tangent: Vec<f64>,
    ) -> (Vec<f64>, f64, Vec<f64>) {
        let (lo, hi) = self.opts.bounds;
        let bound = if p > hi && last.parameter <= hi {
            hi
        } else if p < lo && last.parameter >= lo {
            lo
        } else {
            return (x, p, tangent);
        };
        let t = (bound - last.parameter) / (p - last.parameter);
        let guess: Vec<f64> = last
            .unknowns
            .iter()
            .zip(&x)
            .map(|(a, b)| a + t * (b - a))
            .collect();
        if self.sliced {
            return self
                .land_sliced(last, guess, bound, &tangent)
                .unwrap_or((x, p, tangent));
        }
        match self.newton_at_fixed_p(guess, bound) {
            Ok(xb) => match self.tangent(&xb, bound, &tangent) {
                Ok(tb) => (xb, bound, tb),
                Err(_) => (x, p, tangent),
            },
            Err(_) => (x, p, tangent),
        }
    }

    /// The point on the bound a step passed, where a fold it located lies
    /// beyond the bounds while both ends of the step lie inside: the
    /// branch left [min, max] and came back within one step (the pinned
    /// elastica under displacement control went from 0.99957 over the
    /// fold at the full length 1.0 back to 0.99912 with the bound 0.9999,
    /// and went on). Landed by Newton at the bound from the interpolant
    /// between `last` and the fold ([`Run::land_on_bound`]); None where no
    /// such fold was found, or the landing failed (the step's own
    /// points and events are then kept).
    fn beyond_bound_fold(
        &mut self,
        last: &Point,
        sign: f64,
        ds: f64,
        found: &[super::SpecialPoint],
    ) -> Option<Point> {
        let (lo, hi) = self.opts.bounds;
        let fold = found.iter().find(|sp| {
            sp.kind == super::SpecialKind::Fold
                && (sp.point.parameter > hi || sp.point.parameter < lo)
        })?;
        let beyond = &fold.point;
        let (x, p, tangent) = self.land_on_bound(
            last,
            beyond.unknowns.clone(),
            beyond.parameter,
            beyond.tangent.clone(),
        );
        if p != lo && p != hi {
            return None;
        }
        self.next_point(last, sign, ds, x, p, tangent).ok()
    }

    /// The engine's step control with the run's limits.
    fn control(&self) -> StepControl {
        StepControl {
            min_step: self.opts.min_step,
            max_step: self.opts.max_step,
        }
    }

    /// The shorter step after a step of length `ds` from `last` failed
    /// with `error`, or None when the failure ends the branch. Only a rod
    /// that cannot be built at a trial value (a stiffness or length that
    /// left the physical domain, a value the problem refuses) is cut back:
    /// to the step whose predictor reaches the bound the predictor crossed,
    /// so that [`Run::land_on_bound`] lands the branch exactly there, or
    /// else to half the step, down to the minimum step, below which the
    /// rod's own reason ends the branch. Any other failure is reported.
    fn cut_back(&self, last: &Point, sign: f64, ds: f64, error: &PointError) -> Option<f64> {
        if !matches!(error, PointError::Family(_)) {
            return None;
        }
        let n = last.unknowns.len();
        let rate = sign * last.tangent[n];
        let predicted = last.parameter + ds * rate;
        let (lo, hi) = self.opts.bounds;
        let bound = if predicted < lo && last.parameter > lo {
            Some(lo)
        } else if predicted > hi && last.parameter < hi {
            Some(hi)
        } else {
            None
        };
        // The predictor on the bound; a corrector that then ends a little
        // beyond it is pulled back by Newton at the bound.
        let to_bound = bound
            .map(|b| (b - last.parameter) / rate)
            .filter(|h| h.is_finite() && *h > 0.0 && *h < ds);
        let shorter = to_bound.unwrap_or(0.5 * ds);
        (shorter >= self.opts.min_step).then_some(shorter)
    }

    /// Follows one branch from `start` in direction `sign`, appending its
    /// points to `diagram.branches[branch]` as they come (so a monitor that
    /// saves the diagram keeps every point).
    pub(super) fn follow(
        &mut self,
        start: &Point,
        sign: f64,
        branch: usize,
        diagram: &mut Diagram,
        monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
    ) -> Outcome {
        self.tracker.reset();
        match self.point(
            start.unknowns.clone(),
            start.parameter,
            start.tangent.clone(),
        ) {
            Ok(p) => diagram.branches[branch].points.push(p),
            Err(e) => {
                return Outcome {
                    special_points: vec![],
                    stop_reason: BranchEnd::StartFailed(e.to_string()),
                    interrupted: false,
                }
            }
        }
        diagram.branches[branch].next_step = self.opts.step;
        self.walk(sign, branch, diagram, monitor)
    }

    /// Steps on from the last point of `diagram.branches[branch]` (the
    /// tracker holding that point's modes) with the branch's next step,
    /// until a stop reason or an interrupt.
    pub(super) fn walk(
        &mut self,
        sign: f64,
        branch: usize,
        diagram: &mut Diagram,
        monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
    ) -> Outcome {
        let mut specials = vec![];
        let end = |specials: Vec<usize>, reason: BranchEnd, interrupted: bool| Outcome {
            special_points: specials,
            stop_reason: reason,
            interrupted,
        };
        if let Some(last) = diagram.branches[branch].points.last() {
            self.sliced = self
                .symmetric_kernel(&last.unknowns, last.parameter)
                .is_some();
        }
        let mut ds = diagram.branches[branch].next_step;
        loop {
            let points = &diagram.branches[branch].points;
            let last = points.last().expect("a branch has its start point").clone();
            if let Some(reason) = self.stop_reason(&last, points.len()) {
                return end(specials, reason, false);
            }
            // A switched branch whose first point was landed on a bound
            // (`switched_within_bounds`) and heads out of the bounds ends
            // there, one point long.
            let n = last.unknowns.len();
            let outward = sign * last.tangent[n];
            let (lo, hi) = self.opts.bounds;
            if points.len() == 1
                && diagram.branches[branch].parent.is_some()
                && ((last.parameter == hi && outward > 0.0)
                    || (last.parameter == lo && outward < 0.0))
            {
                return end(specials, BranchEnd::ReachedBound(last.parameter), false);
            }
            // Newton from the parabola through the last two points only
            // where the step control is saturated (the next step is the
            // maximum whatever the corrector's iterations): elsewhere fewer
            // iterations would lengthen the steps and move the points.
            let before = points
                .len()
                .checked_sub(2)
                .map(|i| &points[i])
                .filter(|_| ds >= self.opts.max_step);
            let stepped = self.step_after(before, &last, sign, ds);
            let (x, p, tangent, iterations) = match stepped {
                Ok(Some(stepped)) => stepped,
                Ok(None) => {
                    let Some(shorter) = self.control().after_failure(ds) else {
                        let reason = BranchEnd::StepTooSmall(self.opts.min_step);
                        return end(specials, reason, false);
                    };
                    ds = shorter;
                    continue;
                }
                Err(e) => match self.cut_back(&last, sign, ds, &e) {
                    Some(shorter) => {
                        ds = shorter;
                        continue;
                    }
                    None => return end(specials, BranchEnd::Failed(e.to_string()), false),
                },
            };
            let (x, p, tangent) = self.land_on_bound(&last, x, p, tangent);
            if let Some(reason) = self.not_conservative(p) {
                return end(specials, reason, false);
            }
            let next = match self.next_point(&last, sign, ds, x, p, tangent) {
                Ok(pt) => pt,
                Err(e) => return end(specials, BranchEnd::Failed(e.to_string()), false),
            };
            let index = diagram.branches[branch].points.len() - 1;
            let (found, missed) = self.events(&last, &next, sign, branch, index);
            if let Some(landed) = self.beyond_bound_fold(&last, sign, ds, &found) {
                // The step went out of the bounds and back in through a
                // fold beyond them: the branch ends on the bound it passed
                // (the events of the step lie beyond it, or are not known
                // to lie before it, and are dropped).
                let reason = BranchEnd::ReachedBound(landed.parameter);
                diagram.branches[branch].points.push(landed);
                self.total_points += 1;
                return end(specials, reason, false);
            }
            for sp in found {
                specials.push(diagram.special_points.len());
                diagram.special_points.push(sp);
            }
            diagram.warnings.extend(missed);
            let stopped = self.passed_stop(&last, &next);
            diagram.branches[branch].points.push(next);
            self.total_points += 1;
            if let Some(reason) = stopped {
                return end(specials, reason, false);
            }
            if closes(&diagram.branches[branch].points)
                || passes_again(&diagram.special_points, &specials)
            {
                let points = diagram.branches[branch].points.len();
                return end(specials, BranchEnd::Closed(points), false);
            }
            ds = self.control().after_success(ds, iterations);
            diagram.branches[branch].next_step = ds;
            let progress = Progress {
                points: self.total_points,
                branch,
                parameter: p,
            };
            if !monitor(progress, diagram) {
                return end(specials, BranchEnd::Interrupted, true);
            }
        }
    }
}

/// Whether the last step of a branch passed its first point again in the
/// same direction: the chord from the last point but one to the last
/// passes the first point within a tenth of its length, between its ends,
/// and the tangents there and at the first point agree (cosine ≥ 0.99), so
/// that a branch crossing its start at an angle is not taken for a loop.
/// A closed branch (the full shallow arch's asymmetric branch joining its
/// two branch points) would otherwise be followed round and round until
/// `max_points`. In the scaled unknowns and the parameter, as the
/// arclength.
fn closes(points: &[Point]) -> bool {
    let n = points.len();
    if n < 4 {
        return false;
    }
    let z = |p: &Point| -> Vec<f64> { p.unknowns.iter().copied().chain([p.parameter]).collect() };
    let (first, last, next) = (z(&points[0]), z(&points[n - 2]), z(&points[n - 1]));
    let chord: Vec<f64> = next.iter().zip(&last).map(|(a, b)| a - b).collect();
    let length = chord.iter().map(|c| c * c).sum::<f64>().sqrt();
    if length == 0.0 {
        return false;
    }
    let to_first: Vec<f64> = first.iter().zip(&last).map(|(a, b)| a - b).collect();
    let along = to_first.iter().zip(&chord).map(|(a, c)| a * c).sum::<f64>() / length;
    if !(0.0..=length).contains(&along) {
        return false;
    }
    let across = to_first
        .iter()
        .zip(&chord)
        .map(|(a, c)| (a - along * c / length).powi(2))
        .sum::<f64>()
        .sqrt();
    let cosine: f64 = points[0]
        .tangent
        .iter()
        .zip(&points[n - 1].tangent)
        .map(|(a, b)| a * b)
        .sum();
    across <= 0.1 * length && cosine >= 0.99
}

/// Whether the branch's last special point repeats an earlier one of the
/// same branch (`found`, indices into `all`): the same kind and block at
/// the same point (p to 1e-9, x to 1e-6, relative), met on another step
/// (an isotropic column's in-plane and out-of-plane crossings are one
/// point met once), passed the same way (the
/// branch's directions before them agree, cosine ≥ 0.9) — the branch is a
/// loop that has come round once. Special points are located on their own
/// systems, so this holds where the chord test of [`closes`] misses the
/// start for the curvature near it (a branch leaving a pitchfork).
fn passes_again(all: &[super::SpecialPoint], found: &[usize]) -> bool {
    let Some((&last, earlier)) = found.split_last() else {
        return false;
    };
    let s = &all[last];
    earlier.iter().map(|&i| &all[i]).any(|e| {
        let (x, y) = (&e.point, &s.point);
        let dx = x
            .unknowns
            .iter()
            .zip(&y.unknowns)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let size = 1.0 + x.unknowns.iter().map(|a| a * a).sum::<f64>().sqrt();
        let cosine: f64 = x.tangent.iter().zip(&y.tangent).map(|(a, b)| a * b).sum();
        e.kind == s.kind
            && e.block == s.block
            && e.index != s.index
            && (x.parameter - y.parameter).abs() <= 1e-9 * (1.0 + x.parameter.abs())
            && dx <= 1e-6 * size
            && cosine >= 0.9
    })
}
