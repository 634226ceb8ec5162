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

/// A value and, where it exists, its gradient.
pub(super) type Slope = (f64, Option<Vec<f64>>);

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
}

/// Maximizes `slope`'s value over the box `bounds` from `start` by projected
/// BFGS: the inverse-Hessian step on the variables not held at a bound by
/// the gradient, an Armijo backtracking search along the projected path
/// P(x + t d) (Bertsekas 1982, projected Newton for bound constraints),
/// the BFGS update where the curvature condition sᵀy > 0 holds (else the
/// update is skipped); stops on the projected-gradient norm relative to the
/// value ([`ASCENT_TOLERANCE`]). Deterministic (sequential). Written here
/// because argmin's L-BFGS has no bounds and the box is part of the
/// problem (the paper's (60)); 7 variables make the dense update cheap.
pub(super) fn ascend_in_box(
    start: &[f64],
    bounds: &[(f64, f64)],
    iterations: usize,
    slope: &dyn Fn(&[f64]) -> Option<Slope>,
    stop: &dyn Fn() -> bool,
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
    };
    let mut x = project(start);
    if stop() {
        ascent.end = AscentEnd::Stopped;
        return ascent;
    }
    ascent.evaluations += 1;
    let Some((mut f, gradient)) = slope(&x) else {
        return ascent;
    };
    ascent.best = Some((x.clone(), f));
    let Some(mut g) = gradient else {
        ascent.end = AscentEnd::NoGradient;
        return ascent;
    };
    let widths: Vec<f64> = bounds.iter().map(|(lo, hi)| hi - lo).collect();
    let mut hessian = initial_hessian(&widths, &g);
    loop {
        if projected_gradient(&x, &g, bounds) <= ASCENT_TOLERANCE * f.abs() {
            ascent.end = AscentEnd::Converged;
            return ascent;
        }
        if ascent.iterations >= iterations {
            ascent.end = AscentEnd::Capped;
            return ascent;
        }
        ascent.iterations += 1;
        let mut held = held_at_bounds(&x, &g, bounds);
        let d = loop {
            let d = match ascent_direction(&hessian, &g, &held) {
                Some(d) if d.iter().zip(&g).map(|(a, b)| a * b).sum::<f64>() > 0.0 => d,
                _ => {
                    hessian = initial_hessian(&widths, &g);
                    ascent_direction(&hessian, &g, &held)
                        .expect("a positive diagonal is positive definite")
                }
            };
            // A free variable on its bound that the step would push out
            // is held too (its move would be clipped, and the clipped step
            // would teach the update a false curvature): until none is.
            let outward = stepping_out(&x, &d, bounds, &held);
            if outward.is_empty() {
                break d;
            }
            for i in outward {
                held[i] = true;
            }
        };
        let mut t = 1.0;
        let accepted = loop {
            if stop() {
                ascent.end = AscentEnd::Stopped;
                return ascent;
            }
            let trial = project(&x.iter().zip(&d).map(|(a, b)| a + t * b).collect::<Vec<_>>());
            let rise: f64 = trial
                .iter()
                .zip(&x)
                .zip(&g)
                .map(|((a, b), c)| (a - b) * c)
                .sum();
            ascent.evaluations += 1;
            if let Some((ft, gt)) = slope(&trial) {
                // Armijo on the projected path: f(x_t) ≥ f + σ gᵀ(x_t − x).
                if ft >= f + 1e-4 * rise && ft >= f {
                    break Some((trial, ft, gt));
                }
            }
            t *= 0.5;
            if t < 1e-12 {
                break None;
            }
        };
        let Some((next, fnext, gnext)) = accepted else {
            ascent.end = AscentEnd::Flat;
            return ascent;
        };
        ascent.best = Some((next.clone(), fnext));
        let Some(gnext) = gnext else {
            ascent.end = AscentEnd::NoGradient;
            return ascent;
        };
        // Minimizing −f: s = Δx, y = −Δg.
        let s: Vec<f64> = next.iter().zip(&x).map(|(a, b)| a - b).collect();
        let y: Vec<f64> = g.iter().zip(&gnext).map(|(a, b)| a - b).collect();
        bfgs_update(&mut hessian, &s, &y);
        (x, f, g) = (next, fnext, gnext);
    }
}

/// max_i |x_i − P(x_i + g_i)|: zero exactly at a KKT point of the box.
fn projected_gradient(x: &[f64], g: &[f64], bounds: &[(f64, f64)]) -> f64 {
    x.iter()
        .zip(g)
        .zip(bounds)
        .map(|((xi, gi), (lo, hi))| (xi - (xi + gi).clamp(*lo, *hi)).abs())
        .fold(0.0, f64::max)
}

/// The variables at a bound that the gradient pushes outwards (held there).
fn held_at_bounds(x: &[f64], g: &[f64], bounds: &[(f64, f64)]) -> Vec<bool> {
    x.iter()
        .zip(g)
        .zip(bounds)
        .map(|((xi, gi), (lo, hi))| (*xi <= *lo && *gi < 0.0) || (*xi >= *hi && *gi > 0.0))
        .collect()
}

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
/// of the reduced problem), 0 on the held; None where B_ff is not positive
/// definite (by round-off).
fn ascent_direction(hessian: &DMatrix<f64>, g: &[f64], held: &[bool]) -> Option<Vec<f64>> {
    let free: Vec<usize> = (0..g.len()).filter(|&i| !held[i]).collect();
    let reduced = DMatrix::from_fn(free.len(), free.len(), |i, j| hessian[(free[i], free[j])]);
    let rhs = DVector::from_iterator(free.len(), free.iter().map(|&i| g[i]));
    let step = reduced.cholesky()?.solve(&rhs);
    let mut d = vec![0.0; g.len()];
    for (k, &i) in free.iter().enumerate() {
        d[i] = step[k];
    }
    Some(d)
}

/// The first Hessian model of −f: diag(1/w_i²)/θ, θ such that the first
/// step moves no variable by more than 5 % of its bound's width.
fn initial_hessian(widths: &[f64], g: &[f64]) -> DMatrix<f64> {
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
fn bfgs_update(b: &mut DMatrix<f64>, s: &[f64], y: &[f64]) {
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
            Some((f, Some(vec![-qd[0], -qd[1]])))
        };
        let bounds = [(-1.0, 1.0), (-4.0, 4.0)];
        let ascent = ascend_in_box(&[0.0, 0.0], &bounds, 200, &slope, &|| false);
        assert_eq!(ascent.end, AscentEnd::Converged, "{ascent:?}");
        let (x, _) = ascent.best.expect("a point");
        let x1 = t[1] - q[1][0] * (1.0 - t[0]) / q[1][1];
        assert_eq!(x[0], 1.0);
        assert!((x[1] - x1).abs() < 1e-6, "{x:?} against (1, {x1})");
    }

    /// A value without a gradient ends the ascent there, said so.
    #[test]
    fn ascent_stops_where_there_is_no_gradient() {
        let slope = |x: &[f64]| -> Option<Slope> { Some((-x[0].abs(), None)) };
        let ascent = ascend_in_box(&[0.5], &[(-1.0, 1.0)], 10, &slope, &|| false);
        assert_eq!(ascent.end, AscentEnd::NoGradient);
        assert_eq!(ascent.iterations, 0);
    }
}
