//! Newton on small closed-form systems: x² = 2 to machine precision with
//! quadratic convergence read off the residual history, damping from far
//! away, every failure named, and a badly scaled system under the scaled
//! test.

use super::*;
use nalgebra::DMatrix;

/// A dense test system: F and J from a closure, J factored by LU.
struct Dense<F> {
    n: usize,
    f: F,
    jac: DMatrix<f64>,
    lu: crate::numerics::dense::DenseLu,
    rows: Vec<f64>,
    evaluations: usize,
}

impl<F> Dense<F>
where
    F: FnMut(&[f64], &mut [f64], &mut DMatrix<f64>) -> Result<(), &'static str>,
{
    fn new(n: usize, f: F) -> Self {
        Dense {
            n,
            f,
            jac: DMatrix::zeros(n, n),
            lu: crate::numerics::dense::DenseLu::default(),
            rows: vec![1.0; n],
            evaluations: 0,
        }
    }
}

impl<F> System for Dense<F>
where
    F: FnMut(&[f64], &mut [f64], &mut DMatrix<f64>) -> Result<(), &'static str>,
{
    type Error = &'static str;
    fn size(&self) -> usize {
        self.n
    }
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Self::Error> {
        self.evaluations += 1;
        (self.f)(x, r, &mut self.jac)
    }
    fn linearize(&mut self, _x: &[f64]) -> bool {
        self.lu.factor(&self.jac);
        true
    }
    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        self.lu.newton_step(f, delta)
    }
    fn residual_scales(&self) -> Vec<f64> {
        self.rows.clone()
    }
}

fn damped(tolerance: f64) -> Options {
    Options {
        tolerance,
        max_iterations: 50,
        damping: Damping::NaturalMonotonicity {
            min_damping: 1.0 / 1024.0,
        },
    }
}

fn full(tolerance: f64) -> Options {
    Options {
        damping: Damping::Full,
        ..damped(tolerance)
    }
}

/// A residual that always evaluates, as the fallible kind [`Dense`] takes.
fn infallible(
    f: fn(&[f64], &mut [f64], &mut DMatrix<f64>),
) -> impl FnMut(&[f64], &mut [f64], &mut DMatrix<f64>) -> Result<(), &'static str> {
    move |x, r, j| {
        f(x, r, j);
        Ok(())
    }
}

/// F(x) = x² − 2.
fn sqrt2(x: &[f64], r: &mut [f64], j: &mut DMatrix<f64>) {
    r[0] = x[0] * x[0] - 2.0;
    j[(0, 0)] = 2.0 * x[0];
}

#[test]
fn sqrt2_to_machine_precision_with_quadratic_convergence() {
    let root = 2f64.sqrt();
    let mut x = [1.0];
    let rep = solve(&mut Dense::new(1, infallible(sqrt2)), &mut x, &full(1e-15)).unwrap();
    assert!((x[0] - root).abs() <= f64::EPSILON * root, "{}", x[0]);
    // F_{k+1} = δ_k² = (F_k / 2x_k)², so F_{k+1}/F_k² → 1/(4·2) = 1/8:
    // quadratic convergence, read off the residual history while it is
    // above round-off.
    let h = &rep.history;
    let mut measured = 0;
    for k in 0..h.len() - 1 {
        if h[k] < 0.1 && h[k + 1] > 1e-13 {
            let ratio = h[k + 1] / (h[k] * h[k]);
            assert!(
                (ratio - 0.125).abs() < 0.02,
                "F_{{k+1}}/F_k² = {ratio} at {k}"
            );
            measured += 1;
        }
    }
    assert!(measured >= 2, "{h:?}");
    assert!(*h.last().unwrap() <= 1e-15 && rep.iterations <= 6, "{h:?}");
    assert_eq!(rep.damped_steps, 0);
    assert!(rep.correction[0].abs() <= 1e-15);
}

#[test]
fn damping_brings_newton_home_from_far_away() {
    // arctan x = 0: plain Newton from 10 overshoots and diverges
    // (|x₀| > 1.39), damped Newton converges.
    let atan = |x: &[f64], r: &mut [f64], j: &mut DMatrix<f64>| {
        r[0] = x[0].atan();
        j[(0, 0)] = 1.0 / (1.0 + x[0] * x[0]);
        Ok(())
    };
    let mut x = [10.0];
    let rep = solve(&mut Dense::new(1, atan), &mut x, &damped(1e-12)).unwrap();
    assert!(x[0].abs() < 1e-12 && rep.damped_steps > 0, "{x:?} {rep:?}");
    let mut x = [10.0];
    assert!(solve(&mut Dense::new(1, atan), &mut x, &full(1e-12)).is_err());
}

#[test]
fn singular_jacobian_is_named_not_a_value() {
    let mut x = [0.0];
    let err = solve(
        &mut Dense::new(1, infallible(sqrt2)),
        &mut x,
        &damped(1e-12),
    )
    .unwrap_err();
    assert!(
        matches!(err, NewtonError::SingularJacobian { iteration: 0, .. }),
        "{err}"
    );
    assert_eq!(x, [0.0]);
    // A 2 × 2 linear system with a rank-one matrix.
    let rank_one = |x: &[f64], r: &mut [f64], j: &mut DMatrix<f64>| {
        r[0] = x[0] + 2.0 * x[1] - 1.0;
        r[1] = 2.0 * x[0] + 4.0 * x[1] - 3.0;
        j.copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        Ok(())
    };
    let mut x = [0.0, 0.0];
    let err = solve(&mut Dense::new(2, rank_one), &mut x, &full(1e-12)).unwrap_err();
    assert!(matches!(err, NewtonError::SingularJacobian { .. }), "{err}");
}

