//! The continuation engine is generic: a problem that is not a rod — the
//! one-dimensional Bratu (Gelfand) problem u'' + λ eᵘ = 0, u(0) = u(1) = 0,
//! by central differences on n interior nodes — is continued through its
//! fold by the same engine the rod's driver steps with.
//!
//! References, both independent of the engine: the discrete problem's own
//! fold, computed by shooting on its three-term recurrence (the fold is
//! where ∂u_{n+1}/∂u_1 = 0 on the solution curve), and the continuous
//! problem's closed form λ* = θ²/(2 cosh²(θ/4)) with θ tanh(θ/4) = 4
//! (λ* = 3.513830719125…), which the discrete folds approach at the
//! measured order 2 of the scheme.

use cosserat::continuation::engine::{
    trace, ContinuationProblem, Jacobian, StepControl, TraceEnd, TraceOptions,
};
use cosserat::numerics::staircase::Border;
use nalgebra::{DMatrix, DVector};

/// The central-difference Bratu problem, scaled by h²:
/// F_i = u_{i−1} − 2u_i + u_{i+1} + h²λ e^{u_i}, u_0 = u_{n+1} = 0.
struct Bratu {
    n: usize,
}

impl Bratu {
    fn h2(&self) -> f64 {
        (1.0 / (self.n as f64 + 1.0)).powi(2)
    }
}

/// F_u dense, with LU solves (the test's problems are small).
#[derive(Clone)]
struct Dense(DMatrix<f64>);

#[derive(Default)]
struct Factors {
    plain: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    bordered: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
}

impl Jacobian for Dense {
    type Factors = Factors;

    fn factor(&self, f: &mut Factors) -> bool {
        f.plain = Some(self.0.clone().lu());
        true
    }

    fn newton_step(&self, f: &mut Factors, r: &[f64], delta: &mut [f64]) -> bool {
        let rhs = -DVector::from_column_slice(r);
        match f.plain.as_ref().and_then(|lu| lu.solve(&rhs)) {
            Some(d) => {
                delta.copy_from_slice(d.as_slice());
                true
            }
            None => false,
        }
    }

    fn factor_bordered(&self, f: &mut Factors, border: &Border) {
        let n = self.0.nrows();
        let mut a = DMatrix::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n)).copy_from(&self.0);
        for k in 0..n {
            a[(k, n)] = border.column[k];
            a[(n, k)] = border.row[k];
        }
        a[(n, n)] = border.corner;
        f.bordered = Some(a.lu());
    }

    fn solve_bordered(&self, f: &mut Factors, _: &Border, rhs: &[f64], z: &mut [f64]) -> bool {
        let rhs = DVector::from_column_slice(rhs);
        match f.bordered.as_ref().and_then(|lu| lu.solve(&rhs)) {
            Some(d) if d.iter().all(|v| v.is_finite()) => {
                z.copy_from_slice(d.as_slice());
                true
            }
            _ => false,
        }
    }
}

impl ContinuationProblem for Bratu {
    type Error = String;
    type Jacobian = Dense;

    fn size(&self) -> usize {
        self.n
    }

    fn jacobian(&self) -> Dense {
        Dense(DMatrix::zeros(self.n, self.n))
    }

    fn evaluate(
        &self,
        u: &[f64],
        p: f64,
        r: &mut DVector<f64>,
        fu: &mut Dense,
    ) -> Result<(), String> {
        let (n, h2) = (self.n, self.h2());
        fu.0.fill(0.0);
        for i in 0..n {
            let left = if i > 0 { u[i - 1] } else { 0.0 };
            let right = if i + 1 < n { u[i + 1] } else { 0.0 };
            let e = u[i].exp();
            if !e.is_finite() {
                return Err(format!("e^u overflows at u = {}", u[i]));
            }
            r[i] = left - 2.0 * u[i] + right + h2 * p * e;
            fu.0[(i, i)] = -2.0 + h2 * p * e;
            if i > 0 {
                fu.0[(i, i - 1)] = 1.0;
            }
            if i + 1 < n {
                fu.0[(i, i + 1)] = 1.0;
            }
        }
        Ok(())
    }

    fn parameter_derivative(&self, u: &[f64], _p: f64) -> Result<DVector<f64>, String> {
        let h2 = self.h2();
        Ok(DVector::from_iterator(
            self.n,
            u.iter().map(|v| h2 * v.exp()),
        ))
    }

    /// The Morse index of the energy ∫ ½u'² − λeᵘ, whose Hessian is −F_u
    /// (symmetric tridiagonal): the negative pivots of its LDLᵀ (Sylvester's
    /// law of inertia), None where a pivot vanishes.
    fn morse_index(&self, u: &[f64], p: f64) -> Option<usize> {
        let h2 = self.h2();
        let mut count = 0;
        let mut d_prev = f64::INFINITY;
        for &ui in u {
            let d = 2.0 - h2 * p * ui.exp() - 1.0 / d_prev;
            if d == 0.0 || !d.is_finite() {
                return None;
            }
            count += usize::from(d < 0.0);
            d_prev = d;
        }
        Some(count)
    }

