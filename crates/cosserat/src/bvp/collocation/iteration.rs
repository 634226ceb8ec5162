//! Damped Newton on the collocation equations, and polishing.
//!
//! Steps x ← x + λδ with δ = −J(x)⁻¹F(x) from the condensed banded
//! factorization; λ is accepted by Deuflhard's natural monotonicity test
//! ‖J(x)⁻¹F(x + λδ)‖ ≤ (1 − λ/4)‖δ‖ with the already factored J, so every
//! trial costs one O(N) solve. After convergence a few full steps polish
//! the solution to round-off.

use super::grid::{Grid, Scratch};
use super::lu::BandLu;
use super::CollocationError;
use crate::bvp::newton::{Convergence, NewtonOptions};

/// The factored Newton matrix: per interval the condensed stage block, in
/// flat storage reused across Newton iterations.
pub(super) struct Linearization {
    /// LU factors of the stage matrices W (mn × mn each, row-major).
    pub(super) lu: Vec<f64>,
    /// Their row interchanges.
    pub(super) piv: Vec<usize>,
    /// W⁻¹E (mn × n each, column-major): the stage corrections' response
    /// to δy_i.
    pub(super) z: Vec<f64>,
    /// h b_j J_j (m blocks of n × n each, column-major).
    pub(super) hbj: Vec<f64>,
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

/// Damped Newton with Deuflhard's natural monotonicity test (as in
/// `newton::solve`): accept λ when ‖J(x)⁻¹F(x + λδ)‖ ≤ (1 − λ/4)‖δ‖, using
/// the already factored J; every linear solve is O(N).
pub(super) fn damped_newton(
    grid: &Grid,
    x0: Vec<f64>,
    opts: &NewtonOptions,
) -> Result<NewtonOutcome, CollocationError> {
    let intervals = grid.intervals();
    let mut x = x0;
    let mut f = grid.residual(&x);
    let mut history = vec![max_norm(&f)];
    let (mut damped_steps, mut contraction, mut last_norm) = (0, 0.0f64, f64::NAN);
    let fail = |reason: String, history: Vec<f64>| CollocationError::NoConvergence {
        intervals,
        reason,
        history,
    };
    if !history[0].is_finite() {
        return Err(fail(
            "the initial guess is inadmissible (non-finite residual)".into(),
            history,
        ));
    }
    let mut lin = grid.new_linearization();
    let mut ws = Scratch::new(grid.n, grid.tab.m);
    let test = Convergence::new(opts.tolerance, grid.unknown_scales());
    for iteration in 0..=opts.max_iterations {
        let singular = |history| CollocationError::SingularJacobian {
            iteration,
            intervals,
            history,
        };
        let linearized = grid.linearize(&x, &mut lin, &mut ws);
        let step = grid.newton_correction(&lin, &f);
        let step_ok = linearized && step.iter().all(|v| v.is_finite());
        if step_ok && test.met(*history.last().unwrap(), &x, &step) {
            let mut out = polish(grid, x, f, history, lin, &mut ws);
            out.damped_steps = damped_steps;
            out.contraction = contraction;
            return Ok(out);
        }
        if iteration == opts.max_iterations {
            break;
        }
        if !step_ok {
            return Err(singular(history));
        }
        let step_norm = grid.step_norm(&step);
        if last_norm > 0.0 {
            contraction = contraction.max(step_norm / last_norm);
        }
        last_norm = step_norm;
        let mut lambda = 1.0;
        loop {
            let trial: Vec<f64> = x.iter().zip(&step).map(|(a, b)| a + lambda * b).collect();
            let f_try = grid.residual(&trial);
            let accepted = max_norm(&f_try).is_finite()
                && grid.step_norm(&grid.newton_correction(&lin, &f_try))
                    <= (1.0 - 0.25 * lambda) * step_norm;
            if accepted {
                (x, f) = (trial, f_try);
                break;
            }
            lambda *= 0.5;
            if lambda < opts.min_damping {
                let reason = format!(
                    "no damped step (down to λ = {}) passed the natural monotonicity test at iteration {iteration}; last trial residual {:.3e}",
                    opts.min_damping,
                    max_norm(&f_try)
                );
                return Err(fail(reason, history));
            }
        }
        if lambda < 1.0 {
            damped_steps += 1;
        }
        history.push(max_norm(&f));
    }
    Err(fail(
        format!(
            "{} iterations without reaching the tolerance",
            opts.max_iterations
        ),
        history,
    ))
}

/// Polishing steps after the residual meets the tolerance.
pub(super) const POLISH_STEPS: usize = 2;

/// Up to `POLISH_STEPS` full Newton steps after convergence, each kept only
/// if it reduces the residual by a factor 10 (so they stop at round-off).
/// They cost O(N) each and leave a solution that satisfies the discrete
/// equations to round-off, so that what remains (e.g. the director drift)
/// is discretization error rather than Newton's stopping point.
pub(super) fn polish(
    grid: &Grid,
    mut x: Vec<f64>,
    mut f: Vec<f64>,
    mut history: Vec<f64>,
    mut lin: Linearization,
    ws: &mut Scratch,
) -> NewtonOutcome {
    let iterations = history.len() - 1;
    for _ in 0..POLISH_STEPS {
        if !grid.linearize(&x, &mut lin, ws) {
            break;
        }
        let step = grid.newton_correction(&lin, &f);
        let trial: Vec<f64> = x.iter().zip(&step).map(|(a, b)| a + b).collect();
        let f_try = grid.residual(&trial);
        let norm = max_norm(&f_try);
        if norm.is_nan() || norm > 0.1 * history.last().unwrap() {
            break;
        }
        (x, f) = (trial, f_try);
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
