//! One damped Newton method for every nonlinear system of the crate: the
//! shooting and collocation equations of a rod, the bordered system of
//! pseudo-arclength continuation, the three equations ∇W(κ) = M of a clamp.
//! Nothing of rods is in here: a [`System`] gives its residual, a
//! linearization and a linear solve (dense, banded or bordered — the solver
//! never sees a matrix), and the scales of its rows and unknowns.
//!
//! # The iteration
//!
//! From x₀, with F(x_k) known, each iteration
//!
//! 1. linearizes at x_k and solves J(x_k) δ_k = −F(x_k) (the Newton
//!    correction);
//! 2. stops if the pair (F(x_k), δ_k) passes the [`Convergence`] test;
//! 3. steps x_{k+1} = x_k + λ_k δ_k, with λ_k = 1 undamped
//!    ([`Damping::Full`]) or, damped ([`Damping::NaturalMonotonicity`]),
//!    the first λ ∈ {1, ½, ¼, …} down to λ_min at which F is defined and
//!    the simplified correction δ̄ = −J(x_k)⁻¹F(x_k + λδ_k), solved with the
//!    matrix already factored, satisfies the natural monotonicity test
//!
//!    ‖δ̄‖ ≤ (1 − λ/4) ‖δ_k‖
//!
//!    (Deuflhard, *Newton Methods for Nonlinear Problems*, Sec. 3.1.4).
//!    Unlike ‖F‖ this level function is invariant under a scaling of the
//!    equations, so a badly scaled row cannot trap the iteration in a
//!    spurious minimum of the residual norm.
//!
//! The iteration ends with a [`Report`] (iterations, the residual history,
//! damped steps, the contraction Θ = max ‖δ_{k+1}‖/‖δ_k‖, the last
//! correction) or a [`NewtonError`] that names why it stopped.

use std::fmt;

use nalgebra::DVectorView;

/// A square nonlinear system F(x) = 0, x ∈ ℝⁿ, as Newton needs it.
///
/// Newton calls [`System::residual`] at x₀ and at every trial point, then
/// [`System::linearize`] at each accepted iterate (always the point of the
/// last successful `residual` call, so a system that computes J alongside F
/// may keep it from there), and [`System::solve`] with that linearization
/// for the correction and for the simplified corrections of the damping.
pub trait System {
    /// Why the residual could not be evaluated at a point (an inadmissible
    /// point: an integration that blew up, a non-finite residual, ...).
    type Error;

    /// The number n of unknowns and of equations.
    fn size(&self) -> usize;

    /// F(x) into `r` (length n), or why x is inadmissible.
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Self::Error>;

    /// Prepares the solves with J(x) (e.g. factors it); x is the point of
    /// the last successful [`System::residual`] call. False when J(x)
    /// cannot be formed or factored.
    fn linearize(&mut self, x: &[f64]) -> bool;

    /// The correction δ = −J⁻¹ F of J δ = −F for the right-hand side
    /// `f` = F, with the J of the last [`System::linearize`], into
    /// `delta`. False when J is singular (Newton also treats a Newton
    /// correction that is not finite as singular).
    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool;

    /// The unit ρ_i of each equation: the residual test measures
    /// max_i |F_i| / ρ_i. All 1 (the default) when the system already
    /// returns dimensionless residuals.
    fn residual_scales(&self) -> Vec<f64> {
        vec![1.0; self.size()]
    }

    /// The typical magnitude s_i of each unknown in natural units: a
    /// correction counts as small when it is small against max(|x_i|, s_i).
    fn unknown_scales(&self) -> Vec<f64> {
        vec![1.0; self.size()]
    }

    /// The norm ‖δ‖ of a correction used by the damping and the
    /// contraction Θ; the Euclidean norm by default.
    fn correction_norm(&self, delta: &[f64]) -> f64 {
        DVectorView::from_slice(delta, delta.len()).norm()
    }

    /// The [`System::correction_norm`] of the correction −J⁻¹f for the
    /// right-hand side `f` with the J of the last [`System::linearize`],
    /// or None when the solve fails: the damping's simplified correction,
    /// of which Newton needs only the norm. By default solved into `work`
    /// (resized to n); a system that measures the correction without
    /// keeping it whole overrides this and leaves `work` empty (collocation:
    /// interval by interval, so that a fine mesh holds one vector fewer).
    fn correction_norm_for(&mut self, f: &[f64], work: &mut Vec<f64>) -> Option<f64> {
        work.resize(f.len(), 0.0);
        self.solve(f, work).then(|| self.correction_norm(work))
    }

