//! The local stage of every arm search (prismatic, tapered, spatial):
//! Nelder–Mead (argmin) on −R̂ over a box of design variables.
//!
//! A point outside the box is projected into it and charged its squared
//! distance, so the simplex may step over a bound but is pulled back; a
//! design without a finite critical load costs as reach 0, the worst
//! possible, so the simplex moves away from it (the design returned is the
//! best point evaluated again by the caller, never this penalty). A stop
//! request gives the worst cost rather than an error: argmin's Nelder–Mead
//! unwraps the costs of its first simplex, and the caller discards a
//! polish that ran into a stop.

use std::cell::Cell;

use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::neldermead::NelderMead;
use nalgebra::{DMatrix, DVector};

/// The simplex at `start` with steps of `fraction` of each bound's width
/// (inwards where a step outwards would leave the box).
pub(super) fn box_simplex(start: &[f64], bounds: &[(f64, f64)], fraction: f64) -> Vec<Vec<f64>> {
    std::iter::once(start.to_vec())
        .chain((0..start.len()).map(|d| {
            let mut p = start.to_vec();
            let (lo, hi) = bounds[d];
            let step = fraction * (hi - lo);
            p[d] = if p[d] + step <= hi {
                p[d] + step
            } else {
                p[d] - step
            };
            p
        }))
        .collect()
}

/// Nelder–Mead from `simplex` for at most `iterations` on −reach in the
/// box that `project` projects onto: the best point (projected) and the
/// evaluations spent. `reach` is None where a design has no finite
/// critical load.
pub(super) fn polish_in_box(
    simplex: Vec<Vec<f64>>,
    iterations: u64,
    project: &dyn Fn(&[f64]) -> Vec<f64>,
    reach: &dyn Fn(&[f64]) -> Option<f64>,
    stop: &dyn Fn() -> bool,
) -> (Option<Vec<f64>>, usize) {
    let cost = BoxedReach {
        project,
        reach,
        stop,
        calls: Cell::new(0),
    };
    let Ok(solver) = NelderMead::new(simplex).with_sd_tolerance(1e-12) else {
        return (None, 0);
    };
    let result = Executor::new(&cost, solver)
        .configure(|state| state.max_iters(iterations))
        .run();
    let best = result
        .ok()
        .and_then(|r| r.state().get_best_param().map(|p| project(p)));
    (best, cost.calls.get())
}

/// −R̂ with the box's penalty (module doc).
struct BoxedReach<'a> {
    project: &'a dyn Fn(&[f64]) -> Vec<f64>,
    reach: &'a dyn Fn(&[f64]) -> Option<f64>,
    stop: &'a dyn Fn() -> bool,
    calls: Cell<usize>,
}

impl CostFunction for &BoxedReach<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Vec<f64>) -> Result<f64, ArgminError> {
        if (self.stop)() {
            return Ok(f64::INFINITY);
        }
        self.calls.set(self.calls.get() + 1);
        let q = (self.project)(p);
        let outside: f64 = p.iter().zip(&q).map(|(a, b)| (a - b).powi(2)).sum();
        Ok(-(self.reach)(&q).unwrap_or(0.0) + outside)
    }
}

/// The relative projected-gradient norm at which [`ascend_in_box`] stops:
/// max_i |x_i − P(x_i + ∂R̂/∂x_i)| ≤ this × R̂ (scale-free: the design
/// variables are angles). Near a smooth optimum with an O(1) Hessian the
/// reach is then within ~½ (1e-8 R̂)² of its maximum — far below the
/// discretization error, and the gradient itself is exact to ~1e-10.
pub(super) const ASCENT_TOLERANCE: f64 = 1e-8;

/// A value as the least of smooth branches (R̂ is the reach of the lower
/// of two blocks' critical loads): each branch's value and, where it has
/// one, its gradient. One branch without a gradient is a value alone (an
/// actuator limit).
pub(super) type Slope = Vec<(f64, Option<Vec<f64>>)>;

/// Branches within this relative distance of the least one enter the
/// ascent's max–min model ([`Local`]).
const NEAR_BRANCH: f64 = 1e-2;

