//! The damped Newton method shared by the BVP solvers: full steps where they
//! reduce the residual, halved steps (Armijo backtracking on the residual
//! norm) where they do not, and an error that says why when it fails.
//!
//! Convergence ([`Convergence`]) needs both a small residual, each equation
//! measured in its own unit, and a small Newton correction, each unknown
//! measured against its own magnitude: a residual test alone is fooled by a
//! badly scaled equation (a stiffness of 1e10 made an unbent rod's tip
//! moment look converged), a correction test alone by an ill-conditioned
//! Jacobian; the correction is the affine-invariant measure of how far the
//! iterate is from the root (Deuflhard, *Newton Methods for Nonlinear
//! Problems*, Sec. 2.1).

use nalgebra::{DMatrix, DVector};

use crate::numerics::integrator::IntegrationError;

/// A square nonlinear system F(x) = 0 with its Jacobian. Residuals are
/// expected to be scaled so that their max-norm is dimensionless.
pub trait NonlinearSystem {
    /// Number of unknowns (and equations).
    fn size(&self) -> usize;
    /// F(x) and F'(x); an integration failure makes the point inadmissible.
    fn evaluate(
        &mut self,
        x: &[f64],
        r: &mut DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), IntegrationError>;
    /// The typical magnitude of each unknown in natural units (lengths L,
    /// curvatures 1/L, directors 1, ...): a correction counts as small when
    /// it is small against max(|x_i|, scale_i).
    fn unknown_scales(&self) -> Vec<f64> {
        vec![1.0; self.size()]
    }
}

/// Newton's stopping test: the scaled residual at most the tolerance τ and
/// the scaled correction at most √τ. The correction is first-order the
/// error of the iterate; in the quadratic regime the next one is of the
/// order of its square, so a correction above √τ means the residual test
/// was fooled (a badly scaled equation, a start on the wrong root's
/// shoulder) while one below it is consistent with a residual of τ. (Asking
/// τ of the correction itself would demand more than round-off and the
/// integrator's tolerance allow through an ill-conditioned Jacobian.)
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    tolerance: f64,
    scales: Vec<f64>,
}

impl Convergence {
    /// The test with `tolerance` τ on the residual, √τ on the correction,
    /// and the unknowns' typical magnitudes `scales` (each > 0).
    pub fn new(tolerance: f64, scales: Vec<f64>) -> Self {
        Convergence { tolerance, scales }
    }

    /// max_i |δ_i| / max(|x_i|, scale_i): the correction relative to each
    /// unknown's magnitude, floored at its natural unit.
    pub fn step_size(&self, x: &[f64], step: &[f64]) -> f64 {
        x.iter()
            .zip(step)
            .zip(&self.scales)
            .map(|((xi, di), si)| di.abs() / xi.abs().max(*si))
            .fold(0.0, |m, v| if v.is_nan() { f64::NAN } else { m.max(v) })
    }

    /// Whether the residual (max-norm, already scaled per equation) is small
    /// enough that a correction is worth testing.
    pub fn residual_met(&self, residual: f64) -> bool {
        residual <= self.tolerance
    }

    /// Both measures met.
    pub fn met(&self, residual: f64, x: &[f64], step: &[f64]) -> bool {
        self.residual_met(residual) && self.step_size(x, step) <= self.tolerance.sqrt()
    }
}

/// Newton's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Converged when the max-norm of the scaled residual is at most this
    /// and the largest Newton correction relative to its unknown at most its
    /// square root ([`Convergence`]).
    pub tolerance: f64,
    /// Maximum number of Newton steps.
    pub max_iterations: usize,
    /// Smallest damping factor tried before giving up.
    pub min_damping: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tolerance: 1e-10,
            max_iterations: 50,
            min_damping: 1.0 / 1024.0,
        }
    }
}

/// The outcome of a converged Newton iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonReport {
    /// The solution.
    pub x: Vec<f64>,
    /// Newton steps taken.
    pub iterations: usize,
    /// Scaled residual (max-norm) at every iterate, the last at the solution.
    pub history: Vec<f64>,
    /// Steps that needed damping.
    pub damped_steps: usize,
    /// The largest ratio ‖δ_{k+1}‖/‖δ_k‖ of successive Newton corrections
    /// (Deuflhard's contraction Θ); well below 1 inside the region of
    /// quadratic convergence, near or above 1 when an iterate wandered.
    pub contraction: f64,
    /// The Jacobian at the solution (reused by stability and continuation).
    pub jacobian: DMatrix<f64>,
}

/// Why Newton stopped without converging.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NewtonFailure {
    /// The first evaluation already failed.
    #[error("the initial guess is inadmissible: {0}")]
    BadStart(IntegrationError),
    /// The Jacobian could not be factored.
    #[error(
        "singular Jacobian at iteration {iteration} (a fold or bifurcation, or a degenerate guess)"
    )]
    SingularJacobian {
        /// The iteration whose Jacobian could not be factored.
        iteration: usize,
        /// Scaled residual (max-norm) at every iterate so far.
        history: Vec<f64>,
    },
    /// No damped step reduced the residual.
    #[error("no damped step (down to λ = {min_damping}) passed the natural monotonicity test at iteration {iteration}; last trial: {last_trial}")]
    LineSearch {
        /// The iteration whose damped steps all failed.
        iteration: usize,
        /// The smallest damping factor λ tried.
        min_damping: f64,
        /// The last trial step's outcome, in words.
        last_trial: String,
        /// Scaled residual (max-norm) at every iterate so far.
        history: Vec<f64>,
    },
    /// The iteration budget ran out.
    #[error("{iterations} iterations without reaching the tolerance")]
    IterationLimit {
        /// The iteration budget.
        iterations: usize,
        /// Scaled residual (max-norm) at every iterate.
        history: Vec<f64>,
    },
}

