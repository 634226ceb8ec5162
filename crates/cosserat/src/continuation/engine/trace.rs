//! The branch loop of the engine: steps along a branch of any
//! [`ContinuationProblem`] with step-size control, ends it on a bound
//! (exactly on it), and locates the folds it passes.
//!
//! A fold is where the tangent's parameter component τ_p changes sign
//! between two points. It is located on the arclength h of the step from
//! the earlier point: τ_p(h) of the corrected point of a step of length h
//! has a simple root at the fold, found by the Illinois method. Since p(h)
//! is stationary there, an error δh in the root moves the located p by
//! O(δh²) only: the fold's parameter comes out to the corrector's
//! tolerance. (The rod's driver refines its folds on Govaerts' augmented
//! system instead, `continuation/fold.rs`, which needs second derivatives
//! this trait does not ask for.) An event of the problem's own
//! ([`ContinuationProblem::test_functions`]) is located the same way, on
//! the test function that changed sign instead of τ_p.

use super::corrector::{newton_at_fixed_p, step, tangent};
use super::{ContinuationProblem, StepFailure};
use crate::numerics::scalar::Illinois;

/// Arclength step control, shared by the engine and the rod's driver: a
/// corrector that fails halves Δs (down to the minimum), one that
/// converges in at most 3 iterations lengthens it by 1.5 (up to the
/// maximum).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    /// Smallest step before the branch is given up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
}

impl StepControl {
    /// The step after a corrector that did not converge, or None below the
    /// minimum.
    pub fn after_failure(&self, ds: f64) -> Option<f64> {
        let half = 0.5 * ds;
        (half >= self.min_step).then_some(half)
    }

    /// The step after a corrector that converged in `iterations`.
    pub fn after_success(&self, ds: f64, iterations: usize) -> f64 {
        if iterations <= 3 {
            (ds * 1.5).min(self.max_step)
        } else {
            ds
        }
    }
}

/// The settings of [`trace`].
#[derive(Debug, Clone, PartialEq)]
pub struct TraceOptions {
    /// First arclength step.
    pub step: f64,
    /// Step limits.
    pub control: StepControl,
    /// The branch ends where p leaves [lo, hi], landed on the bound.
    pub bounds: (f64, f64),
    /// Points at most.
    pub max_points: usize,
    /// Newton tolerance of the corrector (scaled residual).
    pub tolerance: f64,
    /// +1: start towards increasing p; −1: decreasing.
    pub direction: f64,
}

/// A point of a traced branch.
#[derive(Debug, Clone, PartialEq)]
pub struct TracePoint {
    /// The unknowns.
    pub u: Vec<f64>,
    /// The parameter.
    pub p: f64,
    /// The unit tangent (u̇, ṗ), oriented along the travel.
    pub tangent: Vec<f64>,
    /// The problem's Morse index there, where it has a monitor.
    pub morse_index: Option<usize>,
}

/// A located fold.
#[derive(Debug, Clone, PartialEq)]
pub struct TracedFold {
    /// The point at the fold (τ_p within the tolerance of zero).
    pub point: TracePoint,
    /// The index of the branch point before it.
    pub after: usize,
}

/// A located event of one of the problem's test functions.
#[derive(Debug, Clone, PartialEq)]
pub struct TracedEvent {
    /// Which test function vanished (its index).
    pub test: usize,
    /// The point where it vanishes (to the tolerance, or the bracket's
    /// round-off).
    pub point: TracePoint,
    /// The index of the branch point before it.
    pub after: usize,
}

/// Why a traced branch ended.
#[derive(Debug, Clone, PartialEq)]
pub enum TraceEnd {
    /// Landed exactly on this bound.
    ReachedBound(f64),
    /// [`TraceOptions::max_points`] points.
    MaxPoints,
    /// The step fell below the minimum.
    StepTooSmall(f64),
    /// A step failed for this reason.
    Failed(String),
}

/// A traced branch: its points, the folds between them, why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// The points in order.
    pub points: Vec<TracePoint>,
    /// The folds located between them.
    pub folds: Vec<TracedFold>,
    /// The test functions' events located between them (an event that
    /// could not be located is left out of `events` and named in
    /// `unlocated`: the index of its test function and of the point
    /// before it).
    pub events: Vec<TracedEvent>,
    /// Events detected by a sign change but not located.
    pub unlocated: Vec<(usize, usize)>,
    /// Why the branch ended.
    pub end: TraceEnd,
}

