//! The damped Newton method shared by the BVP solvers: full steps where they
//! reduce the residual, halved steps (Armijo backtracking on the residual
//! norm) where they do not, and an error that says why when it fails.

use nalgebra::{DMatrix, DVector};

use super::integrator::IntegrationError;

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
}

/// Newton's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Converged when the max-norm of the scaled residual is at most this.
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
    SingularJacobian { iteration: usize, history: Vec<f64> },
    /// No damped step reduced the residual.
    #[error("no damped step (down to λ = {min_damping}) passed the natural monotonicity test at iteration {iteration}; last trial: {last_trial}")]
    LineSearch {
        iteration: usize,
        min_damping: f64,
        last_trial: String,
        history: Vec<f64>,
    },
    /// The iteration budget ran out.
    #[error("{iterations} iterations without reaching the tolerance")]
    IterationLimit {
        iterations: usize,
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
    let mut damped_steps = 0;
    let (mut contraction, mut last_step_norm) = (0.0_f64, f64::NAN);
    for iteration in 0..=opts.max_iterations {
        let norm = *history.last().unwrap();
        if norm <= opts.tolerance {
            return Ok(NewtonReport {
                x,
                iterations: iteration,
                history,
                damped_steps,
                contraction,
                jacobian: jac,
            });
        }
        if iteration == opts.max_iterations {
            break;
        }
        let lu = jac.clone().lu();
        let Some(step) = lu.solve(&(-&r)) else {
            return Err(NewtonFailure::SingularJacobian { iteration, history });
        };
        if step.iter().any(|v| !v.is_finite()) {
            return Err(NewtonFailure::SingularJacobian { iteration, history });
        }
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