    /// Whether the iterate x with scaled residual norm `residual` and
    /// correction `delta` is converged; by default the [`Convergence`]
    /// test. A system overrides it only when its stopping rule differs on
    /// purpose (and says why).
    fn converged(&self, test: &Convergence, residual: f64, x: &[f64], delta: &[f64]) -> bool {
        test.met(residual, x, delta)
    }
}

/// Newton's stopping test: the scaled residual at most the tolerance τ and
/// the scaled correction at most √τ,
///
///   max_i |F_i| / ρ_i ≤ τ   and   max_i |δ_i| / max(|x_i|, s_i) ≤ √τ.
///
/// Both are needed. A residual test alone is fooled by a badly scaled
/// equation (a stiffness of 1e10 made an unbent rod's tip moment look
/// converged), a correction test alone by an ill-conditioned Jacobian; the
/// correction is the affine-invariant measure of how far the iterate is
/// from the root (Deuflhard, Sec. 2.1). The correction is first-order the
/// error of the iterate; in the quadratic regime the next one is of the
/// order of its square, so a correction above √τ means the residual test
/// was fooled (a badly scaled equation, a start on the wrong root's
/// shoulder) while one below it is consistent with a residual of τ. (Asking
/// τ of the correction itself would demand more than round-off and an
/// integrator's tolerance allow through an ill-conditioned Jacobian.)
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    tolerance: f64,
    scales: Vec<f64>,
    /// ρ_i; empty means all 1 (and then no division at all).
    residual_scales: Vec<f64>,
}

impl Convergence {
    /// The test with `tolerance` τ on the residual, √τ on the correction,
    /// the unknowns' typical magnitudes `scales` (each > 0) and residual
    /// rows measured as they are (ρ_i = 1).
    pub fn new(tolerance: f64, scales: Vec<f64>) -> Self {
        Convergence {
            tolerance,
            scales,
            residual_scales: vec![],
        }
    }

    /// The same test with the residual rows measured in units ρ_i (each
    /// > 0): row i counts |F_i| / ρ_i.
    #[must_use]
    pub fn with_residual_scales(mut self, scales: Vec<f64>) -> Self {
        self.residual_scales = if scales.iter().all(|&s| s == 1.0) {
            vec![]
        } else {
            scales
        };
        self
    }

    /// The tolerance τ.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// max_i |F_i| / ρ_i, the max-norm of the scaled residual.
    ///
    /// A NaN entry makes the norm NaN only when no number follows it (the
    /// fold the solvers have always used, kept so that residual histories
    /// stay bit-identical); a NaN residual still never converges, since its
    /// Newton correction is not finite.
    pub fn residual_norm(&self, r: &[f64]) -> f64 {
        let fold = |m: f64, v: f64| if v.is_nan() { f64::NAN } else { m.max(v) };
        if self.residual_scales.is_empty() {
            r.iter().map(|v| v.abs()).fold(0.0, fold)
        } else {
            r.iter()
                .zip(&self.residual_scales)
                .map(|(v, s)| v.abs() / s)
                .fold(0.0, fold)
        }
    }

    /// max_i |δ_i| / max(|x_i|, s_i): the correction relative to each
    /// unknown's magnitude, floored at its natural unit.
    pub fn step_size(&self, x: &[f64], step: &[f64]) -> f64 {
        x.iter()
            .zip(step)
            .zip(&self.scales)
            .map(|((xi, di), si)| di.abs() / xi.abs().max(*si))
            .fold(0.0, |m, v| if v.is_nan() { f64::NAN } else { m.max(v) })
    }

    /// Whether the residual (already measured by
    /// [`Convergence::residual_norm`]) is small enough that a correction is
    /// worth testing.
    pub fn residual_met(&self, residual: f64) -> bool {
        residual <= self.tolerance
    }

    /// Both measures met.
    pub fn met(&self, residual: f64, x: &[f64], step: &[f64]) -> bool {
        self.residual_met(residual) && self.step_size(x, step) <= self.tolerance.sqrt()
    }
}

