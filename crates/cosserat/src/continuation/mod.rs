//! Pseudo-arclength continuation of equilibria (Keller 1977) with tracking
//! of the Hessian eigenvalues, detection and location of folds and branch
//! points, and branch switching — a bifurcation diagram in one call.
//!
//! The discretization is shooting on the family F(x, p) = 0 of
//! [`Family`]; each point carries the lowest eigenvalues of the second
//! variation per block (tracked by eigenvector overlap, not by sorted
//! position), its Morse index and a stable flag. Events between two points:
//! a **fold** where the parameter component of the tangent changes sign; a
//! **branch point** where the Morse index of a block changes without a
//! fold. Folds are located where τ_p = 0; branch points where det F_x = 0
//! when the model can represent the bifurcating mode (exact to the
//! integration tolerance), else where the tracked eigenvalue vanishes
//! (accurate to the finite-element mesh). Branch switching follows the
//! null vector of [F_x F_p] orthogonal to the branch tangent, both ways.

mod family;
mod tracking;

pub use family::{tip_angle, Family, FamilyError, Parameter, PointError};
pub use tracking::{Spectrum, Tracker};

use nalgebra::{DMatrix, DVector, Vector3};

use crate::bvp::newton::Convergence;
use crate::bvp::{solve, SolverOptions, Strategy};
use crate::equations::RodSample;
use crate::model::{ModelChoice, ModelLevel};
use crate::stability::{Block, StabilityOptions};

/// Continuation settings (BifurcationKit's ContinuationPar, in spirit).
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationOptions {
    /// The parameter value to start from.
    pub start: f64,
    /// Stop when the parameter leaves [min, max].
    pub bounds: (f64, f64),
    /// Initial arclength step.
    pub step: f64,
    /// Smallest step before giving up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Points per branch at most.
    pub max_points: usize,
    /// Follow the start branch in both directions.
    pub both_directions: bool,
    /// Depth of recursive branch switching (0: none).
    pub switch_depth: usize,
    /// Stop a branch when the tip tangent turns more than this (rad) from
    /// the clamp tangent.
    pub tip_angle_limit: Option<f64>,
    /// Discretization of the second variation and eigenvalues per block.
    pub stability: StabilityOptions,
    /// Newton tolerance of the corrector (scaled residual).
    pub tolerance: f64,
    /// Relative tolerance on the parameter when locating events.
    pub event_tolerance: f64,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        ContinuationOptions {
            start: 0.0,
            bounds: (f64::NEG_INFINITY, f64::INFINITY),
            step: 0.05,
            min_step: 1e-7,
            max_step: 0.2,
            max_points: 400,
            both_directions: false,
            switch_depth: 1,
            tip_angle_limit: None,
            stability: StabilityOptions {
                elements: 40,
                order: 2,
                eigenvalues: 4,
            },
            tolerance: 1e-11,
            event_tolerance: 1e-11,
        }
    }
}

/// One equilibrium on a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The parameter value.
    pub parameter: f64,
    /// The discrete unknowns x.
    pub unknowns: Vec<f64>,
    /// The unit tangent (x, p) of the branch.
    pub tangent: Vec<f64>,
    /// The tip.
    pub tip: RodSample,
    /// The angle (rad) between the tip tangent and the clamp tangent.
    pub tip_angle: f64,
    /// Tracked eigenvalues, block after block.
    pub eigenvalues: Vec<f64>,
    /// Morse index.
    pub morse_index: usize,
    /// Stable (Morse index 0).
    pub stable: bool,
    /// The L² norm of the curvature, √∫|κ|².
    pub norm: f64,
    /// Positions along the rod (for pictures).
    pub shape: Vec<Vector3<f64>>,
}

/// Kinds of special points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpecialKind {
    /// The parameter turns back.
    Fold,
    /// Another branch crosses.
    BranchPoint,
}

impl SpecialKind {
    /// The name in output files.
    pub fn name(self) -> &'static str {
        match self {
            SpecialKind::Fold => "fold",
            SpecialKind::BranchPoint => "branch_point",
        }
    }
}