/// How a projected ascent ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum AscentEnd {
    /// The projected gradient is below [`ASCENT_TOLERANCE`] × R̂.
    Converged,
    /// The line search found no increase along an ascent direction:
    /// the values are flat to round-off there (converged as far as the
    /// arithmetic tells).
    Flat,
    /// The accepted point has no gradient (a double critical load, an
    /// actuator limit): a derivative-free method must go on from it.
    NoGradient,
    /// The iteration cap was reached.
    Capped,
    /// `stop()` turned true.
    Stopped,
    /// The start has no value (no finite critical load).
    Infeasible,
}

/// The result of [`ascend_in_box`].
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Ascent {
    /// The best point reached (in the box) and its value.
    pub best: Option<(Vec<f64>, f64)>,
    /// Evaluations (value and gradient) used.
    pub evaluations: usize,
    /// Quasi-Newton iterations taken.
    pub iterations: usize,
    /// Why it ended.
    pub end: AscentEnd,
    /// The quasi-Newton model of −R̂'s Hessian where it ended (None where no
    /// step was taken from a point with a gradient): the warm start of a
    /// polish of the same design on another mesh.
    pub hessian: Option<DMatrix<f64>>,
}

/// Maximizes `slope`'s value — the least of its branches — over the box
/// `bounds` from `start` by projected BFGS: the quasi-Newton step on the
/// variables not held at a bound by the gradient, an Armijo backtracking
/// search along the projected path P(x + t d) (Bertsekas 1982, projected
/// Newton for bound constraints), the BFGS update where the curvature
/// condition sᵀy > 0 holds (else the update is skipped); stops on the
/// projected-gradient norm relative to the value ([`ASCENT_TOLERANCE`]).
/// Where a second branch is near the least (two blocks' critical loads
/// about to meet: R̂ has a kink there, and optima often sit on it), the
/// step is the max–min one (the SQP step of a minimax problem: the
/// quadratic model max_d min_i(f_i + g_iᵀd) − ½dᵀBd, solved through its
/// one multiplier μ), the update uses the gradient of the Lagrangian
/// μ g_a + (1 − μ) g_b, and the stationarity test is on that gradient with
/// the branches equal. Deterministic (sequential). Written here because
/// argmin's L-BFGS has no bounds and the box is part of the problem (the
/// paper's (60)); 7 variables make the dense update cheap. `warm` is a
/// Hessian model to start from (another mesh's, at a nearby point), else a
/// diagonal guess rescaled after the first step.
pub(super) fn ascend_in_box(
    start: &[f64],
    bounds: &[(f64, f64)],
    iterations: usize,
    slope: &dyn Fn(&[f64]) -> Option<Slope>,
    stop: &dyn Fn() -> bool,
    warm: Option<&DMatrix<f64>>,
) -> Ascent {
    let project = |p: &[f64]| -> Vec<f64> {
        p.iter()
            .zip(bounds)
            .map(|(v, (lo, hi))| v.clamp(*lo, *hi))
            .collect()
    };
    let mut ascent = Ascent {
        best: None,
        evaluations: 0,
        iterations: 0,
        end: AscentEnd::Infeasible,
        hessian: None,
    };
    let mut x = project(start);
    if stop() {
        ascent.end = AscentEnd::Stopped;
        return ascent;
    }
    ascent.evaluations += 1;
    let Some(mut here) = slope(&x) else {
        return ascent;
    };
    let Some(mut local) = Local::at(&here) else {
        ascent.best = Some((x.clone(), least(&here)));
        ascent.end = AscentEnd::NoGradient;
        return ascent;
    };
    ascent.best = Some((x.clone(), local.f));
    let widths: Vec<f64> = bounds.iter().map(|(lo, hi)| hi - lo).collect();
    // Whether `hessian` is the diagonal guess, to be rescaled by the first
    // measured curvature before its first update.
    let mut guessed = warm.is_none();
    let mut hessian = warm.map_or_else(|| initial_hessian(&widths, &local.g), Clone::clone);
    loop {
        let mut step = local.step(&x, &hessian, bounds, &widths);
        let f = local.f;
        let stationary = step.stationary(&x, bounds, f);
        if stationary || ascent.iterations >= iterations {
            ascent.end = if stationary {
                AscentEnd::Converged
            } else {
                AscentEnd::Capped
            };
            ascent.hessian = Some(hessian);
            return ascent;
        }
        if step.increase <= 0.0 {
            // The model gives no increase: start it again from the
            // diagonal guess, once; if that gives none either, the values
            // are flat to round-off here.
            hessian = initial_hessian(&widths, &local.g);
            guessed = true;
            step = local.step(&x, &hessian, bounds, &widths);
            if step.increase <= 0.0 {
                ascent.end = AscentEnd::Flat;
                ascent.hessian = Some(hessian);
                return ascent;
            }
        }
        ascent.iterations += 1;
        let path = ProjectedPath {
            x: &x,
            d: &step.d,
            local: &local,
            held: &step.held,
            bounds,
        };
        let (next, there) = match path.search(slope, stop, &mut ascent.evaluations) {
            Step::Accepted(point) => point,
            Step::Flat => {
                ascent.end = AscentEnd::Flat;
                ascent.hessian = Some(hessian);
                return ascent;
            }
            Step::Stopped => {
                ascent.end = AscentEnd::Stopped;
                return ascent;
            }
        };
        ascent.best = Some((next.clone(), least(&there)));
        let Some(next_local) = Local::at(&there) else {
            ascent.end = AscentEnd::NoGradient;
            return ascent;
        };
        // Minimizing −f: s = Δx, y = −Δ(gradient of the Lagrangian).
        if let (Some(before), Some(after)) = (step.lagrangian(&here), step.lagrangian(&there)) {
            let s: Vec<f64> = next.iter().zip(&x).map(|(a, b)| a - b).collect();
            let y: Vec<f64> = before.iter().zip(&after).map(|(a, b)| a - b).collect();
            if guessed {
                guessed = !rescale(&mut hessian, &widths, &s, &y);
            }
            bfgs_update(&mut hessian, &s, &y);
        }
        (x, here, local) = (next, there, next_local);
    }
}

