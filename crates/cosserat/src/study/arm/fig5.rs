//! The data set behind the paper's Fig. 5 (Sec. 4.1): the reach of many
//! designs over the box of c2..cM, each with the Taylor fit b of its
//! intrinsic curvature (59), and the design closest to an intrinsically
//! straight rod — the paper's point 'Q', the sample with the least Σ b_i²
//! (its objective B(C) for straight rods, Sec. 3.2).
//!
//! 'Q' is a sample of a data set, not the straight arm: a polynomial loaded
//! shape with M coefficients is not an elastica, so its κ⁰ is never exactly
//! zero, and a finite data set only comes near the least-Σb² shape. The
//! true straight optimum R̂0 ([`super::StraightArm`]) is solved directly.

use super::{ArmOptimum, ArmProblem, ArmScene};

/// Designs of the box: Sobol' samples in the order of the global stage.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReachMap {
    /// c1..cM of each design with a finite critical load.
    pub shape_coefficients: Vec<Vec<f64>>,
    /// b1..bM, the least-squares Taylor fit of κ̄⁰2 (paper (59)).
    pub curvature_coefficients: Vec<Vec<f64>>,
    /// R̂ of each design.
    pub reach: Vec<f64>,
    /// Its design load.
    pub gamma: Vec<f64>,
    /// Samples evaluated (with or without a critical load).
    pub samples: usize,
    /// Whether `stop()` ended the map before all samples were evaluated:
    /// then it holds the first `samples` only.
    pub interrupted: bool,
}

/// The sample closest to an intrinsically straight rod (least Σ b_i²).
#[derive(Debug, Clone, PartialEq)]
pub struct ClosestStraight {
    /// Its index in the map.
    pub index: usize,
    /// Σ b_i².
    pub curvature_norm: f64,
    /// The design with its shapes.
    pub optimum: ArmOptimum,
}

impl ArmProblem {
    /// R̂ and b of the first `samples` Sobol' points of the box; stops
    /// early when `stop()` turns true (checked before every sample), the
    /// map then holding what was computed, marked interrupted.
    pub fn reach_map(&self, scene: &ArmScene, samples: usize, stop: &dyn Fn() -> bool) -> ReachMap {
        let mut map = ReachMap::default();
        for i in 1..=samples {
            if stop() {
                map.interrupted = true;
                break;
            }
            map.samples = i;
            let p = self.sample_point(i);
            let Some(d) = self.design_in(scene, &p) else {
                continue;
            };
            let Some(o) = self.finish(scene, d, 1) else {
                continue;
            };
            map.reach.push(o.design.reach);
            map.gamma.push(o.design.gamma);
            map.shape_coefficients.push(o.design.shape_coefficients);
            map.curvature_coefficients.push(o.curvature_coefficients);
        }
        map
    }
}

impl ReachMap {
    /// The paper's 'Q': the sample with the least Σ b_i², with its shapes.
    pub fn closest_straight(
        &self,
        problem: &ArmProblem,
        scene: &ArmScene,
    ) -> Option<ClosestStraight> {
        let norm = |b: &Vec<f64>| b.iter().map(|v| v * v).sum::<f64>();
        let index = (0..self.reach.len()).min_by(|&a, &b| {
            norm(&self.curvature_coefficients[a]).total_cmp(&norm(&self.curvature_coefficients[b]))
        })?;
        let design = problem.design_in(scene, &self.shape_coefficients[index][1..])?;
        Some(ClosestStraight {
            index,
            curvature_norm: norm(&self.curvature_coefficients[index]),
            optimum: problem.checked(scene, problem.finish(scene, design, 1)?),
        })
    }
}

/// Σ b_i² of a design (the paper's B(C), Sec. 3.2), for Nelder–Mead;
/// points outside the box are projected into it and charged their squared
/// distance, designs without a critical load charged a large constant.
struct CurvatureCost<'a> {
    problem: &'a ArmProblem,
    scene: &'a ArmScene,
    stop: &'a dyn Fn() -> bool,
}

impl CurvatureCost<'_> {
    fn fit(&self, p: &[f64]) -> Option<ArmOptimum> {
        let d = self.problem.design_in(self.scene, p)?;
        self.problem.finish(self.scene, d, 1)
    }
}

impl argmin::core::CostFunction for &CurvatureCost<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        if (self.stop)() {
            // Stopping: the worst cost, not an error — argmin's Nelder–Mead
            // unwraps the costs of its first simplex (a panic), and the
            // caller discards a polish that ran into a stop.
            return Ok(f64::INFINITY);
        }
        let q = self.problem.project(p);
        let outside: f64 = p.iter().zip(&q).map(|(a, b)| (a - b).powi(2)).sum();
        let norm = self.fit(&q).map_or(1e6, |o| {
            o.curvature_coefficients.iter().map(|b| b * b).sum::<f64>()
        });
        Ok(norm + outside)
    }
}

impl ArmProblem {
    /// The paper's R0 (Sec. 3.2): the design that minimizes Σ b_i², by
    /// Nelder–Mead from each of the `starts` map samples with the least
    /// Σ b_i²; the best result.
    ///
    /// `stop()` (checked at every evaluation) ends it early: the result is
    /// then the best of the polishes finished, and the flag is true.
    pub fn least_curvature(
        &self,
        scene: &ArmScene,
        map: &ReachMap,
        starts: usize,
        iterations: u64,
        stop: &dyn Fn() -> bool,
    ) -> (Option<ClosestStraight>, bool) {
        use argmin::core::{Executor, State};
        let norm = |b: &Vec<f64>| b.iter().map(|v| v * v).sum::<f64>();
        let mut order: Vec<usize> = (0..map.reach.len()).collect();
        order.sort_by(|&a, &b| {
            norm(&map.curvature_coefficients[a]).total_cmp(&norm(&map.curvature_coefficients[b]))
        });
        let cost = CurvatureCost {
            problem: self,
            scene,
            stop,
        };
        let mut best: Option<ClosestStraight> = None;
        for &index in order.iter().take(starts) {
            if stop() {
                return (best, true);
            }
            let start = map.shape_coefficients[index][1..].to_vec();
            let simplex = self.simplex(&start);
            let Ok(solver) =
                argmin::solver::neldermead::NelderMead::new(simplex).with_sd_tolerance(1e-14)
            else {
                continue;
            };
            let result = Executor::new(&cost, solver)
                .configure(|s| s.max_iters(iterations))
                .run();
            if stop() {
                return (best, true);
            }
            // The cost never fails but on an interrupt, handled above.
            let Ok(result) = result else {
                continue;
            };
            let Some(p) = result.state().get_best_param() else {
                continue;
            };
            let Some(optimum) = cost.fit(&self.project(p)) else {
                continue;
            };
            let found = norm(&optimum.curvature_coefficients);
            if best.as_ref().is_none_or(|b| found < b.curvature_norm) {
                best = Some(ClosestStraight {
                    index,
                    curvature_norm: found,
                    optimum,
                });
            }
        }
        // Its reach is reported: with its discretization error.
        let best = best.map(|b| ClosestStraight {
            optimum: self.checked(scene, b.optimum),
            ..b
        });
        (best, false)
    }
}