/// A located fold or branch point.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecialPoint {
    /// Fold or branch point.
    pub kind: SpecialKind,
    /// The branch it lies on.
    pub branch: usize,
    /// The index of the branch point just before it.
    pub index: usize,
    /// The located point.
    pub point: Point,
    /// The block whose eigenvalue vanishes.
    pub block: Block,
    /// The Hessian null mode as nodal rotations.
    pub null_mode: Vec<Vector3<f64>>,
    /// The bifurcating mode breaks a symmetry of the branch (out of the
    /// plane of a planar branch, or bending of a straight one).
    pub symmetry_breaking: bool,
    /// The new branches started here.
    pub children: Vec<usize>,
    /// The located singularity: |det F_x| relative to its scale on the
    /// neighbouring points, and the eigenvalue of the block there.
    pub singularity: (f64, f64),
}

/// A followed branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Its points in order.
    pub points: Vec<Point>,
    /// The special point it was switched from.
    pub parent: Option<usize>,
    /// Why it ended ([`BranchEnd::InProgress`] while it is followed).
    pub stop_reason: BranchEnd,
    /// The direction of travel: +1 along the stored tangents, −1 against
    /// them (the backward half of a `both_directions` start).
    pub direction: f64,
    /// The arclength step the next point would be tried with: with the
    /// points and the direction, all a resumed run needs to go on exactly
    /// as an uninterrupted one.
    pub next_step: f64,
}

/// A bifurcation diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagram {
    /// The branches.
    pub branches: Vec<Branch>,
    /// Folds and branch points.
    pub special_points: Vec<SpecialPoint>,
    /// Column names of the eigenvalues: `"in_plane[0]"`, ...
    pub eigenvalue_names: Vec<String>,
    /// Finite-element nodes of the null modes.
    pub nodes: Vec<f64>,
    /// Why the whole run ended: "in progress" while it runs (what a
    /// checkpoint records), then "completed" or "interrupted".
    pub stop_reason: RunState,
    /// What the run noticed but could not settle: events detected (a Morse
    /// index that changed) that could not be located.
    pub warnings: Vec<String>,
}

/// Why continuation could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContinuationError {
    /// No equilibrium at the start value.
    #[error("no equilibrium at the start value p = {p}: {message}")]
    Start {
        /// The start value of the parameter.
        p: f64,
        /// Why no equilibrium was found there.
        message: String,
    },
    /// A point could not be evaluated.
    #[error(transparent)]
    Point(#[from] PointError),
}

/// What a monitor hears after every point; returning false stops the run
/// (an interrupt), keeping what was computed.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    /// Points so far, all branches.
    pub points: usize,
    /// The branch being followed.
    pub branch: usize,
    /// The current parameter.
    pub parameter: f64,
}

/// Continues the family from `opts.start`.
pub fn continuation(
    family: &Family,
    opts: &ContinuationOptions,
    monitor: &mut dyn FnMut(Progress, &Diagram) -> bool,
) -> Result<Diagram, ContinuationError> {
    let start = family.rod_at(opts.start).map_err(PointError::from)?;
    crate::stability::check_conservative(&start).map_err(|e| ContinuationError::Start {
        p: opts.start,
        message: e.to_string(),
    })?;
    let mut run = Run::new(family, opts);
    let first = run.start_point()?;
    let mut diagram = Diagram {
        branches: vec![],
        special_points: vec![],
        eigenvalue_names: run.tracker.names(),
        nodes: run.tracker.nodes(),
        stop_reason: RunState::InProgress,
        warnings: vec![],
    };
    // (start point, direction sign, parent special point, depth)
    let mut queue = vec![(first, 1.0, None::<usize>, 0usize)];
    if opts.both_directions {
        let mut back = queue[0].clone();
        back.1 = -1.0;
        queue.push(back);
    }
    drain(&mut run, &mut diagram, queue, monitor);
    Ok(diagram)
}

/// A branch to follow: start point, direction, parent special point, depth.
type Pending = (Point, f64, Option<usize>, usize);

