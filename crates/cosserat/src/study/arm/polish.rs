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