/// The least value of a slope's branches.
fn least(slope: &Slope) -> f64 {
    slope.iter().map(|b| b.0).fold(f64::INFINITY, f64::min)
}

/// The ascent's model at a point: the least branch (value f, index, its
/// gradient g) and, where one is within [`NEAR_BRANCH`], the next-least
/// branch with its gradient.
struct Local {
    f: f64,
    index: usize,
    g: Vec<f64>,
    other: Option<(usize, f64, Vec<f64>)>,
}

impl Local {
    /// None where the least branch has no gradient.
    fn at(slope: &Slope) -> Option<Local> {
        let index = (0..slope.len()).min_by(|&a, &b| slope[a].0.total_cmp(&slope[b].0))?;
        let (f, g) = (slope[index].0, slope[index].1.clone()?);
        let other = (0..slope.len())
            .filter(|&i| i != index && slope[i].0 <= f + NEAR_BRANCH * f.abs())
            .min_by(|&a, &b| slope[a].0.total_cmp(&slope[b].0))
            .and_then(|i| Some((i, slope[i].0, slope[i].1.clone()?)));
        Some(Local { f, index, g, other })
    }

    /// The model's increase for a move Δx: min_i (f_i + g_iᵀΔx) − f.
    fn predicted(&self, dx: &[f64]) -> f64 {
        let dot = |g: &[f64]| g.iter().zip(dx).map(|(a, b)| a * b).sum::<f64>();
        let own = dot(&self.g);
        self.other
            .as_ref()
            .map_or(own, |(_, f2, g2)| own.min(f2 - self.f + dot(g2)))
    }

