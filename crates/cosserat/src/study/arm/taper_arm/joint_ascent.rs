//! Projected quasi-Newton ascent over a box with one linear equality: the
//! joint optimization of a tapered arm's shape and section (the shape's
//! box, the section's lower bound A ≥ A_min and its volume Σ V_j a_j = 1).
//!
//! The feasible set Ω = {lo ≤ x ≤ hi, wᵀx = b} (w ≥ 0) is convex, and its
//! Euclidean projection is x_i(μ) = clamp(y_i − μ w_i, lo_i, hi_i) with μ
//! the root of the piecewise-linear, non-increasing wᵀx(μ) − b, found
//! exactly between its breakpoints ([`Feasible::project`]). Each iteration
//! of the ascent:
//!
//! - holds the variables at a bound that the projected gradient step
//!   P(x + τg) − x, τ → 0, leaves there (the multiplier of the equality is
//!   part of the projection, so this is the KKT sign test);
//! - takes the quasi-Newton step of the reduced problem on the free
//!   variables F with the equality kept, d_F = B_FF⁻¹(g_F − ν w_F),
//!   ν = w_Fᵀ B_FF⁻¹ g_F / w_Fᵀ B_FF⁻¹ w_F (so that w_Fᵀ d_F = 0), holding
//!   too any free variable on a bound that d would push out;
//! - searches along the projected path P(x + t d) with Armijo's condition
//!   (Bertsekas 1982, projected Newton methods; Nocedal & Wright,
//!   *Numerical Optimization*, 2006, Sec. 16.7);
//! - updates the BFGS model B of −f's Hessian where sᵀy > 0 (s ⟂ w, so the
//!   equality's multiplier does not enter the curvature).
//!
//! It stops when the projected-gradient norm max_i |x_i − P(x + g)_i| —
//! zero exactly at a KKT point of Ω — is at most `tolerance` × |f|.

use nalgebra::{DMatrix, DVector};

use crate::study::arm::polish::{bfgs_update, initial_hessian};

/// Distance (relative to the bound, absolute below 1) within which a
/// variable counts as on its bound.
const BOUND_SLACK: f64 = 1e-12;

/// A value and, where it exists, its gradient.
pub type Slope = (f64, Option<Vec<f64>>);

/// The feasible set {lo ≤ x ≤ hi, wᵀx = b}: checked by [`Feasible::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct Feasible {
    lower: Vec<f64>,
    upper: Vec<f64>,
    weights: Vec<f64>,
    total: f64,
}

impl Feasible {
    /// The box [lower, upper] (upper may be +∞) cut by wᵀx = total; None
    /// unless the lengths agree, lo ≤ hi, w ≥ 0 with some w_i > 0 (else
    /// the box alone: pass `weights` all zero and any total), and some
    /// point of the box meets the equality.
    pub fn new(lower: Vec<f64>, upper: Vec<f64>, weights: Vec<f64>, total: f64) -> Option<Self> {
        let n = lower.len();
        if upper.len() != n || weights.len() != n {
            return None;
        }
        let ordered = lower
            .iter()
            .zip(&upper)
            .all(|(l, u)| l <= u && l.is_finite());
        if !ordered || weights.iter().any(|w| !(*w >= 0.0 && w.is_finite())) {
            return None;
        }
        let f = Feasible {
            lower,
            upper,
            weights,
            total,
        };
        if f.constrained() {
            let least: f64 = f.weights.iter().zip(&f.lower).map(|(w, l)| w * l).sum();
            let most: f64 = f
                .weights
                .iter()
                .zip(&f.upper)
                .map(|(w, u)| if *w > 0.0 { w * u } else { 0.0 })
                .sum();
            if !(least <= total && total <= most) {
                return None;
            }
        }
        Some(f)
    }

    fn constrained(&self) -> bool {
        self.weights.iter().any(|w| *w > 0.0)
    }