impl NewtonFailure {
    /// The residual history up to the failure.
    pub fn history(&self) -> &[f64] {
        match self {
            NewtonFailure::BadStart(_) => &[],
            NewtonFailure::SingularJacobian { history, .. }
            | NewtonFailure::LineSearch { history, .. }
            | NewtonFailure::IterationLimit { history, .. } => history,
        }
    }
}

fn max_norm(r: &DVector<f64>) -> f64 {
    r.iter().fold(
        0.0,
        |m, v| if v.is_nan() { f64::NAN } else { m.max(v.abs()) },
    )
}

/// Solves F(x) = 0 from `x0` by damped Newton.
pub fn solve<S: NonlinearSystem>(
    system: &mut S,
    x0: &[f64],
    opts: &NewtonOptions,
) -> Result<NewtonReport, NewtonFailure> {
    let n = system.size();
    let mut x = x0.to_vec();
    let (mut r, mut jac) = (DVector::zeros(n), DMatrix::zeros(n, n));
    system
        .evaluate(&x, &mut r, &mut jac)
        .map_err(NewtonFailure::BadStart)?;
    let (mut r_try, mut jac_try) = (DVector::zeros(n), DMatrix::zeros(n, n));
    let mut history = vec![max_norm(&r)];
    let test = Convergence::new(opts.tolerance, system.unknown_scales());
    let mut damped_steps = 0;
    let (mut contraction, mut last_step_norm) = (0.0_f64, f64::NAN);
    for iteration in 0..=opts.max_iterations {
        let norm = *history.last().unwrap();
        let lu = jac.clone().lu();
        let step = lu.solve(&(-&r)).filter(|d| d.iter().all(|v| v.is_finite()));
        if let Some(step) = &step {
            if test.met(norm, &x, step.as_slice()) {
                return Ok(NewtonReport {
                    x,
                    iterations: iteration,
                    history,
                    damped_steps,
                    contraction,
                    jacobian: jac,
                });
            }
        }
        if iteration == opts.max_iterations {
            break;
        }
        let Some(step) = step else {
            return Err(NewtonFailure::SingularJacobian { iteration, history });
        };
        // Affine-invariant damping (Deuflhard's natural monotonicity test):
        // accept λ when the simplified Newton correction at the trial point,
        // ‖J(x)⁻¹F(x + λδ)‖, is smaller than (1 − λ/4)‖δ‖. Unlike the
        // residual norm, this level function is invariant under scaling of
        // the equations, so multiple shooting does not stall in spurious
        // minima of ‖F‖.
        let step_norm = step.norm();
        if last_step_norm > 0.0 {
            contraction = contraction.max(step_norm / last_step_norm);
        }
        last_step_norm = step_norm;
        let mut lambda = 1.0;
        loop {
            let trial: Vec<f64> = x
                .iter()
                .zip(step.iter())
                .map(|(a, b)| a + lambda * b)
                .collect();
            let outcome = system.evaluate(&trial, &mut r_try, &mut jac_try);
            let accepted = match &outcome {
                Ok(()) => lu
                    .solve(&r_try)
                    .is_some_and(|c| c.norm() <= (1.0 - 0.25 * lambda) * step_norm),
                Err(_) => false,
            };
            if accepted {
                x = trial;
                std::mem::swap(&mut r, &mut r_try);
                std::mem::swap(&mut jac, &mut jac_try);
                break;
            }
            lambda *= 0.5;
            if lambda < opts.min_damping {
                let last_trial = match outcome {
                    Ok(()) => format!("scaled residual {:.3e}", max_norm(&r_try)),
                    Err(e) => e.to_string(),
                };
                return Err(NewtonFailure::LineSearch {
                    iteration,
                    min_damping: opts.min_damping,
                    last_trial,
                    history,
                });
            }
        }
        if lambda < 1.0 {
            damped_steps += 1;
        }
        history.push(max_norm(&r));
    }
    Err(NewtonFailure::IterationLimit {
        iterations: opts.max_iterations,
        history,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x² = 2 from far away, with damping.
    struct Sqrt2;
    impl NonlinearSystem for Sqrt2 {
        fn size(&self) -> usize {
            1
        }
        fn evaluate(
            &mut self,
            x: &[f64],
            r: &mut DVector<f64>,
            j: &mut DMatrix<f64>,
        ) -> Result<(), IntegrationError> {
            r[0] = x[0] * x[0] - 2.0;
            j[(0, 0)] = 2.0 * x[0];
            Ok(())
        }
    }

    #[test]
    fn converges_quadratically_to_sqrt2() {
        let rep = solve(&mut Sqrt2, &[100.0], &NewtonOptions::default()).unwrap();
        assert!((rep.x[0] - 2f64.sqrt()).abs() < 1e-12);
        let h = &rep.history;
        let n = h.len();
        // quadratic convergence: e_{k+1} ≈ e_k² / (2√2)
        assert!(h[n - 1] <= 1e-10 && h[n - 2] < 1e-3);
    }

    #[test]
    fn singular_jacobian_is_reported() {
        let err = solve(&mut Sqrt2, &[0.0], &NewtonOptions::default()).unwrap_err();
        assert!(
            matches!(err, NewtonFailure::SingularJacobian { .. }),
            "{err}"
        );
    }

    #[test]
    fn iteration_cap_is_reported() {
        let opts = NewtonOptions {
            max_iterations: 1,
            ..Default::default()
        };
        let err = solve(&mut Sqrt2, &[100.0], &opts).unwrap_err();
        assert!(matches!(err, NewtonFailure::IterationLimit { .. }), "{err}");
    }
}