/// Follows queued branches, switching at their branch points to the
/// configured depth, until the queue is empty ("completed") or the monitor
/// interrupts ("interrupted").
fn drain(
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
        let outcome = run.follow(start, sign, index, diagram, monitor);
        diagram.branches[index].stop_reason = outcome.stop_reason.clone();
        if outcome.interrupted {
            diagram.stop_reason = RunState::Interrupted;
            return;
        }
        queue.extend(run.switches(diagram, &outcome.special_points, depth));
    }
    diagram.stop_reason = RunState::Completed;
}

impl Run<'_> {
    /// New branches from the given special points, if `depth` allows.
    fn switches(&mut self, diagram: &Diagram, specials: &[usize], depth: usize) -> Vec<Pending> {
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
}

/// Solves the bordered system by LU, or — where it is singular, exactly at
/// a branch point — by the truncated SVD (the minimum-norm correction).
fn bordered_solve(a: DMatrix<f64>, rhs: &DVector<f64>) -> Option<DVector<f64>> {
    let finite = |v: &DVector<f64>| v.iter().all(|x| x.is_finite());
    if let Some(x) = a.clone().lu().solve(rhs).filter(finite) {
        let scale = a.amax().max(f64::MIN_POSITIVE);
        if x.amax() * scale < 1e12 * rhs.amax().max(f64::MIN_POSITIVE) {
            return Some(x);
        }
    }
    let svd = a.svd(true, true);
    let tol = 1e-12 * svd.singular_values.max();
    svd.solve(rhs, tol).ok().filter(finite)
}

/// A converged corrector: (x, p), its iterations and F_x there.
type Corrected = (Vec<f64>, usize, DMatrix<f64>);

/// A corrected step: unknowns, parameter, tangent, corrector iterations.
type Stepped = (Vec<f64>, f64, Vec<f64>, usize);

/// What following one branch produced.
struct Outcome {
    special_points: Vec<usize>,
    stop_reason: BranchEnd,
    interrupted: bool,
}

/// The state of one continuation run.
struct Run<'a> {
    family: &'a Family,
    opts: &'a ContinuationOptions,
    tracker: Tracker,
    total_points: usize,
}

impl<'a> Run<'a> {
    fn new(family: &'a Family, opts: &'a ContinuationOptions) -> Self {
        let blocks = match family.level() {
            ModelLevel::Planar => vec![Block::InPlane, Block::OutOfPlane],
            ModelLevel::Kirchhoff | ModelLevel::Cosserat => vec![Block::Full],
        };
        Run {
            family,
            opts,
            tracker: Tracker::new(family, blocks, opts.stability),
            total_points: 0,
        }
    }

    /// The equilibrium at the start value (the BVP solver with its load
    /// ramp), with its tangent oriented towards increasing p.
    fn start_point(&mut self) -> Result<Point, ContinuationError> {
        let p = self.opts.start;
        let start_err = |message: String| ContinuationError::Start { p, message };
        let rod = self
            .family
            .rod_at(p)
            .map_err(|e| start_err(e.to_string()))?;
        let model = ModelChoice::forced(&rod, self.family.level()).map_err(start_err)?;
        let solver = SolverOptions {
            method: self.family.method(),
            strategy: Strategy::Auto,
            ..Default::default()
        };
        let raw = solve(&rod, &model, &solver)
            .map_err(|e| start_err(e.to_string()))?
            .unknowns;
        let x = self.family.scaled(&raw);
        let x = self
            .newton_at_fixed_p(x, p)
            .map_err(|e| start_err(e.to_string()))?;
        let mut forward = vec![0.0; x.len()];
        forward.push(1.0);
        let tangent = self.tangent(&x, p, &forward)?;
        self.tracker.reset();
        self.point(x, p, tangent)
    }