    /// The Euclidean projection of y onto the set (module doc).
    pub fn project(&self, y: &[f64]) -> Vec<f64> {
        let at = |mu: f64| -> Vec<f64> {
            y.iter()
                .zip(&self.weights)
                .zip(self.lower.iter().zip(&self.upper))
                .map(|((v, w), (l, u))| (v - mu * w).clamp(*l, *u))
                .collect()
        };
        if !self.constrained() {
            return at(0.0);
        }
        let excess = |mu: f64| -> f64 {
            at(mu)
                .iter()
                .zip(&self.weights)
                .map(|(x, w)| x * w)
                .sum::<f64>()
                - self.total
        };
        // Breakpoints of the piecewise-linear excess(μ), non-increasing.
        let mut kinks: Vec<f64> = y
            .iter()
            .zip(&self.weights)
            .zip(self.lower.iter().zip(&self.upper))
            .filter(|((_, w), _)| **w > 0.0)
            .flat_map(|((v, w), (l, u))| [(v - l) / w, (v - u) / w])
            .filter(|m| m.is_finite())
            .collect();
        kinks.sort_by(f64::total_cmp);
        kinks.dedup();
        // excess ≤ 0 at the largest kink (everything at its lower bound,
        // and the set is not empty); below the smallest, every variable
        // with a finite upper bound is at it and the others are free, so
        // excess falls there with slope −Σ w_i² over the unbounded.
        let values: Vec<f64> = kinks.iter().map(|m| excess(*m)).collect();
        let k = values
            .iter()
            .position(|e| *e <= 0.0)
            .unwrap_or(kinks.len() - 1);
        if values[k] == 0.0 {
            return at(kinks[k]);
        }
        if k == 0 {
            let slope: f64 = self
                .weights
                .iter()
                .zip(&self.upper)
                .filter(|(w, u)| **w > 0.0 && u.is_infinite())
                .map(|(w, _)| w * w)
                .sum();
            if slope == 0.0 {
                return at(kinks[0]);
            }
            return at(kinks[0] + values[0] / slope);
        }
        // Linear on [kinks[k − 1], kinks[k]]: its root.
        let (m0, m1) = (kinks[k - 1], kinks[k]);
        let (e0, e1) = (values[k - 1], values[k]);
        at(m0 + (m1 - m0) * e0 / (e0 - e1))
    }

    /// max_i |x_i − P(x + g)_i|: zero exactly at a KKT point.
    pub fn projected_gradient(&self, x: &[f64], g: &[f64]) -> f64 {
        let step: Vec<f64> = x.iter().zip(g).map(|(a, b)| a + b).collect();
        self.project(&step)
            .iter()
            .zip(x)
            .map(|(p, a)| (p - a).abs())
            .fold(0.0, f64::max)
    }

    /// The variables on a bound that an infinitesimal projected gradient
    /// step leaves there or pushes against it (module doc).
    fn held(&self, x: &[f64], g: &[f64]) -> Vec<bool> {
        let largest = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let tau = if largest > 0.0 { 1e-9 / largest } else { 1.0 };
        let step: Vec<f64> = x.iter().zip(g).map(|(a, b)| a + tau * b).collect();
        let p = self.project(&step);
        (0..x.len())
            .map(|i| (self.at_lower(x, i) && p[i] <= x[i]) || (self.at_upper(x, i) && p[i] >= x[i]))
            .collect()
    }

    /// Whether x_i is on its bound, to [`BOUND_SLACK`]: the projection puts
    /// a variable within rounding of its bound, and a step that pushed such
    /// a variable out would be bent by the projection for every step size
    /// (no ascent along the projected path however short).
    fn at_lower(&self, x: &[f64], i: usize) -> bool {
        x[i] <= self.lower[i] + BOUND_SLACK * self.lower[i].abs().max(1.0)
    }

    fn at_upper(&self, x: &[f64], i: usize) -> bool {
        x[i] >= self.upper[i] - BOUND_SLACK * self.upper[i].abs().max(1.0)
    }
}

/// How a joint ascent ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointEnd {
    /// The projected gradient is below the tolerance × |f|.
    Converged,
    /// The line search found no increase along an ascent direction: flat
    /// to round-off there (as converged as the arithmetic tells).
    Flat,
    /// The accepted point has no gradient (a double critical load).
    NoGradient,
    /// The iteration cap was reached.
    Capped,
    /// `stop()` turned true.
    Stopped,
    /// The start has no value.
    Infeasible,
}