    /// With an odd n, the middle node reaching u = 1: u_{(n+1)/2} − 1.
    fn test_functions(&self, u: &[f64], _p: f64) -> Vec<f64> {
        if self.n % 2 == 1 {
            vec![u[self.n / 2] - 1.0]
        } else {
            vec![]
        }
    }
}

/// u_{n+1} and its derivatives in a = u_1 and λ by the recurrence
/// u_{i+1} = 2u_i − u_{i−1} − h²λ e^{u_i}, u_0 = 0.
fn shoot(n: usize, a: f64, lambda: f64) -> (f64, f64, f64) {
    let h2 = (1.0 / (n as f64 + 1.0)).powi(2);
    let (mut u0, mut u1) = (0.0, a);
    let (mut a0, mut a1) = (0.0, 1.0);
    let (mut l0, mut l1) = (0.0, 0.0);
    for _ in 1..=n {
        let e = h2 * u1.exp();
        let u2 = 2.0 * u1 - u0 - lambda * e;
        let a2 = 2.0 * a1 - a0 - lambda * e * a1;
        let l2 = 2.0 * l1 - l0 - e - lambda * e * l1;
        (u0, u1, a0, a1, l0, l1) = (u1, u2, a1, a2, l1, l2);
    }
    (u1, a1, l1)
}

/// λ(a) on the discrete solution curve, by Newton in λ from `guess`.
fn lambda_at(n: usize, a: f64, guess: f64) -> f64 {
    let mut lambda = guess;
    for _ in 0..50 {
        let (u, _, du_dl) = shoot(n, a, lambda);
        let step = u / du_dl;
        lambda -= step;
        if step.abs() <= 1e-16 * lambda.abs() {
            break;
        }
    }
    lambda
}