    /// Newton in x at fixed p (the start point of a branch).
    fn newton_at_fixed_p(&self, mut x: Vec<f64>, p: f64) -> Result<Vec<f64>, PointError> {
        let n = x.len();
        let (mut r, mut j) = (DVector::zeros(n), DMatrix::zeros(n, n));
        let test = Convergence::new(self.opts.tolerance, vec![1.0; n]);
        for _ in 0..30 {
            self.family.residual(&x, p, &mut r, &mut j)?;
            let Some(dx) = j.clone().lu().solve(&(-&r)) else {
                break;
            };
            if test.met(r.amax(), &x, dx.as_slice()) {
                return Ok(x);
            }
            x.iter_mut().zip(dx.iter()).for_each(|(a, b)| *a += b);
        }
        Err(PointError::NoConvergence(p))
    }

    /// The unit tangent at (x, p): the null vector of [F_x F_p], oriented
    /// along `previous`.
    fn tangent(&self, x: &[f64], p: f64, previous: &[f64]) -> Result<Vec<f64>, PointError> {
        let n = x.len();
        let (mut r, mut fx) = (DVector::zeros(n), DMatrix::zeros(n, n));
        self.family.residual(x, p, &mut r, &mut fx)?;
        self.tangent_from(&fx, x, p, previous)
    }