    /// The max–min quasi-Newton step at x (module doc of [`ascend_in_box`]):
    /// the multiplier μ of the least branch, the held variables of the
    /// combined gradient μ g_a + (1 − μ) g_b, the direction and the model's
    /// increase along it (≤ 0: the model `hessian` is to be reset; a model
    /// that is not positive definite gives a zero step).
    fn step(
        &self,
        x: &[f64],
        hessian: &DMatrix<f64>,
        bounds: &[(f64, f64)],
        widths: &[f64],
    ) -> MaxMinStep {
        let mut mu = 1.0;
        let mut held = vec![false; x.len()];
        let mut d = vec![0.0; x.len()];
        // Twice: the held set of the least branch's gradient gives μ, μ's
        // combined gradient gives the held set of the step.
        for _ in 0..2 {
            let combined = self.combined(mu);
            // The ε-active set of one branch; with two, the variables on
            // their bounds only (the max–min step does not move held ones,
            // so one ε inside would stay there).
            let pg = match self.other {
                Some(_) => 0.0,
                None => projected_gradient(x, &combined, bounds),
            };
            held = held_at_bounds(x, &combined, bounds, widths, pg);
            loop {
                let zero = || vec![0.0; x.len()];
                let da = ascent_direction(hessian, &self.g, &held).unwrap_or_else(zero);
                (mu, d) = match &self.other {
                    Some((_, f2, g2)) => {
                        // The max–min model moves the free variables only:
                        // a held variable's own move would follow the
                        // combined gradient, which may lower the least
                        // branch.
                        let only_free = |v: Vec<f64>| -> Vec<f64> {
                            v.iter()
                                .zip(&held)
                                .map(|(a, h)| if *h { 0.0 } else { *a })
                                .collect()
                        };
                        let da = only_free(da);
                        let db =
                            only_free(ascent_direction(hessian, g2, &held).unwrap_or_else(zero));
                        let free = |v: &[f64], w: &[f64]| -> f64 {
                            (0..v.len())
                                .filter(|&i| !held[i])
                                .map(|i| v[i] * w[i])
                                .sum()
                        };
                        let u: Vec<f64> = self.g.iter().zip(g2).map(|(a, b)| a - b).collect();
                        let w: Vec<f64> = da.iter().zip(&db).map(|(a, b)| a - b).collect();
                        let curvature = free(&u, &w);
                        let mu = if curvature > 0.0 {
                            (-((self.f - f2) + free(&u, &db)) / curvature).clamp(0.0, 1.0)
                        } else {
                            1.0
                        };
                        let d = da
                            .iter()
                            .zip(&db)
                            .map(|(a, b)| mu * a + (1.0 - mu) * b)
                            .collect();
                        (mu, d)
                    }
                    None => (1.0, da),
                };
                // A free variable on its bound that the step would push
                // out is held too (its move would be clipped, and the
                // clipped step would teach the update a false curvature).
                let outward = stepping_out(x, &d, bounds, &held);
                if outward.is_empty() {
                    break;
                }
                for i in outward {
                    held[i] = true;
                }
            }
        }
        MaxMinStep {
            mu,
            increase: self.predicted(&d),
            d,
            held,
            combined: self.combined(mu),
            branches: (self.index, self.other.as_ref().map(|o| o.0)),
            gap: self.other.as_ref().map_or(0.0, |o| o.1 - self.f),
        }
    }

    /// μ g_a + (1 − μ) g_b (g_a alone without a near branch).
    fn combined(&self, mu: f64) -> Vec<f64> {
        match &self.other {
            Some((_, _, g2)) => self
                .g
                .iter()
                .zip(g2)
                .map(|(a, b)| mu * a + (1.0 - mu) * b)
                .collect(),
            None => self.g.clone(),
        }
    }
}

/// One iteration's max–min step.
struct MaxMinStep {
    /// The least branch's multiplier (1: its own quasi-Newton step).
    mu: f64,
    /// The model's increase along `d` ([`Local::predicted`]).
    increase: f64,
    /// The direction.
    d: Vec<f64>,
    /// The variables held at their bounds.
    held: Vec<bool>,
    /// μ g_a + (1 − μ) g_b.
    combined: Vec<f64>,
    /// The branches of the model (least, near).
    branches: (usize, Option<usize>),
    /// f_b − f_a (0 without a near branch).
    gap: f64,
}

