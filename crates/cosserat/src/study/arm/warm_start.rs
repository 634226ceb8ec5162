//! Pieces of the arm search that a sweep reuses point by point: the
//! samples of the box and the finished optimum of a design (curvature fit
//! (59), shapes); a sweep's polishes are the search's own
//! ([`ArmProblem::polished`]).
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
