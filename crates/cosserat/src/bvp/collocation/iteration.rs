//! Damped Newton on the collocation equations, and polishing.
//!
//! Steps x ← x + λδ with δ = −J(x)⁻¹F(x) from the condensed banded
//! factorization, by the crate's one Newton method
//! ([`crate::numerics::newton`]); λ is accepted by Deuflhard's natural monotonicity test
//! ‖J(x)⁻¹F(x + λδ)‖ ≤ (1 − λ/4)‖δ‖ with the already factored J, so every
//! trial costs one O(N) solve. After convergence a few full steps polish
//! the solution to round-off.

use super::grid::{Grid, Scratch};
use super::lu::BandLu;
use super::CollocationError;
use crate::bvp::newton::NewtonOptions;
use crate::numerics::newton::{self, NewtonError, System, Trial};

/// The factored Newton matrix: per interval the factored stage block, in
/// flat storage reused across Newton iterations. Nothing else per interval
/// is kept: the stage corrections' response to δy_i, W⁻¹E, is applied as a
/// second solve with these factors, and the node rows are combined with
/// the stage rows so that they hold no Jacobian ([`super::Tableau::d`]).
pub(super) struct Linearization {
    /// The stage matrices W factored by [`super::stage_lu::StageSplit`].
    pub(super) lu: Vec<f64>,
    /// Their row interchanges.
    pub(super) piv: Vec<u8>,
    pub(super) band: BandLu,
    /// Whether the last `linearize` succeeded.
    pub(super) valid: bool,
}

pub(super) struct NewtonOutcome {
    pub(super) x: Vec<f64>,
    pub(super) iterations: usize,
    pub(super) history: Vec<f64>,
    pub(super) damped_steps: usize,
    pub(super) contraction: f64,
    /// The last successful factorization (at x or the iterate before).
    pub(super) lin: Option<Linearization>,
}

pub(super) fn max_norm(r: &[f64]) -> f64 {
    r.iter().fold(
        0.0,
        |m, v| if v.is_nan() { f64::NAN } else { m.max(v.abs()) },
    )
}

/// The collocation equations as a [`System`] of the numerics layer: the
/// residual of the mesh, the condensed banded factorization as the
/// linearization (so that every solve is O(N)), and the mesh's own norm of
/// a correction.
struct Collocation<'g, 'a> {
    grid: &'g Grid<'a>,
    n: usize,
    lin: Linearization,
    ws: Scratch,
    /// The node part of a simplified correction ([`Grid::correction_norm`]).
    head: Vec<f64>,
}

/// A residual that is not finite (its max-norm), which makes a point
/// inadmissible.
struct NonFinite(f64);

impl System for Collocation<'_, '_> {
    type Error = NonFinite;

    fn size(&self) -> usize {
        self.n
    }

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), NonFinite> {
        self.grid.residual_into(x, r);
        let norm = max_norm(r);
        if norm.is_finite() {
            Ok(())
        } else {
            Err(NonFinite(norm))
        }
    }

    fn linearize(&mut self, x: &[f64]) -> bool {
        self.grid.linearize(x, &mut self.lin, &mut self.ws)
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        self.grid.newton_correction(&self.lin, f, delta);
        true
    }

    fn unknown_scales(&self) -> Vec<f64> {
        self.grid.unknown_scales()
    }

    fn correction_norm(&self, delta: &[f64]) -> f64 {
        self.grid.step_norm(delta)
    }

    /// The damping's simplified correction measured interval by interval:
    /// one vector of the unknowns' size fewer.
    fn correction_norm_for(&mut self, f: &[f64], _work: &mut Vec<f64>) -> Option<f64> {
        self.head
            .resize(self.grid.p + self.grid.n * self.grid.intervals(), 0.0);
        Some(self.grid.correction_norm(&self.lin, f, &mut self.head))
    }
}