impl MaxMinStep {
    /// A KKT point of the max–min problem on the box: the combined
    /// gradient's projection below [`ASCENT_TOLERANCE`] × f, and where
    /// both branches carry weight, the branches equal to that tolerance.
    fn stationary(&self, x: &[f64], bounds: &[(f64, f64)], f: f64) -> bool {
        let tolerance = ASCENT_TOLERANCE * f.abs();
        projected_gradient(x, &self.combined, bounds) <= tolerance
            && (self.mu >= 1.0 || self.gap <= tolerance)
    }

    /// The gradient of the Lagrangian μ g_a + (1 − μ) g_b at a point's
    /// slope, the branches by their index (None where one has no
    /// gradient there).
    fn lagrangian(&self, slope: &Slope) -> Option<Vec<f64>> {
        let ga = slope.get(self.branches.0)?.1.as_ref()?;
        match self.branches.1 {
            Some(b) if self.mu < 1.0 => {
                let gb = slope.get(b)?.1.as_ref()?;
                Some(
                    ga.iter()
                        .zip(gb)
                        .map(|(a, b)| self.mu * a + (1.0 - self.mu) * b)
                        .collect(),
                )
            }
            _ => Some(ga.clone()),
        }
    }
}

/// How a line search ended.
enum Step {
    /// The accepted point and its slope.
    Accepted((Vec<f64>, Slope)),
    /// No step of at least 1e-12 increased the value.
    Flat,
    /// `stop()` turned true.
    Stopped,
}

/// The projected search path P(x + t d) of one iteration.
struct ProjectedPath<'a> {
    x: &'a [f64],
    d: &'a [f64],
    local: &'a Local,
    held: &'a [bool],
    bounds: &'a [(f64, f64)],
}

