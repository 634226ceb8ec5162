//! Pieces of the arm search that a sweep reuses point by point: the
//! samples of the box, a Nelder–Mead polish from a given start with a
//! chosen simplex size (a warm start from a neighbouring grid point's
//! optimum needs a small simplex, a cold start the search's 5 %), and the
//! finished optimum of a design (curvature fit (59), shapes).
//!
//! A child module of `study::arm`, so that it uses the search's private
//! pieces instead of copying them.

use super::{sampling, ArmDesign, ArmOptimum, ArmProblem, ArmScene};

impl ArmProblem {
    /// The i-th sample (i ≥ 1) of the box of c2..cM — the samples of the
    /// global stage of [`ArmProblem::optimize`]: point i − 1 of the
    /// scrambled Sobol' sequence (`study/arm/sampling.rs`) mapped onto the bounds.
    pub fn sample_point(&self, i: usize) -> Vec<f64> {
        assert!(i >= 1, "samples are numbered from 1");
        sampling::unit_point(i - 1, self.bounds.len())
            .iter()
            .zip(&self.bounds)
            .map(|(u, (lo, hi))| lo + (hi - lo) * u)
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
        self.nelder_mead(scene, self.simplex_sized(&start, step), iterations, &|| {
            false
        })
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
