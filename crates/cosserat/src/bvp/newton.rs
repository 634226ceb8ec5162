//! Newton on the shooting equations: a dense [`NonlinearSystem`] (F and
//! its Jacobian from one integration with sensitivities) solved by the
//! crate's one damped Newton method, [`crate::numerics::newton`], with
//! Deuflhard's natural monotonicity damping: full steps where they bring
//! the simplified correction down, halved steps where they do not, and an
//! error that says why when it fails.
//!
//! Convergence ([`Convergence`], re-exported from the numerics layer) needs
//! both a small residual, each equation measured in its own unit, and a
//! small Newton correction, each unknown measured against its own
//! magnitude.

use nalgebra::{DMatrix, DVector};

use crate::numerics::integrator::IntegrationError;
use crate::numerics::newton::{self as numerics_newton, Damping, NewtonError, Options, System};

pub use crate::numerics::newton::Convergence;

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

/// Newton's settings for the BVP solvers (shooting and collocation);
/// [`NewtonOptions::damped`] turns them into the numerics layer's.
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

/// Why Newton stopped without converging: the numerics layer's
/// [`NewtonError`] with an integration failure as the reason a point is
/// inadmissible.
pub type NewtonFailure = NewtonError<IntegrationError>;

impl NewtonOptions {
    /// The settings of the numerics layer's Newton: these, damped by the
    /// natural monotonicity test down to `min_damping`.
    pub fn damped(&self) -> Options {
        Options {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            damping: Damping::NaturalMonotonicity {
                min_damping: self.min_damping,
            },
        }
    }
}

/// A [`NonlinearSystem`] as the numerics layer's [`System`]: F and J come
/// from one evaluation; J of the accepted iterate is factored once per
/// iteration by partial-pivoting LU and reused by the damping's simplified
/// corrections.
struct Dense<'a, S: NonlinearSystem> {
    system: &'a mut S,
    /// F of the last evaluation.
    r: DVector<f64>,
    /// J of the last evaluation (at the iterate once Newton linearizes).
    jac: DMatrix<f64>,
    /// LU of J at the current iterate.
    lu: crate::numerics::dense::DenseLu,
}

impl<S: NonlinearSystem> System for Dense<'_, S> {
    type Error = IntegrationError;

    fn size(&self) -> usize {
        self.system.size()
    }

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), IntegrationError> {
        self.system.evaluate(x, &mut self.r, &mut self.jac)?;
        r.copy_from_slice(self.r.as_slice());
        Ok(())
    }

    fn linearize(&mut self, _x: &[f64]) -> bool {
        self.lu.factor(&self.jac);
        true
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        self.lu.newton_step(f, delta)
    }

    fn unknown_scales(&self) -> Vec<f64> {
        self.system.unknown_scales()
    }
}

/// Solves F(x) = 0 from `x0` by damped Newton.
pub fn solve<S: NonlinearSystem>(
    system: &mut S,
    x0: &[f64],
    opts: &NewtonOptions,
) -> Result<NewtonReport, NewtonFailure> {
    newton_dense(system, x0, opts).map(|(report, _, _)| report)
}

/// Damped Newton with the dense LU of the system's Jacobian: the report,
/// the last correction δ (the one that passed the stopping test) and the
/// solver's state, whose LU is that of J at the root.
#[allow(clippy::type_complexity)]
fn newton_dense<'a, S: NonlinearSystem>(
    system: &'a mut S,
    x0: &[f64],
    opts: &NewtonOptions,
) -> Result<(NewtonReport, Vec<f64>, Dense<'a, S>), NewtonFailure> {
    let n = system.size();
    let mut dense = Dense {
        system,
        r: DVector::zeros(n),
        jac: DMatrix::zeros(n, n),
        lu: crate::numerics::dense::DenseLu::default(),
    };
    let mut x = x0.to_vec();
    let report = numerics_newton::solve(&mut dense, &mut x, &opts.damped())?;
    let jacobian = std::mem::replace(&mut dense.jac, DMatrix::zeros(0, 0));
    Ok((
        NewtonReport {
            x,
            iterations: report.iterations,
            history: report.history,
            damped_steps: report.damped_steps,
            contraction: report.contraction,
            jacobian,
        },
        report.correction,
        dense,
    ))
}

/// The most polishing steps [`solve_polished`] takes after convergence.
const POLISH_STEPS: usize = 2;
/// A polishing step counts only when it divides the scaled residual by at
/// least this factor: Newton's quadratic convergence does, while a step
/// within the noise of the integration (its step sequence changing with
/// x) or of round-off does not.
const POLISH_GAIN: f64 = 100.0;
/// A scaled residual at or below this is left as it is: the rounding noise
/// of a shooting residual, a sum over tens of steps of twelve stages each
/// of O(1) terms, is of this order (the cantilever at k = 10 stops at
/// 4.5e-14, and a step from there gains less than [`POLISH_GAIN`]).
const POLISH_FLOOR: f64 = 1e3 * f64::EPSILON;

/// [`solve`], then the root polished: Newton's stopping test is met as soon
/// as the residual falls below the tolerance, so where the iteration stops
/// inside the quadratic regime, and with it the root's last digits, depends
/// on the start (a ramp solved loosely leaves 1e-12 where a tight one left
/// 5e-16). Here the correction δ that passed the test is applied as long as
/// it divides the residual by 100 (at most twice, each one evaluation with
/// sensitivities), so that the root is the same to round-off whatever the
/// start: a symmetric problem's root (Greenhill's straight shaft) keeps its
/// symmetry, which continuation's branch switching relies on. A residual
/// already at its rounding noise (1000 ε) or a correction at round-off of
/// the unknowns is not polished. Polishing steps count as iterations and
/// extend the residual history.
pub fn solve_polished<S: NonlinearSystem>(
    system: &mut S,
    x0: &[f64],
    opts: &NewtonOptions,
) -> Result<NewtonReport, NewtonFailure> {
    let n = system.size();
    let (mut polished, mut delta, mut dense) = newton_dense(system, x0, opts)?;
    let test = numerics_newton::Convergence::new(opts.tolerance, dense.system.unknown_scales());
    let (mut r, mut jac) = (DVector::zeros(n), DMatrix::zeros(n, n));
    let mut trial = vec![0.0; n];
    for _ in 0..POLISH_STEPS {
        let norm = *polished.history.last().unwrap_or(&f64::NAN);
        if !(norm > POLISH_FLOOR && test.step_size(&polished.x, &delta) > 16.0 * f64::EPSILON) {
            break;
        }
        for ((t, a), d) in trial.iter_mut().zip(&polished.x).zip(&delta) {
            *t = a + d;
        }
        if dense.system.evaluate(&trial, &mut r, &mut jac).is_err() {
            break;
        }
        let trial_norm = test.residual_norm(r.as_slice());
        // False for a NaN residual too.
        let gained = trial_norm * POLISH_GAIN <= norm;
        if !gained {
            break;
        }
        polished.x.copy_from_slice(&trial);
        std::mem::swap(&mut polished.jacobian, &mut jac);
        polished.history.push(trial_norm);
        polished.iterations += 1;
        dense.lu.factor(&polished.jacobian);
        if !dense.lu.newton_step(r.as_slice(), &mut delta) {
            break;
        }
    }
    Ok(polished)
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
        assert_eq!(
            err.to_string(),
            "singular Jacobian at iteration 0 (a fold or bifurcation, or a degenerate guess)"
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