impl JointEnd {
    /// The name in reports and result files.
    pub fn name(self) -> &'static str {
        match self {
            JointEnd::Converged => "converged",
            JointEnd::Flat => "flat",
            JointEnd::NoGradient => "no_gradient",
            JointEnd::Capped => "capped",
            JointEnd::Stopped => "stopped",
            JointEnd::Infeasible => "infeasible",
        }
    }
}

/// The result of [`ascend`].
#[derive(Debug, Clone, PartialEq)]
pub struct JointAscent {
    /// The best point reached (feasible) and its value.
    pub best: Option<(Vec<f64>, f64)>,
    /// Its projected-gradient norm (NaN without a gradient).
    pub projected_gradient: f64,
    /// Evaluations (value and gradient) used.
    pub evaluations: usize,
    /// Quasi-Newton iterations taken.
    pub iterations: usize,
    /// Why it ended.
    pub end: JointEnd,
}

/// Maximizes `slope`'s value over `feasible` from `start` (projected onto
/// it) by the projected BFGS of the module doc, at most `iterations`
/// steps, until the projected gradient is at most `tolerance` × |f|.
/// `scales` are the variables' typical ranges (the first step moves none
/// by more than 5 % of its own).
pub fn ascend(
    start: &[f64],
    feasible: &Feasible,
    scales: &[f64],
    (iterations, tolerance): (usize, f64),
    slope: &dyn Fn(&[f64]) -> Option<Slope>,
    stop: &dyn Fn() -> bool,
) -> JointAscent {
    let mut run = JointAscent {
        best: None,
        projected_gradient: f64::NAN,
        evaluations: 0,
        iterations: 0,
        end: JointEnd::Infeasible,
    };
    let mut x = feasible.project(start);
    if stop() {
        run.end = JointEnd::Stopped;
        return run;
    }
    run.evaluations += 1;
    let Some((mut f, gradient)) = slope(&x) else {
        return run;
    };
    run.best = Some((x.clone(), f));
    let Some(mut g) = gradient else {
        run.end = JointEnd::NoGradient;
        return run;
    };
    let mut hessian = initial_hessian(scales, &g);
    // Whether the model is the first diagonal (a scaled projected
    // gradient step), where a failed line search means flat indeed.
    let mut fresh = true;
    loop {
        run.projected_gradient = feasible.projected_gradient(&x, &g);
        if run.projected_gradient <= tolerance * f.abs() {
            run.end = JointEnd::Converged;
            return run;
        }
        if run.iterations >= iterations {
            run.end = JointEnd::Capped;
            return run;
        }
        run.iterations += 1;
        let d = direction(feasible, &mut hessian, scales, &x, &g);
        let Some((next, fnext, gnext)) =
            line_search(feasible, &x, f, &g, &d, slope, stop, &mut run)
        else {
            if run.end == JointEnd::Stopped {
                return run;
            }
            if fresh {
                run.end = JointEnd::Flat;
                return run;
            }
            // The model's direction found no rise (an ill-conditioned
            // model after steps across bounds): start it again.
            hessian = initial_hessian(scales, &g);
            fresh = true;
            continue;
        };
        fresh = false;
        run.best = Some((next.clone(), fnext));
        let Some(gnext) = gnext else {
            run.projected_gradient = f64::NAN;
            run.end = JointEnd::NoGradient;
            return run;
        };
        // Minimizing −f: s = Δx, y = −Δg.
        let s: Vec<f64> = next.iter().zip(&x).map(|(a, b)| a - b).collect();
        let y: Vec<f64> = g.iter().zip(&gnext).map(|(a, b)| a - b).collect();
        bfgs_update(&mut hessian, &s, &y);
        (x, f, g) = (next, fnext, gnext);
    }
}