    /// The tangent with F_x already known at (x, p).
    fn tangent_from(
        &self,
        fx: &DMatrix<f64>,
        x: &[f64],
        p: f64,
        previous: &[f64],
    ) -> Result<Vec<f64>, PointError> {
        let n = x.len();
        let fp = self.family.parameter_derivative(x, p)?;
        let mut a = DMatrix::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n)).copy_from(fx);
        a.view_mut((0, n), (n, 1)).copy_from(&fp);
        for (k, v) in previous.iter().enumerate() {
            a[(n, k)] = *v;
        }
        let mut rhs = DVector::zeros(n + 1);
        rhs[n] = 1.0;
        let t = bordered_solve(a, &rhs)
            .filter(|t| t.iter().all(|v| v.is_finite()) && t.norm() > 0.0)
            .ok_or(PointError::SingularTangent(p))?;
        let t = t.normalize();
        Ok(t.as_slice().to_vec())
    }

    /// Newton on F(x, p) = 0, τᵀ(z − z_pred) = 0 from the predictor.
    fn correct(&self, pred: &[f64], tangent: &[f64]) -> Result<Option<Corrected>, PointError> {
        let n = pred.len() - 1;
        let mut z = pred.to_vec();
        let (mut r, mut fx) = (DVector::zeros(n), DMatrix::zeros(n, n));
        let fp = self.family.parameter_derivative(&z[..n], z[n])?;
        let test = Convergence::new(self.opts.tolerance, vec![1.0; n + 1]);
        for it in 0..10 {
            if self
                .family
                .residual(&z[..n], z[n], &mut r, &mut fx)
                .is_err()
            {
                return Ok(None);
            }
            let arc: f64 = tangent
                .iter()
                .zip(z.iter().zip(pred))
                .map(|(t, (a, b))| t * (a - b))
                .sum();
            let mut a = DMatrix::zeros(n + 1, n + 1);
            a.view_mut((0, 0), (n, n)).copy_from(&fx);
            a.view_mut((0, n), (n, 1)).copy_from(&fp);
            for (k, v) in tangent.iter().enumerate() {
                a[(n, k)] = *v;
            }
            let mut rhs = DVector::zeros(n + 1);
            rhs.rows_mut(0, n).copy_from(&(-&r));
            rhs[n] = -arc;
            let Some(dz) = bordered_solve(a, &rhs) else {
                return Ok(None);
            };
            if arc.abs() <= 1e-13 && test.met(r.amax(), &z, dz.as_slice()) {
                return Ok(Some((z, it, fx)));
            }
            z.iter_mut().zip(dz.iter()).for_each(|(a, b)| *a += b);
        }
        Ok(None)
    }

    /// A complete point: tangent given, eigenvalues tracked.
    fn point(
        &mut self,
        x: Vec<f64>,
        p: f64,
        tangent: Vec<f64>,
    ) -> Result<Point, ContinuationError> {
        let spectrum = self.tracker.measure(self.family, &x, p)?;
        self.point_from(x, p, tangent, spectrum)
    }

    /// A complete point from its measured spectrum.
    fn point_from(
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
            unknowns: x,
            tangent,
            tip_angle,
            tip,
            morse_index: spectrum.morse_index,
            stable: spectrum.morse_index == 0,
            eigenvalues: spectrum.values,
            norm: spectrum.curvature_norm,
            shape: spectrum.shape,
        })
    }

    /// Corrector from `from` along its tangent (times `sign`) by `ds`.
    fn step(&self, from: &Point, sign: f64, ds: f64) -> Result<Option<Stepped>, PointError> {
        let t: Vec<f64> = from.tangent.iter().map(|v| v * sign).collect();
        let mut z = from.unknowns.clone();
        z.push(from.parameter);
        let pred: Vec<f64> = z.iter().zip(&t).map(|(a, b)| a + ds * b).collect();
        let Some((z, iterations, fx)) = self.correct(&pred, &t)? else {
            return Ok(None);
        };
        let n = z.len() - 1;
        let tangent = self.tangent_from(&fx, &z[..n], z[n], &t)?;
        // Keep the stored tangent oriented along the travel direction.
        let stored: Vec<f64> = tangent.iter().map(|v| v * sign).collect();
        Ok(Some((z[..n].to_vec(), z[n], stored, iterations)))
    }

    fn stop_reason(&self, point: &Point, count: usize) -> Option<BranchEnd> {
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
            Some(limit) if point.tip_angle >= limit => {
                Some(BranchEnd::TipAngle(point.tip_angle.to_degrees()))
            }
            _ => None,
        }
    }

    /// A step that leaves [min, max] is pulled back onto the bound it
    /// crossed (Newton at fixed p from the linear interpolant), so that a
    /// branch ends exactly at its bound — e.g. at the design load.
    fn land_on_bound(
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
        match self.newton_at_fixed_p(guess, bound) {
            Ok(xb) => match self.tangent(&xb, bound, &tangent) {
                Ok(tb) => (xb, bound, tb),
                Err(_) => (x, p, tangent),
            },
            Err(_) => (x, p, tangent),
        }
    }

    /// Follows one branch from `start` in direction `sign`, appending its
    /// points to `diagram.branches[branch]` as they come (so a monitor that
    /// saves the diagram keeps every point).
    fn follow(
        &mut self,
        start: Point,
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
    fn walk(
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
        let mut ds = diagram.branches[branch].next_step;
        loop {
            let points = &diagram.branches[branch].points;
            let last = points.last().expect("a branch has its start point").clone();
            if let Some(reason) = self.stop_reason(&last, points.len()) {
                return end(specials, reason, false);
            }
            let (x, p, tangent, iterations) = match self.step(&last, sign, ds) {
                Ok(Some(stepped)) => stepped,
                Ok(None) => {
                    ds *= 0.5;
                    if ds < self.opts.min_step {
                        let reason = BranchEnd::StepTooSmall(self.opts.min_step);
                        return end(specials, reason, false);
                    }
                    continue;
                }
                Err(e) => return end(specials, BranchEnd::Failed(e.to_string()), false),
            };
            let (x, p, tangent) = self.land_on_bound(&last, x, p, tangent);
            let next = match self.point(x, p, tangent) {
                Ok(pt) => pt,
                Err(e) => return end(specials, BranchEnd::Failed(e.to_string()), false),
            };
            let index = diagram.branches[branch].points.len() - 1;
            let (found, missed) = self.events(&last, &next, sign, branch, index);
            for sp in found {
                specials.push(diagram.special_points.len());
                diagram.special_points.push(sp);
            }
            diagram.warnings.extend(missed);
            diagram.branches[branch].points.push(next);
            self.total_points += 1;
            if iterations <= 3 {
                ds = (ds * 1.5).min(self.opts.max_step);
            }
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

mod events;
mod resume;
mod status;

pub use status::{BranchEnd, RunState};

pub use resume::{resume, SavedBranch, SavedDiagram, SavedSpecial};