/// The discrete fold: the maximum of λ(a), where ∂u_{n+1}/∂a = 0 on the
/// curve, bracketed on a grid in a and bisected to adjacent numbers.
fn recurrence_fold(n: usize) -> f64 {
    let g = |a: f64, guess: f64| {
        let lambda = lambda_at(n, a, guess);
        (shoot(n, a, lambda).1, lambda)
    };
    let da = 0.2 / (n as f64 + 1.0);
    let (mut a, mut lambda) = (da, 0.0_f64);
    let (mut ga, l) = g(a, 1.0);
    lambda = lambda.max(l);
    loop {
        let (gb, lb) = g(a + da, lambda);
        if ga * gb < 0.0 {
            break;
        }
        (a, ga, lambda) = (a + da, gb, lb);
    }
    let (mut lo, mut hi) = (a, a + da);
    while !cosserat::numerics::scalar::adjacent(lo, hi) {
        let mid = 0.5 * (lo + hi);
        let (gm, lm) = g(mid, lambda);
        lambda = lm;
        if gm * ga > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lambda_at(n, 0.5 * (lo + hi), lambda)
}

/// The continuous fold: θ tanh(θ/4) = 4 by Newton, λ* = θ²/(2 cosh²(θ/4)).
fn continuous_fold() -> f64 {
    let mut theta: f64 = 4.8;
    for _ in 0..50 {
        let f = theta * (theta / 4.0).tanh() - 4.0;
        let df = (theta / 4.0).tanh() + theta / (4.0 * (theta / 4.0).cosh().powi(2));
        theta -= f / df;
    }
    theta * theta / (2.0 * (theta / 4.0).cosh().powi(2))
}

fn options(bounds: (f64, f64)) -> TraceOptions {
    TraceOptions {
        step: 0.1,
        control: StepControl {
            min_step: 1e-8,
            max_step: 0.5,
        },
        bounds,
        max_points: 400,
        tolerance: 1e-12,
        direction: 1.0,
    }
}

/// The engine's fold of the n-node problem, the branch from λ = 0.1 (near
/// u = 0) through the fold down to λ = 1 on the upper branch.
fn engine_fold(n: usize) -> f64 {
    let problem = Bratu { n };
    let t = trace(&problem, vec![0.0; n], 0.1, &options((1.0, 4.0))).unwrap();
    assert_eq!(t.end, TraceEnd::ReachedBound(1.0), "n = {n}: {:?}", t.end);
    assert_eq!(t.folds.len(), 1, "n = {n}: one fold");
    t.folds[0].point.p
}

#[test]
fn the_engine_locates_the_discrete_bratu_fold() {
    for n in [16, 32, 64] {
        let located = engine_fold(n);
        let reference = recurrence_fold(n);
        eprintln!("n = {n}: engine {located:.15}, recurrence {reference:.15}");
        assert!(
            (located - reference).abs() <= 1e-10 * reference,
            "n = {n}: engine {located:.15}, recurrence {reference:.15}"
        );
    }
}

#[test]
fn the_discrete_folds_converge_at_order_two_to_the_closed_form() {
    let exact = continuous_fold();
    assert!((exact - 3.513_830_719_125_16).abs() < 1e-12, "λ* = {exact}");
    let ns = [16usize, 32, 64];
    let errors: Vec<f64> = ns.iter().map(|&n| engine_fold(n) - exact).collect();
    let h = |n: usize| 1.0 / (n as f64 + 1.0);
    for k in 0..2 {
        let order = (errors[k] / errors[k + 1]).ln() / (h(ns[k]) / h(ns[k + 1])).ln();
        eprintln!(
            "n = {}: error {:e}, order {order:.4}",
            ns[k + 1],
            errors[k + 1]
        );
        assert!(
            (order - 2.0).abs() < 0.05,
            "order {order} between n = {} and {} (errors {:e}, {:e})",
            ns[k],
            ns[k + 1],
            errors[k],
            errors[k + 1]
        );
    }
    // Richardson with the measured order 2 removes the h² term: what is
    // left is O(h⁴), far below the finest error.
    let (h1, h2) = (h(ns[1]), h(ns[2]));
    let extrapolated = exact + (errors[2] * h1 * h1 - errors[1] * h2 * h2) / (h1 * h1 - h2 * h2);
    assert!(
        (extrapolated - exact).abs() < 0.01 * errors[2].abs(),
        "extrapolated {extrapolated}, λ* {exact}, finest error {:e}",
        errors[2]
    );
}

#[test]
fn the_monitor_sees_the_lower_branch_stable_and_the_upper_unstable() {
    let problem = Bratu { n: 32 };
    let t = trace(&problem, vec![0.0; 32], 0.1, &options((1.0, 4.0))).unwrap();
    let fold = &t.folds[0];
    for (i, point) in t.points.iter().enumerate() {
        let expected = usize::from(i > fold.after);
        assert_eq!(
            point.morse_index,
            Some(expected),
            "point {i} at λ = {}",
            point.p
        );
    }
    // The branch lands exactly on its bound, on a solution there.
    let last = t.points.last().unwrap();
    assert_eq!(last.p, 1.0);
    let mut r = DVector::zeros(32);
    let mut fu = problem.jacobian();
    problem.evaluate(&last.u, 1.0, &mut r, &mut fu).unwrap();
    assert!(r.amax() < 1e-12, "residual {:e}", r.amax());
}

/// λ where the symmetric discrete solution has u = 1 at its middle node
/// m = (n + 1)/2: the recurrence marched from the middle (u_m = 1,
/// u_{m−1} = u_{m+1} = 1 − h²λe/2) to u_0(λ), bisected to u_0 = 0 below
/// the fold (on the lower branch u_m grows from 0 to ≈ 1.18 at the fold;
/// the continuous problem has u(½) = 1 at λ ≈ 3.488, the fold at 3.514).
fn middle_at_one(n: usize) -> f64 {
    let h2 = (1.0 / (n as f64 + 1.0)).powi(2);
    let m = n.div_ceil(2);
    let u0 = |lambda: f64| {
        let (mut right, mut here) = (1.0_f64, 1.0 - 0.5 * h2 * lambda * 1f64.exp());
        for _ in 1..m {
            let left = 2.0 * here - right - h2 * lambda * here.exp();
            (right, here) = (here, left);
        }
        here
    };
    let (mut lo, mut hi) = (0.1, 3.5);
    assert!(u0(lo) > 0.0 && u0(hi) < 0.0, "bracket");
    while !cosserat::numerics::scalar::adjacent(lo, hi) {
        let mid = 0.5 * (lo + hi);
        if u0(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The problem's own test function is located like a fold: the middle
/// node of n = 31 reaching 1, against the recurrence marched from the
/// middle.
#[test]
fn a_test_function_of_the_problem_is_located() {
    let n = 31;
    let problem = Bratu { n };
    let t = trace(&problem, vec![0.0; n], 0.1, &options((1.0, 4.0))).unwrap();
    assert!(t.unlocated.is_empty(), "{:?}", t.unlocated);
    assert_eq!(t.events.len(), 1, "u_mid = 1 once, below the fold");
    let event = &t.events[0];
    let reference = middle_at_one(n);
    eprintln!(
        "event at λ = {:.15}, recurrence {reference:.15}",
        event.point.p
    );
    assert!(
        (event.point.p - reference).abs() <= 1e-10 * reference,
        "event at λ = {}, recurrence {reference}",
        event.point.p
    );
    assert!((event.point.u[n / 2] - 1.0).abs() <= 1e-10);
}

/// The engine is the boundary: its sources import nothing of rods.
#[test]
fn the_engine_imports_nothing_of_rods() {
    let sources = [
        include_str!("../src/continuation/engine/mod.rs"),
        include_str!("../src/continuation/engine/corrector.rs"),
        include_str!("../src/continuation/engine/trace.rs"),
    ];
    for source in sources {
        for line in source
            .lines()
            .filter(|l| l.trim_start().starts_with("use "))
        {
            for forbidden in ["model", "equations", "bvp", "stability", "Family", "Rod"] {
                assert!(
                    !line.contains(forbidden),
                    "the engine imports {forbidden}: {line}"
                );
            }
        }
    }
}