impl ProjectedPath<'_> {
    /// The point at step t, P(x + t d).
    fn at(&self, t: f64) -> Vec<f64> {
        (0..self.x.len())
            .map(|i| {
                let (lo, hi) = self.bounds[i];
                (self.x[i] + t * self.d[i]).clamp(lo, hi)
            })
            .collect()
    }

    /// The first breakpoint: the least t > 0 at which a free variable
    /// reaches a bound (∞ when none does).
    fn breakpoint(&self) -> f64 {
        (0..self.x.len())
            .filter(|&i| !self.held[i] && self.d[i] != 0.0)
            .map(|i| {
                let (lo, hi) = self.bounds[i];
                let room = if self.d[i] > 0.0 {
                    hi - self.x[i]
                } else {
                    lo - self.x[i]
                };
                room / self.d[i]
            })
            .filter(|t| *t > 0.0)
            .fold(f64::INFINITY, f64::min)
    }

    /// Armijo backtracking along the path from t = 1: f(x_t) ≥ f +
    /// σ m(x_t − x), m the model's increase ([`Local::predicted`]), and
    /// f(x_t) > f: a strict increase (a step that leaves f unchanged, as
    /// the halvings do once t d is below the values' round-off, is no
    /// progress: accepted, it let the ascent repeat the same ≈ 20-evaluation
    /// search up to its iteration cap, 7567 evaluations of one 400-element
    /// check polish of the Fig. 6 sweep at a projected gradient 1.5× the
    /// tolerance). Where t = 1 fails and the first breakpoint lies before
    /// it, the breakpoint is tried next (so that a variable the step
    /// pushes through a bound lands on it, instead of halvings that leave
    /// it just inside); then t halves, down to 1e-12. A point whose least
    /// branch has no gradient (a double critical load within one block) is
    /// passed over once for a shorter step, and taken if that fails.
    fn search(
        &self,
        slope: &dyn Fn(&[f64]) -> Option<Slope>,
        stop: &dyn Fn() -> bool,
        evaluations: &mut usize,
    ) -> Step {
        let f = self.local.f;
        let breakpoint = self.breakpoint();
        let mut t: f64 = 1.0;
        let mut kink = None;
        while t >= 1e-12 {
            if stop() {
                return Step::Stopped;
            }
            let trial = self.at(t);
            let dx: Vec<f64> = trial.iter().zip(self.x).map(|(a, b)| a - b).collect();
            let rise = self.local.predicted(&dx);
            *evaluations += 1;
            if let Some(there) = slope(&trial) {
                let ft = least(&there);
                if ft >= f + 1e-4 * rise && ft > f {
                    if Local::at(&there).is_none() && kink.is_none() && t > 1e-6 {
                        kink = Some((trial, there));
                        t *= 0.5;
                        continue;
                    }
                    let accepted = (trial, there);
                    return if t == 1.0 && self.local.other.is_none() {
                        self.extend(accepted, breakpoint, slope, stop, evaluations)
                    } else {
                        Step::Accepted(accepted)
                    };
                }
                if let Some(kink) = kink.take() {
                    return Step::Accepted(kink);
                }
            }
            t = if t == 1.0 && breakpoint < 1.0 {
                breakpoint
            } else {
                0.5 * t
            };
        }
        kink.map_or(Step::Flat, Step::Accepted)
    }

    /// The slope of f along d at a point with gradient `g` (over the free
    /// variables, those the path moves).
    fn slope_along(&self, g: &[f64]) -> f64 {
        (0..self.d.len())
            .filter(|&i| !self.held[i])
            .map(|i| g[i] * self.d[i])
            .sum()
    }

    /// Goes on past an accepted full step while f still rises steeply
    /// along the path (its slope there above half the slope at x: the
    /// quasi-Newton model's curvature is too large, as where R̂ is nearly
    /// linear on the way to a bound): t grows to the secant estimate of
    /// the slope's zero, at least ×2 and at most ×8, never past the first
    /// breakpoint, while f increases and no other branch comes near.
    /// Without this a search creeps to a bound by steps growing ×2–3 per
    /// iteration.
    fn extend(
        &self,
        accepted: (Vec<f64>, Slope),
        breakpoint: f64,
        slope: &dyn Fn(&[f64]) -> Option<Slope>,
        stop: &dyn Fn() -> bool,
        evaluations: &mut usize,
    ) -> Step {
        let s0 = self.slope_along(&self.local.g);
        let (mut t, mut best) = (1.0, accepted);
        for _ in 0..EXTENSIONS {
            let Some(local) = Local::at(&best.1).filter(|l| l.other.is_none()) else {
                break;
            };
            let s1 = self.slope_along(&local.g);
            if s1 <= 0.5 * s0 || t >= breakpoint {
                break;
            }
            let secant = if s1 < s0 {
                t * s0 / (s0 - s1)
            } else {
                f64::INFINITY
            };
            let next = secant.clamp(2.0 * t, 8.0 * t).min(breakpoint);
            if stop() {
                return Step::Stopped;
            }
            let trial = self.at(next);
            *evaluations += 1;
            match slope(&trial) {
                Some(there) if least(&there) > local.f && Local::at(&there).is_some() => {
                    (t, best) = (next, (trial, there));
                }
                _ => break,
            }
        }
        Step::Accepted(best)
    }
}

/// The most extensions of one accepted full step ([`ProjectedPath::extend`]).
const EXTENSIONS: usize = 8;

/// Rescales the diagonal first guess B0 = diag(1/w_i²)/θ to the curvature
/// the first step measured, B0 = κ diag(1/w_i²) with κ = ỹᵀỹ/s̃ᵀỹ in the
/// width-scaled variables x̃ = x/w (Nocedal & Wright, eq. 6.20, before the
/// first update): the guess limits the first step to 5 % of the box, and
/// left unscaled it keeps later steps short where R̂ is nearly linear.
/// Whether it was rescaled (not where no positive curvature was measured).
fn rescale(b: &mut DMatrix<f64>, widths: &[f64], s: &[f64], y: &[f64]) -> bool {
    let sy: f64 = s.iter().zip(y).map(|(a, b)| a * b).sum();
    let yy: f64 = y.iter().zip(widths).map(|(a, w)| (a * w).powi(2)).sum();
    if !(sy > 0.0 && yy > 0.0) {
        return false;
    }
    let kappa = yy / sy;
    *b = DMatrix::from_fn(widths.len(), widths.len(), |i, j| {
        if i == j {
            kappa / (widths[i] * widths[i])
        } else {
            0.0
        }
    });
    true
}