/// How the step length λ of x_{k+1} = x_k + λδ_k is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Damping {
    /// λ = 1 always: plain Newton, for systems started close to the root
    /// (a continuation corrector from its predictor); a full step onto an
    /// inadmissible point ends the iteration ([`NewtonError::Evaluation`]).
    Full,
    /// Halve λ from 1 until F is defined at x + λδ and the natural
    /// monotonicity test ‖J(x)⁻¹F(x + λδ)‖ ≤ (1 − λ/4)‖δ‖ holds; give up
    /// below `min_damping` ([`NewtonError::LineSearch`]).
    NaturalMonotonicity {
        /// The smallest λ tried.
        min_damping: f64,
    },
}

/// Newton's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The tolerance τ of the [`Convergence`] test.
    pub tolerance: f64,
    /// Newton steps at most: the test is tried at x₀, …, x_max.
    pub max_iterations: usize,
    /// The step-length rule.
    pub damping: Damping,
}

/// A converged iteration (the root itself is left in the caller's x).
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Newton steps taken.
    pub iterations: usize,
    /// The scaled residual max_i |F_i|/ρ_i at every iterate, the last at
    /// the root.
    pub history: Vec<f64>,
    /// Steps with λ < 1.
    pub damped_steps: usize,
    /// The largest ratio ‖δ_{k+1}‖/‖δ_k‖ of successive corrections
    /// (Deuflhard's contraction Θ): well below 1 inside the region of
    /// quadratic convergence, near or above 1 when an iterate wandered.
    pub contraction: f64,
    /// The correction δ at the root that passed the test (the estimate of
    /// the root's remaining error).
    pub correction: Vec<f64>,
    /// F at the root (unscaled).
    pub residual: Vec<f64>,
}

/// The outcome of the last trial step of a failed damping.
#[derive(Debug, Clone, PartialEq)]
pub enum Trial<E> {
    /// F was defined there, with this scaled residual norm.
    Residual(f64),
    /// F was not defined there.
    Failed(E),
}

impl<E: fmt::Display> fmt::Display for Trial<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Trial::Residual(r) => write!(f, "scaled residual {r:.3e}"),
            Trial::Failed(e) => write!(f, "{e}"),
        }
    }
}

/// Why Newton stopped without converging; `E` is the system's
/// [`System::Error`].
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonError<E> {
    /// F is not defined at x₀.
    BadStart(E),
    /// An undamped step landed where F is not defined.
    Evaluation {
        /// The iteration whose step failed.
        iteration: usize,
        /// Why F is not defined there.
        error: E,
        /// Scaled residual at every iterate so far.
        history: Vec<f64>,
    },
    /// J could not be factored, or the correction was not finite.
    SingularJacobian {
        /// The iteration whose Jacobian was singular.
        iteration: usize,
        /// Scaled residual at every iterate so far.
        history: Vec<f64>,
    },
    /// No damped step passed the natural monotonicity test.
    LineSearch {
        /// The iteration whose damped steps all failed.
        iteration: usize,
        /// The smallest damping factor λ tried.
        min_damping: f64,
        /// The last trial's outcome.
        last_trial: Trial<E>,
        /// Scaled residual at every iterate so far.
        history: Vec<f64>,
    },
    /// The iteration budget ran out.
    IterationLimit {
        /// The budget.
        iterations: usize,
        /// Scaled residual at every iterate.
        history: Vec<f64>,
    },
}

impl<E> NewtonError<E> {
    /// The residual history up to the failure (empty for a bad start).
    pub fn history(&self) -> &[f64] {
        match self {
            NewtonError::BadStart(_) => &[],
            NewtonError::Evaluation { history, .. }
            | NewtonError::SingularJacobian { history, .. }
            | NewtonError::LineSearch { history, .. }
            | NewtonError::IterationLimit { history, .. } => history,
        }
    }
}

impl<E: fmt::Display> fmt::Display for NewtonError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NewtonError::BadStart(e) => write!(f, "the initial guess is inadmissible: {e}"),
            NewtonError::Evaluation {
                iteration, error, ..
            } => write!(
                f,
                "the Newton step of iteration {iteration} left the domain: {error}"
            ),
            NewtonError::SingularJacobian { iteration, .. } => write!(
                f,
                "singular Jacobian at iteration {iteration} (a fold or bifurcation, or a degenerate guess)"
            ),
            NewtonError::LineSearch {
                iteration,
                min_damping,
                last_trial,
                ..
            } => write!(
                f,
                "no damped step (down to λ = {min_damping}) passed the natural monotonicity test at iteration {iteration}; last trial: {last_trial}"
            ),
            NewtonError::IterationLimit { iterations, .. } => {
                write!(f, "{iterations} iterations without reaching the tolerance")
            }
        }
    }
}