/// Damped Newton ([`crate::numerics::newton`]) with Deuflhard's natural
/// monotonicity test: accept λ when ‖J(x)⁻¹F(x + λδ)‖ ≤ (1 − λ/4)‖δ‖,
/// using the already factored J; every linear solve is O(N). A residual
/// that is not finite makes a trial point inadmissible. Converged, the
/// solution is polished.
pub(super) fn damped_newton(
    grid: &Grid,
    x0: Vec<f64>,
    opts: &NewtonOptions,
) -> Result<NewtonOutcome, CollocationError> {
    let intervals = grid.intervals();
    let mut x = x0;
    let mut system = Collocation {
        grid,
        n: x.len(),
        lin: grid.new_linearization(),
        ws: Scratch::new(grid),
        head: Vec::new(),
    };
    let fail = |reason: String, history: Vec<f64>| CollocationError::NoConvergence {
        intervals,
        reason,
        history,
    };
    match newton::solve(&mut system, &mut x, &opts.damped()) {
        Ok(report) => {
            let Collocation { lin, mut ws, .. } = system;
            let buffers = (report.residual, report.correction);
            let mut out = polish(grid, x, buffers, report.history, lin, &mut ws);
            out.damped_steps = report.damped_steps;
            out.contraction = report.contraction;
            Ok(out)
        }
        Err(NewtonError::BadStart(NonFinite(norm))) => Err(fail(
            "the initial guess is inadmissible (non-finite residual)".into(),
            vec![norm],
        )),
        Err(NewtonError::SingularJacobian { iteration, history }) => {
            Err(CollocationError::SingularJacobian {
                iteration,
                intervals,
                history,
            })
        }
        Err(NewtonError::LineSearch {
            iteration,
            min_damping,
            last_trial: Trial::Residual(last) | Trial::Failed(NonFinite(last)),
            history,
        }) => Err(fail(
            format!(
                "no damped step (down to λ = {min_damping}) passed the natural monotonicity test at iteration {iteration}; last trial residual {last:.3e}"
            ),
            history,
        )),
        Err(NewtonError::IterationLimit {
            iterations,
            history,
        }) => Err(fail(
            format!("{iterations} iterations without reaching the tolerance"),
            history,
        )),
        // Damped steps never end on an inadmissible point.
        Err(NewtonError::Evaluation {
            iteration,
            error: NonFinite(norm),
            history,
        }) => Err(fail(
            format!("the step of iteration {iteration} has a residual of {norm:.3e}"),
            history,
        )),
    }
}

/// Polishing steps after the residual meets the tolerance.
pub(super) const POLISH_STEPS: usize = 2;

/// Up to `POLISH_STEPS` full Newton steps after convergence, each kept only
/// if it reduces the residual by a factor 10 (so they stop at round-off).
/// They cost O(N) each and leave a solution that satisfies the discrete
/// equations to round-off, so that what remains (e.g. the director drift)
/// is discretization error rather than Newton's stopping point. `buffers`
/// are F(x) and a vector of the unknowns' size to work in (Newton's last
/// correction), so that polishing holds no more vectors than Newton.
pub(super) fn polish(
    grid: &Grid,
    mut x: Vec<f64>,
    buffers: (Vec<f64>, Vec<f64>),
    mut history: Vec<f64>,
    mut lin: Linearization,
    ws: &mut Scratch,
) -> NewtonOutcome {
    let (mut f, mut trial) = buffers;
    let mut f_try = vec![0.0; x.len()];
    let iterations = history.len() - 1;
    for _ in 0..POLISH_STEPS {
        if !grid.linearize(&x, &mut lin, ws) {
            break;
        }
        // The step, then x + step in place.
        grid.newton_correction(&lin, &f, &mut trial);
        trial.iter_mut().zip(&x).for_each(|(b, a)| *b += a);
        grid.residual_into(&trial, &mut f_try);
        let norm = max_norm(&f_try);
        if norm.is_nan() || norm > 0.1 * history.last().unwrap() {
            break;
        }
        std::mem::swap(&mut x, &mut trial);
        std::mem::swap(&mut f, &mut f_try);
        history.push(norm);
    }
    NewtonOutcome {
        x,
        iterations: iterations.max(history.len() - 1),
        history,
        damped_steps: 0,
        contraction: 0.0,
        lin: lin.valid.then_some(lin),
    }
}