#[test]
fn a_full_step_out_of_the_domain_is_named() {
    // F(x) = √x − ½, defined for x ≥ 0: the full step from 4 lands at −2.
    let root = |x: &[f64], r: &mut [f64], j: &mut DMatrix<f64>| {
        if x[0] < 0.0 {
            return Err("negative x");
        }
        r[0] = x[0].sqrt() - 0.5;
        j[(0, 0)] = 0.5 / x[0].sqrt();
        Ok(())
    };
    let mut x = [4.0];
    let err = solve(&mut Dense::new(1, root), &mut x, &full(1e-12)).unwrap_err();
    assert!(
        matches!(
            err,
            NewtonError::Evaluation {
                iteration: 0,
                error: "negative x",
                ..
            }
        ),
        "{err}"
    );
    assert_eq!(x, [4.0], "x keeps the last admissible iterate");
    let mut x = [4.0];
    solve(&mut Dense::new(1, root), &mut x, &damped(1e-14)).unwrap();
    assert!((x[0] - 0.25).abs() < 1e-14);
    let mut x = [-1.0];
    let err = solve(&mut Dense::new(1, root), &mut x, &damped(1e-14)).unwrap_err();
    assert_eq!(err, NewtonError::BadStart("negative x"));
}

#[test]
fn line_search_and_iteration_limit_are_named() {
    // x² + 1 = 0 has no real root: damping cannot help.
    let no_root = |x: &[f64], r: &mut [f64], j: &mut DMatrix<f64>| {
        r[0] = x[0] * x[0] + 1.0;
        j[(0, 0)] = 2.0 * x[0];
        Ok(())
    };
    let mut x = [0.3];
    let err = solve(&mut Dense::new(1, no_root), &mut x, &damped(1e-12)).unwrap_err();
    assert!(matches!(err, NewtonError::LineSearch { .. }), "{err}");
    assert!(err.to_string().contains("last trial: scaled residual"));
    let opts = Options {
        max_iterations: 1,
        ..damped(1e-12)
    };
    let mut x = [100.0];
    let err = solve(&mut Dense::new(1, infallible(sqrt2)), &mut x, &opts).unwrap_err();
    assert!(
        matches!(err, NewtonError::IterationLimit { iterations: 1, ref history } if history.len() == 2),
        "{err}"
    );
}

/// Row 0 in units of 1e9 (a stiffness), row 1 in units of 1e−9.
fn badly_scaled(x: &[f64], r: &mut [f64], j: &mut DMatrix<f64>) {
    r[0] = 1e9 * (x[0] * x[0] - 2.0);
    r[1] = 1e-9 * (x[1] * x[1] * x[1] - 8.0);
    j.fill(0.0);
    j[(0, 0)] = 2e9 * x[0];
    j[(1, 1)] = 3e-9 * x[1] * x[1];
}

#[test]
fn a_badly_scaled_system_converges_under_the_scaled_test() {
    let mut sys = Dense::new(2, infallible(badly_scaled));
    sys.rows = vec![1e9, 1e-9];
    let mut x = [1.0, 1.0];
    let rep = solve(&mut sys, &mut x, &damped(1e-14)).unwrap();
    assert!((x[0] - 2f64.sqrt()).abs() <= 2.0 * f64::EPSILON, "{x:?}");
    assert!((x[1] - 2.0).abs() <= 4.0 * f64::EPSILON, "{x:?}");
    assert!(*rep.history.last().unwrap() <= 1e-14);
    // Unscaled, row 0 cannot get below its round-off 1e9 · 4e−16 = 4e−7:
    // Newton runs into round-off without ever meeting the test.
    let mut x = [1.0, 1.0];
    let err = solve(
        &mut Dense::new(2, infallible(badly_scaled)),
        &mut x,
        &damped(1e-14),
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            NewtonError::LineSearch { .. } | NewtonError::IterationLimit { .. }
        ),
        "{err}"
    );
    assert!(err.history().iter().all(|&h| h > 1e-7), "{err:?}");
}

#[test]
fn the_correction_test_is_not_fooled_by_a_tiny_residual() {
    // Row 1 alone is below τ at x₀ = (√2, 1), yet x₁ is far from 2: the
    // correction test keeps Newton going.
    let mut x = [2f64.sqrt(), 1.0];
    let mut sys = Dense::new(2, infallible(badly_scaled));
    sys.rows = vec![1e9, 1.0];
    let tolerance: f64 = 1e-7;
    let rep = solve(&mut sys, &mut x, &damped(tolerance)).unwrap();
    // Converged to the correction test: the error is below √τ relative.
    assert!(rep.iterations > 0, "{rep:?}");
    assert!((x[1] - 2.0).abs() <= 2.0 * tolerance.sqrt(), "{x:?}");
}

#[test]
fn residual_norm_is_the_scaled_max_norm() {
    let t = Convergence::new(1e-10, vec![1.0; 2]);
    assert_eq!(t.residual_norm(&[-3.0, 2.0]), 3.0);
    assert!(t.residual_norm(&[0.0, f64::NAN]).is_nan());
    assert!(!t.residual_met(f64::NAN));
    let t = t.with_residual_scales(vec![2.0, 4.0]);
    assert_eq!(t.residual_norm(&[1.0, -4.0]), 1.0);
}