/// The reason a point was inadmissible is part of the message, so it is
/// not repeated as a `source`.
impl<E: fmt::Debug + fmt::Display> std::error::Error for NewtonError<E> {}

/// Solves F(x) = 0 by Newton's method from the x given, which holds the
/// last admissible accepted iterate on return — the root on success.
pub fn solve<S: System + ?Sized>(
    system: &mut S,
    x: &mut [f64],
    opts: &Options,
) -> Result<Report, NewtonError<S::Error>> {
    let n = system.size();
    let test = Convergence::new(opts.tolerance, system.unknown_scales())
        .with_residual_scales(system.residual_scales());
    let mut r = vec![0.0; n];
    system.residual(x, &mut r).map_err(NewtonError::BadStart)?;
    let (mut r_try, mut trial) = (vec![0.0; n], vec![0.0; n]);
    // The simplified corrections' buffer, sized only by a system that needs
    // one (`System::correction_norm_for`).
    let (mut step, mut simplified) = (vec![0.0; n], Vec::new());
    let mut history = vec![test.residual_norm(&r)];
    let mut damped_steps = 0;
    let (mut contraction, mut last_step_norm) = (0.0_f64, f64::NAN);
    // The test is tried at x₀, …, x_max: a budget of max steps.
    for iteration in 0..=opts.max_iterations {
        let norm = *history.last().unwrap();
        let solved = system.linearize(x)
            && system.solve(&r, &mut step)
            && step.iter().all(|v| v.is_finite());
        if solved && system.converged(&test, norm, x, &step) {
            return Ok(Report {
                iterations: iteration,
                history,
                damped_steps,
                contraction,
                correction: step,
                residual: r,
            });
        }
        if iteration == opts.max_iterations {
            break;
        }
        if !solved {
            return Err(NewtonError::SingularJacobian { iteration, history });
        }
        let step_norm = system.correction_norm(&step);
        if last_step_norm > 0.0 {
            contraction = contraction.max(step_norm / last_step_norm);
        }
        last_step_norm = step_norm;
        // λ = 1, ½, ¼, …: a full step unless damped; damped, the trial is
        // accepted when F is defined there and the simplified correction,
        // solved with J(x) already factored, passes the natural
        // monotonicity test ‖J(x)⁻¹F(x + λδ)‖ ≤ (1 − λ/4)‖δ‖. (The order of
        // the operations is the shooting solver's since it was written, so
        // that every iterate is bit for bit what it was.)
        let mut lambda = 1.0;
        loop {
            for ((t, a), b) in trial.iter_mut().zip(x.iter()).zip(&step) {
                *t = a + lambda * b;
            }
            let outcome = system.residual(&trial, &mut r_try);
            let min_damping = match opts.damping {
                Damping::Full => match outcome {
                    Ok(()) => break,
                    Err(error) => {
                        return Err(NewtonError::Evaluation {
                            iteration,
                            error,
                            history,
                        })
                    }
                },
                Damping::NaturalMonotonicity { min_damping } => min_damping,
            };
            let accepted = outcome.is_ok()
                && system
                    .correction_norm_for(&r_try, &mut simplified)
                    .is_some_and(|norm| norm <= (1.0 - 0.25 * lambda) * step_norm);
            if accepted {
                break;
            }
            lambda *= 0.5;
            if lambda < min_damping {
                let last_trial = match outcome {
                    Ok(()) => Trial::Residual(test.residual_norm(&r_try)),
                    Err(e) => Trial::Failed(e),
                };
                return Err(NewtonError::LineSearch {
                    iteration,
                    min_damping,
                    last_trial,
                    history,
                });
            }
        }
        x.copy_from_slice(&trial);
        std::mem::swap(&mut r, &mut r_try);
        if lambda < 1.0 {
            damped_steps += 1;
        }
        history.push(test.residual_norm(&r));
    }
    Err(NewtonError::IterationLimit {
        iterations: opts.max_iterations,
        history,
    })
}

#[cfg(test)]
mod tests;