/// Follows the branch through (u0, p0): Newton at p0 from the guess u0,
/// then steps until a bound, the point limit or a failure; folds located
/// on the way. Err only when the start itself fails.
pub fn trace<P: ContinuationProblem>(
    problem: &P,
    u0: Vec<f64>,
    p0: f64,
    opts: &TraceOptions,
) -> Result<Trace, StepFailure<P::Error>>
where
    P::Error: std::fmt::Display,
{
    let u = newton_at_fixed_p(problem, u0, p0, opts.tolerance)?;
    let mut towards = vec![0.0; u.len() + 1];
    towards[u.len()] = opts.direction;
    let t = tangent(problem, &u, p0, &towards)?;
    let mut trace = Trace {
        points: vec![point(problem, u, p0, t)],
        folds: vec![],
        events: vec![],
        unlocated: vec![],
        end: TraceEnd::MaxPoints,
    };
    let mut ds = opts.step;
    while trace.points.len() < opts.max_points {
        let last = trace.points.last().expect("the start point").clone();
        let stepped = match step(problem, &last.u, last.p, &last.tangent, ds, opts.tolerance) {
            Ok(Some(s)) => s,
            Ok(None) => {
                let Some(shorter) = opts.control.after_failure(ds) else {
                    trace.end = TraceEnd::StepTooSmall(opts.control.min_step);
                    return Ok(trace);
                };
                ds = shorter;
                continue;
            }
            Err(e) => {
                trace.end = TraceEnd::Failed(e.to_string());
                return Ok(trace);
            }
        };
        let (u, p, t, iterations) = stepped;
        if let Some(bound) = crossed(opts.bounds, last.p, p) {
            trace.end = match land(problem, &last, (&u, p), bound, opts.tolerance) {
                Ok(landed) => {
                    trace.points.push(landed);
                    TraceEnd::ReachedBound(bound)
                }
                Err(e) => TraceEnd::Failed(e.to_string()),
            };
            return Ok(trace);
        }
        let n = u.len();
        let after = trace.points.len() - 1;
        if last.tangent[n] * t[n] < 0.0 {
            let fold = |_: &[f64], _: f64, t: &[f64]| t[n];
            let ends = (last.tangent[n], t[n]);
            if let Some(point) = locate(problem, &last, ds, ends, opts.tolerance, fold) {
                trace.folds.push(TracedFold { point, after });
            }
        }
        let before = problem.test_functions(&last.u, last.p);
        let now = problem.test_functions(&u, p);
        for (test, (&a, &b)) in before.iter().zip(&now).enumerate() {
            if a * b > 0.0 || a == 0.0 {
                continue;
            }
            let value = |u: &[f64], p: f64, _: &[f64]| {
                problem
                    .test_functions(u, p)
                    .get(test)
                    .copied()
                    .unwrap_or(f64::NAN)
            };
            match locate(problem, &last, ds, (a, b), opts.tolerance, value) {
                Some(point) => trace.events.push(TracedEvent { test, point, after }),
                None => trace.unlocated.push((test, after)),
            }
        }
        trace.points.push(point(problem, u, p, t));
        ds = opts.control.after_success(ds, iterations);
    }
    Ok(trace)
}

/// A point with the problem's Morse index.
fn point<P: ContinuationProblem>(
    problem: &P,
    u: Vec<f64>,
    p: f64,
    tangent: Vec<f64>,
) -> TracePoint {
    let morse_index = problem.morse_index(&u, p);
    TracePoint {
        u,
        p,
        tangent,
        morse_index,
    }
}

/// The bound between `from` and `to`, if the step crossed one.
fn crossed((lo, hi): (f64, f64), from: f64, to: f64) -> Option<f64> {
    if to > hi && from <= hi {
        Some(hi)
    } else if to < lo && from >= lo {
        Some(lo)
    } else {
        None
    }
}

/// The point on `bound` by Newton at the fixed bound from the linear
/// interpolant between `last` and the step's end (u, p).
fn land<P: ContinuationProblem>(
    problem: &P,
    last: &TracePoint,
    (u, p): (&[f64], f64),
    bound: f64,
    tolerance: f64,
) -> Result<TracePoint, StepFailure<P::Error>> {
    let s = (bound - last.p) / (p - last.p);
    let guess: Vec<f64> = last.u.iter().zip(u).map(|(a, b)| a + s * (b - a)).collect();
    let ub = newton_at_fixed_p(problem, guess, bound, tolerance)?;
    let tb = tangent(problem, &ub, bound, &last.tangent)?;
    Ok(point(problem, ub, bound, tb))
}

/// Trials of an event's location at most.
const TRIALS: usize = 60;

/// The zero of a test function g between `last` and its step of length
/// `ds` (g at the two ends in `ends`, of opposite signs): the point of the
/// step of length h with g(h) = 0, by the Illinois method on h ∈ (0, ds),
/// converged when |g| ≤ the tolerance or the bracket has shrunk to
/// round-off (the point of least |g| is kept). None when a trial step
/// fails or g is not finite there.
fn locate<P: ContinuationProblem>(
    problem: &P,
    last: &TracePoint,
    ds: f64,
    ends: (f64, f64),
    tolerance: f64,
    g: impl Fn(&[f64], f64, &[f64]) -> f64,
) -> Option<TracePoint> {
    let mut bracket = Illinois::new(0.0, ds, ends.0, ends.1)?;
    let mut best: Option<(f64, TracePoint)> = None;
    for _ in 0..TRIALS {
        let h = bracket.next_point();
        let (u, p, t, _) = step(problem, &last.u, last.p, &last.tangent, h, tolerance).ok()??;
        let value = g(&u, p, &t);
        if !value.is_finite() {
            return None;
        }
        if best.as_ref().is_none_or(|(b, _)| value.abs() < *b) {
            best = Some((value.abs(), point(problem, u, p, t)));
        }
        if value.abs() <= tolerance {
            break;
        }
        bracket.update(h, value);
        if bracket.width() <= 4.0 * f64::EPSILON * ds {
            break;
        }
    }
    best.map(|(_, point)| point)
}