/// max_i |x_i − P(x_i + g_i)|: zero exactly at a KKT point of the box.
fn projected_gradient(x: &[f64], g: &[f64], bounds: &[(f64, f64)]) -> f64 {
    x.iter()
        .zip(g)
        .zip(bounds)
        .map(|((xi, gi), (lo, hi))| (xi - (xi + gi).clamp(*lo, *hi)).abs())
        .fold(0.0, f64::max)
}

/// The ε-active variables (Bertsekas 1982): within ε_i of a bound that the
/// gradient pushes them to, ε_i = min([`ACTIVE_FRACTION`] w_i, pg) with pg
/// the projected-gradient norm (so that ε → 0 at a KKT point and a free
/// variable near the optimum is never mistaken for a bound one). They are
/// held on that bound for the iteration.
fn held_at_bounds(
    x: &[f64],
    g: &[f64],
    bounds: &[(f64, f64)],
    widths: &[f64],
    pg: f64,
) -> Vec<bool> {
    (0..x.len())
        .map(|i| {
            let (lo, hi) = bounds[i];
            let eps = (ACTIVE_FRACTION * widths[i]).min(pg);
            (x[i] <= lo + eps && g[i] < 0.0) || (x[i] >= hi - eps && g[i] > 0.0)
        })
        .collect()
}

/// The largest ε of the ε-active set, as a fraction of a bound's width.
const ACTIVE_FRACTION: f64 = 1e-3;

/// The free variables on a bound that `d` moves outwards.
fn stepping_out(x: &[f64], d: &[f64], bounds: &[(f64, f64)], held: &[bool]) -> Vec<usize> {
    (0..x.len())
        .filter(|&i| {
            let (lo, hi) = bounds[i];
            !held[i] && ((x[i] <= lo && d[i] < 0.0) || (x[i] >= hi && d[i] > 0.0))
        })
        .collect()
}

/// d solving B_ff d_f = g_f on the free variables (the quasi-Newton step
/// of the reduced problem), g_i/B_ii on the held; None where B_ff is not positive
/// definite (by round-off).
fn ascent_direction(hessian: &DMatrix<f64>, g: &[f64], held: &[bool]) -> Option<Vec<f64>> {
    let free: Vec<usize> = (0..g.len()).filter(|&i| !held[i]).collect();
    let reduced = DMatrix::from_fn(free.len(), free.len(), |i, j| hessian[(free[i], free[j])]);
    let rhs = DVector::from_iterator(free.len(), free.iter().map(|&i| g[i]));
    let step = reduced.cholesky()?.solve(&rhs);
    // The held variables move along their gradient scaled by the model's
    // diagonal (Bertsekas 1982), onto their bound as t grows: continuous
    // in t, so that short steps change them little.
    let mut d: Vec<f64> = (0..g.len())
        .map(|i| if held[i] { g[i] / hessian[(i, i)] } else { 0.0 })
        .collect();
    for (k, &i) in free.iter().enumerate() {
        d[i] = step[k];
    }
    Some(d)
}

/// The first Hessian model of −f: diag(1/w_i²)/θ, θ such that the first
/// step moves no variable by more than 5 % of its bound's width.
pub(crate) fn initial_hessian(widths: &[f64], g: &[f64]) -> DMatrix<f64> {
    let largest = widths
        .iter()
        .zip(g)
        .map(|(w, gi)| (w * gi).abs())
        .fold(0.0, f64::max);
    let theta = if largest > 0.0 { 0.05 / largest } else { 1.0 };
    DMatrix::from_fn(widths.len(), widths.len(), |i, j| {
        if i == j {
            1.0 / (theta * widths[i] * widths[i])
        } else {
            0.0
        }
    })
}