/// The ascent direction at x (module doc), the model reset to its first
/// diagonal where it gives none.
fn direction(
    feasible: &Feasible,
    hessian: &mut DMatrix<f64>,
    scales: &[f64],
    x: &[f64],
    g: &[f64],
) -> Vec<f64> {
    let mut held = feasible.held(x, g);
    loop {
        let d = match reduced_step(hessian, g, &feasible.weights, &held) {
            Some(d) if dot(&d, g) > 0.0 => d,
            _ => {
                *hessian = initial_hessian(scales, g);
                reduced_step(hessian, g, &feasible.weights, &held)
                    .expect("a positive diagonal is positive definite")
            }
        };
        // A free variable on its bound that d pushes out is held too (its
        // move would be clipped and teach the update a false curvature).
        let outward: Vec<usize> = (0..x.len())
            .filter(|&i| {
                !held[i]
                    && ((feasible.at_lower(x, i) && d[i] < 0.0)
                        || (feasible.at_upper(x, i) && d[i] > 0.0))
            })
            .collect();
        if outward.is_empty() {
            return d;
        }
        for i in outward {
            held[i] = true;
        }
    }
}

/// Armijo backtracking along P(x + t d): the accepted point, its value and
/// gradient; None when t falls below 10⁻¹² or `stop()` turns true (then
/// `run.end` says so).
#[allow(clippy::too_many_arguments)]
fn line_search(
    feasible: &Feasible,
    x: &[f64],
    f: f64,
    g: &[f64],
    d: &[f64],
    slope: &dyn Fn(&[f64]) -> Option<Slope>,
    stop: &dyn Fn() -> bool,
    run: &mut JointAscent,
) -> Option<(Vec<f64>, f64, Option<Vec<f64>>)> {
    let mut t = 1.0;
    while t >= 1e-12 {
        if stop() {
            run.end = JointEnd::Stopped;
            return None;
        }
        let trial = feasible.project(&x.iter().zip(d).map(|(a, b)| a + t * b).collect::<Vec<_>>());
        let moved: Vec<f64> = trial.iter().zip(x).map(|(a, b)| a - b).collect();
        let rise = dot(&moved, g);
        run.evaluations += 1;
        if let Some((ft, gt)) = slope(&trial) {
            // Armijo, and a strict rise: at the reach's round-off an equal
            // value is no progress (the ascent would loop in place).
            if ft >= f + 1e-4 * rise && ft > f {
                return Some((trial, ft, gt));
            }
        }
        t *= 0.5;
    }
    None
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// d_F = B_FF⁻¹(g_F − ν w_F) with w_Fᵀ d_F = 0, zero on the held
/// variables; None where B_FF is not positive definite (by round-off).
fn reduced_step(
    hessian: &DMatrix<f64>,
    g: &[f64],
    weights: &[f64],
    held: &[bool],
) -> Option<Vec<f64>> {
    let free: Vec<usize> = (0..g.len()).filter(|&i| !held[i]).collect();
    let reduced = DMatrix::from_fn(free.len(), free.len(), |i, j| hessian[(free[i], free[j])]);
    let factor = reduced.cholesky()?;
    let gf = DVector::from_iterator(free.len(), free.iter().map(|&i| g[i]));
    let wf = DVector::from_iterator(free.len(), free.iter().map(|&i| weights[i]));
    let mut step = factor.solve(&gf);
    if wf.iter().any(|w| *w > 0.0) {
        let bw = factor.solve(&wf);
        let nu = wf.dot(&step) / wf.dot(&bw);
        step -= bw * nu;
    }
    let mut d = vec![0.0; g.len()];
    for (k, &i) in free.iter().enumerate() {
        d[i] = step[k];
    }
    Some(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The projection onto a box cut by a plane against its closed form:
    /// y = (0.9, 0.5, −0.2, 3), w = (1, 1, 1, 0), b = 1, x ≥ 0.05, the last
    /// in [−1, 1]: x_i = max(0.05, y_i − μ) with μ = 0.225 (the third at
    /// its bound: 0.9 − μ + 0.5 − μ + 0.05 = 1), the last clamped to 1.
    #[test]
    fn projection_meets_its_closed_form() {
        let f = Feasible::new(
            vec![0.05, 0.05, 0.05, -1.0],
            vec![f64::INFINITY, f64::INFINITY, f64::INFINITY, 1.0],
            vec![1.0, 1.0, 1.0, 0.0],
            1.0,
        )
        .unwrap();
        let p = f.project(&[0.9, 0.5, -0.2, 3.0]);
        let exact = [0.675, 0.275, 0.05, 1.0];
        for (a, b) in p.iter().zip(exact) {
            assert!((a - b).abs() < 1e-15, "{p:?}");
        }
        assert!(Feasible::new(vec![0.5; 3], vec![1.0; 3], vec![1.0; 3], 1.0).is_none());
    }

    /// A coupled concave quadratic f = −½ (x − t)ᵀQ(x − t) over
    /// x0 ∈ [−1, 1] (a shape variable) and a1..a3 ≥ 0.05 with
    /// a1 + a2 + a3 = 1, whose unconstrained maximum t = (3, 1, 0.9, −0.3)
    /// violates both: the KKT point has x0 = 1 and a3 = 0.05 on their
    /// bounds and solves the linear system of the stationarity of the
    /// Lagrangian on the free variables with the equality (closed form,
    /// solved here densely), with multipliers of the right signs.
    #[test]
    fn ascent_reaches_the_kkt_point_of_a_quadratic() {
        let q = DMatrix::from_row_slice(
            4,
            4,
            &[
                2.0, 0.3, 0.0, 0.1, //
                0.3, 1.0, 0.4, 0.0, //
                0.0, 0.4, 1.5, 0.2, //
                0.1, 0.0, 0.2, 1.0,
            ],
        );
        let t = DVector::from_column_slice(&[3.0, 1.0, 0.9, -0.3]);
        let slope = |x: &[f64]| -> Option<Slope> {
            let d = DVector::from_column_slice(x) - &t;
            let qd = &q * &d;
            Some((-0.5 * d.dot(&qd), Some((-qd).as_slice().to_vec())))
        };
        let feasible = Feasible::new(
            vec![-1.0, 0.05, 0.05, 0.05],
            vec![1.0, f64::INFINITY, f64::INFINITY, f64::INFINITY],
            vec![0.0, 1.0, 1.0, 1.0],
            1.0,
        )
        .unwrap();
        let run = ascend(
            &[0.0, 0.4, 0.3, 0.3],
            &feasible,
            &[2.0, 1.0, 1.0, 1.0],
            (200, 1e-12),
            &slope,
            &|| false,
        );
        assert_eq!(run.end, JointEnd::Converged, "{run:?}");
        let (x, _) = run.best.unwrap();
        // Free a1, a2 with x0 = 1, a3 = 0.05: Q_ff a_f − ν (1, 1) =
        // Q_ff t_f − Q_fh (x_h − t_h), a1 + a2 = 0.95.
        let (x0, a3) = (1.0, 0.05);
        let h = DVector::from_column_slice(&[x0 - t[0], a3 - t[3]]);
        let qfh = DMatrix::from_row_slice(2, 2, &[q[(1, 0)], q[(1, 3)], q[(2, 0)], q[(2, 3)]]);
        let rhs_f = DMatrix::from_row_slice(2, 2, &[q[(1, 1)], q[(1, 2)], q[(2, 1)], q[(2, 2)]])
            * DVector::from_column_slice(&[t[1], t[2]])
            - qfh * h;
        let kkt = DMatrix::from_row_slice(
            3,
            3,
            &[
                q[(1, 1)],
                q[(1, 2)],
                1.0, //
                q[(2, 1)],
                q[(2, 2)],
                1.0, //
                1.0,
                1.0,
                0.0,
            ],
        );
        let sol = kkt
            .lu()
            .solve(&DVector::from_column_slice(&[rhs_f[0], rhs_f[1], 1.0 - a3]))
            .unwrap();
        let exact = [x0, sol[0], sol[1], a3];
        for (a, b) in x.iter().zip(exact) {
            assert!((a - b).abs() < 1e-9, "{x:?} against {exact:?}");
        }
        // The multipliers: the gradient at the optimum pushes x0 up and
        // a3 (less the equality's ν = −sol[2]) down, the a's off their bound.
        let (_, g) = slope(&x).unwrap();
        let g = g.unwrap();
        let nu = sol[2];
        assert!(g[0] > 0.0 && g[3] - nu < 0.0, "{g:?}, ν = {nu}");
        assert!((g[1] - nu).abs() < 1e-9 && (g[2] - nu).abs() < 1e-9);
    }
}
