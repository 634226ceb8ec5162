//! Pieces of the arm search that a sweep reuses point by point: Halton
//! samples of the box, a Nelder–Mead polish from a given start with a
//! chosen simplex size (a warm start from a neighbouring grid point's
//! optimum needs a small simplex, a cold start the search's 5 %), and the
//! finished optimum of a design (curvature fit (59), shapes).
//!
//! A child module of `optimize`, so that it uses the search's private
//! pieces instead of copying them.

use argmin::core::{Executor, State};
use argmin::solver::neldermead::NelderMead;

use super::{halton, ArmDesign, ArmOptimum, ArmProblem, ArmScene, ReachCost, PRIMES};

impl ArmProblem {
    /// The i-th Halton point (i ≥ 1) of the box of c2..cM — the samples of
    /// the global stage of [`ArmProblem::optimize`].
    pub fn halton_point(&self, i: usize) -> Vec<f64> {
        self.bounds
            .iter()
            .enumerate()
            .map(|(d, (lo, hi))| lo + (hi - lo) * halton(i, PRIMES[d % PRIMES.len()]))
            .collect()
    }

    /// Nelder–Mead on −R̂ from `start` (projected into the bounds), the
    /// initial simplex spanning `step` times each bound's width; returns
    /// the polished design and the evaluations used.
    pub fn polish_with_step(
        &self,
        scene: &ArmScene,
        start: &[f64],
        iterations: u64,
        step: f64,
    ) -> (Option<ArmDesign>, usize) {
        if start.is_empty() {
            // M = 1: nothing to polish, the shape is fixed by α.
            return (self.design_in(scene, &[]), 1);
        }
        let start = self.project(start);
        let simplex: Vec<Vec<f64>> = std::iter::once(start.clone())
            .chain((0..start.len()).map(|d| {
                let mut p = start.clone();
                let (lo, hi) = self.bounds[d];
                let h = step * (hi - lo);
                p[d] = if p[d] + h <= hi { p[d] + h } else { p[d] - h };
                p
            }))
            .collect();
        let never = || false;
        let cost = ReachCost {
            problem: self,
            scene,
            stop: &never,
            calls: std::cell::Cell::new(0),
        };
        let Ok(solver) = NelderMead::new(simplex).with_sd_tolerance(1e-12) else {
            return (None, 0);
        };
        let result = Executor::new(&cost, solver)
            .configure(|state| state.max_iters(iterations))
            .run();
        let design = result.ok().and_then(|r| {
            let p = r.state().get_best_param()?.clone();
            self.design_in(scene, &self.project(&p))
        });
        (design, cost.calls.get())
    }

    /// The optimum record of a design: the Taylor fit b of κ̄⁰2 (paper
    /// (59)), the loaded and unloaded shapes.
    pub fn complete(
        &self,
        scene: &ArmScene,
        design: ArmDesign,
        evaluations: usize,
    ) -> Option<ArmOptimum> {
        self.finish(scene, design, evaluations)
    }
}