/// The BFGS update of the Hessian model B of −f,
/// B ← B − B s sᵀB / sᵀBs + y yᵀ / yᵀs (Nocedal & Wright, eq. 6.19), with
/// y the change of −∇f; skipped where yᵀs ≤ 1e-12 |s||y| (no positive
/// curvature measured), so that B stays positive definite.
pub(crate) fn bfgs_update(b: &mut DMatrix<f64>, s: &[f64], y: &[f64]) {
    let (s, y) = (DVector::from_column_slice(s), DVector::from_column_slice(y));
    let sy = s.dot(&y);
    if sy <= 1e-12 * s.norm() * y.norm() || sy <= 0.0 {
        return;
    }
    let bs = &*b * &s;
    let sbs = s.dot(&bs);
    if sbs <= 0.0 {
        return;
    }
    *b += &y * y.transpose() / sy - &bs * bs.transpose() / sbs;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ill-conditioned concave quadratic, f = 3 − ½ (x − t)ᵀ Q (x − t),
    /// whose unconstrained maximum t lies outside the box in x0: the
    /// box-constrained maximum is at x0 = 1 (its bound) with x1 maximizing
    /// f along it, x1 = t1 − Q10 (1 − t0)/Q11 (closed form, the KKT point:
    /// ∂f/∂x0 = −(Q(x − t))0 > 0 there, pushing out).
    #[test]
    fn ascent_reaches_the_box_constrained_maximum_of_a_quadratic() {
        let q = [[1.0, 0.999], [0.999, 1.0]];
        let t = [2.0, -1.0];
        let slope = |x: &[f64]| -> Option<Slope> {
            let d = [x[0] - t[0], x[1] - t[1]];
            let qd = [
                q[0][0] * d[0] + q[0][1] * d[1],
                q[1][0] * d[0] + q[1][1] * d[1],
            ];
            let f = 3.0 - 0.5 * (d[0] * qd[0] + d[1] * qd[1]);
            Some(vec![(f, Some(vec![-qd[0], -qd[1]]))])
        };
        let bounds = [(-1.0, 1.0), (-4.0, 4.0)];
        let ascent = ascend_in_box(&[0.0, 0.0], &bounds, 200, &slope, &|| false, None);
        assert_eq!(ascent.end, AscentEnd::Converged, "{ascent:?}");
        let (x, _) = ascent.best.expect("a point");
        let x1 = t[1] - q[1][0] * (1.0 - t[0]) / q[1][1];
        assert_eq!(x[0], 1.0);
        assert!((x[1] - x1).abs() < 1e-6, "{x:?} against (1, {x1})");
    }

    /// A maximum on a kink: f = min(1 + x0, 1 − x0) − x1², two smooth
    /// branches meeting at x0 = 0, where f has its maximum 1 at (0, 0)
    /// (closed form). The max–min step reaches it and stops there as a
    /// KKT point (the branches equal, μ g_a + (1 − μ) g_b = 0 at μ = ½);
    /// a single-branch ascent would zigzag across x0 = 0.
    #[test]
    fn ascent_reaches_a_maximum_on_a_kink() {
        let slope = |x: &[f64]| -> Option<Slope> {
            let q = x[1] * x[1];
            Some(vec![
                (1.0 + x[0] - q, Some(vec![1.0, -2.0 * x[1]])),
                (1.0 - x[0] - q, Some(vec![-1.0, -2.0 * x[1]])),
            ])
        };
        let bounds = [(-1.0, 1.0), (-1.0, 1.0)];
        let ascent = ascend_in_box(&[0.7, 0.5], &bounds, 100, &slope, &|| false, None);
        assert_eq!(ascent.end, AscentEnd::Converged, "{ascent:?}");
        let (x, f) = ascent.best.expect("a point");
        assert!(x[0].abs() < 1e-8 && x[1].abs() < 1e-6, "{x:?}");
        assert!((f - 1.0).abs() < 1e-8, "{f}");
        assert!(
            ascent.evaluations < 40,
            "{} evaluations",
            ascent.evaluations
        );
    }

    /// A value without a gradient ends the ascent there, said so.
    #[test]
    fn ascent_stops_where_there_is_no_gradient() {
        let slope = |x: &[f64]| -> Option<Slope> { Some(vec![(-x[0].abs(), None)]) };
        let ascent = ascend_in_box(&[0.5], &[(-1.0, 1.0)], 10, &slope, &|| false, None);
        assert_eq!(ascent.end, AscentEnd::NoGradient);
        assert_eq!(ascent.iterations, 0);
    }
}
