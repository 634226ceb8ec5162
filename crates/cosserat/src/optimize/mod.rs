//! The longest soft robotic arm (Sipos & Várkonyi 2019, Sec. 3–4): the
//! loaded shape that reaches farthest in a direction α before the arm loses
//! stability, with the intrinsic curvature that produces it.
//!
//! The loaded shape is the turning angle φ(s̄) = Σ_{i=1}^{M} c_i s̄^{i−1}
//! (paper (52)); c1 is a rigid rotation fixed by the reach direction
//! (third condition of (46)); the critical load γ_crit = F L²/B2 of the
//! shape held fixed is a generalized eigenvalue of the verified second
//! variation ([`crate::stability::critical_load`], both blocks); the reach
//! is R̂ = √γ_crit |(x̄(1), z̄(1))| in units of √(B2/F) (paper (54)–(55)).
//! The intrinsic curvature follows from (43): κ̄⁰2 = φ' − γ m̄2, with m̄2 the
//! moment of the unit tip load on the shape.
//!
//! The search is deterministic: an Owen-scrambled Sobol' set over the box
//! of c2..cM (the global stage, the private `optimize/sampling.rs`), then Nelder–Mead (argmin)
//! from the best few (the polish).

use std::ops::ControlFlow;
use std::sync::Arc;

use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::neldermead::NelderMead;

use crate::model::{Clamp, LinearElastic, Profile, Rod};
use crate::numerics::scalar::{bisect_or_break, golden_section_max};
use crate::stability::{critical_load, FixedShape, StabilityOptions};

pub mod control_path;
pub mod fig5;
mod resolve;
mod sampling;
pub mod scene;

pub use control_path::{
    control_path, control_path_until, loading_path_in, loading_path_until, shape_holding_path,
    shape_holding_path_until,
};
pub use fig5::{ClosestStraight, ReachMap};
pub use resolve::{MeshStudy, Resolution, Verdict, MAX_ELEMENTS, REACH_TOLERANCE};
pub use scene::{ArmScene, ArmWeight};

mod warm_start;

/// The arm to design.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmProblem {
    /// B̄1 = B1/B2.
    pub b1: f64,
    /// B̄3 = B3/B2.
    pub b3: f64,
    /// Reach direction (rad) above the horizontal: the tip at elevation α.
    pub alpha: f64,
    /// Bounds of c2..cM (M − 1 pairs).
    pub bounds: Vec<(f64, f64)>,
    /// Discretization of the second variation.
    pub stability: StabilityOptions,
}

/// How hard to search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SearchOptions {
    /// Samples (scrambled Sobol' points) of the global stage.
    pub samples: usize,
    /// Nelder–Mead polishes from the best samples.
    pub starts: usize,
    /// Iterations of each polish.
    pub iterations: u64,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            samples: 400,
            starts: 4,
            iterations: 400,
        }
    }
}

/// One evaluated design.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmDesign {
    /// R̂ = √γ_crit |(x̄(1), z̄(1))| (with an [`ArmScene`]: L̂(λ) |r̄(1)|).
    pub reach: f64,
    /// The design load: γ_crit = F L²/B2 (with an [`ArmScene`]: the load
    /// factor λ, γ_crit or, actuator-limited, the largest λ below it that
    /// the actuators can hold).
    pub gamma: f64,
    /// c1..cM of the loaded shape φ(s̄).
    pub shape_coefficients: Vec<f64>,
}

/// The optimum with what a user keeps of it.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmOptimum {
    /// The design.
    pub design: ArmDesign,
    /// b1..bM: the least-squares Taylor fit of κ̄⁰2(s̄) (paper (59)).
    pub curvature_coefficients: Vec<f64>,
    /// The loaded shape in scaled coordinates (x̂, ŷ, ẑ) = √γ (x̄, ȳ, z̄).
    pub loaded_shape: Vec<[f64; 3]>,
    /// The unloaded (intrinsic) shape, same scaling and clamp.
    pub unloaded_shape: Vec<[f64; 3]>,
    /// κ̄⁰2 at the shape points.
    pub intrinsic_curvature: Vec<f64>,
    /// Designs evaluated.
    pub evaluations: usize,
    /// The critical load factor of the loaded shape (≥ `design.gamma`; equal
    /// unless the actuators limit the load).
    pub critical_load: f64,
    /// The loads and limits the design was made for.
    pub scene: ArmScene,
    /// Its discretization check ([`ArmProblem::resolve`]): R̂ on finer
    /// meshes, the error estimate, and whether it was searched for again on
    /// a finer mesh. None
    /// where no check was made (a sample, the best so far of an
    /// interrupted search).
    pub resolution: Option<Resolution>,
}

/// How far a search has come: what `cosserat optimize --resume` keeps of an
/// interrupted run to go on where it stopped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SearchProgress {
    /// Samples evaluated: the global stage goes on from the next one.
    pub samples_done: usize,
    /// The best samples so far as (R̂, c2..cM), best first, at most
    /// `starts` of them: the starting points of the polishes.
    pub leaders: Vec<(f64, Vec<f64>)>,
    /// Polishes finished (an interrupted polish is redone).
    pub polishes_done: usize,
    /// The best design so far.
    pub best: Option<ArmDesign>,
    /// Designs evaluated so far.
    pub evaluations: usize,
}

/// Composite Gauss–Legendre nodes (5 points on each of 32 panels) on [0, 1].
fn quadrature() -> Vec<(f64, f64)> {
    const X: [f64; 5] = [
        -0.906_179_845_938_664,
        -0.538_469_310_105_683_1,
        0.0,
        0.538_469_310_105_683_1,
        0.906_179_845_938_664,
    ];
    const W: [f64; 5] = [
        0.236_926_885_056_189_1,
        0.478_628_670_499_366_5,
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
    ];
    let panels = 32;
    let h = 1.0 / panels as f64;
    (0..panels)
        .flat_map(|p| {
            X.iter()
                .zip(W)
                .map(move |(x, w)| ((p as f64 + 0.5 * (x + 1.0)) * h, 0.5 * w * h))
        })
        .collect()
}

fn polynomial(c: &[f64], s: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, ci| acc * s + ci)
}

impl ArmProblem {
    /// M, the number of shape coefficients.
    pub fn coefficients(&self) -> usize {
        self.bounds.len() + 1
    }

    /// The non-dimensional rod: L = 1, B = (B̄1, 1, B̄3), a unit tip load
    /// pulling down (e1), clamped at the origin with d3 horizontal.
    pub fn rod(&self) -> Rod {
        self.rod_in(&ArmScene::default())
    }

    /// The non-dimensional rod under the scene's loads per unit λ.
    pub fn rod_in(&self, scene: &ArmScene) -> Rod {
        Rod {
            length: 1.0,
            energy: Arc::new(LinearElastic::uniform([self.b1, 1.0, self.b3], [0.0; 3])),
            clamp: Clamp::paper(),
            loads: scene.loads(),
            support: None,
        }
    }

    /// The full coefficients c1..cM: c1 turns the shape so that the tip
    /// lies at elevation α (atan2(−x̄, z̄) = α).
    pub fn full_coefficients(&self, rest: &[f64]) -> (Vec<f64>, f64) {
        let mut c = vec![0.0];
        c.extend_from_slice(rest);
        let (mut z, mut x) = (0.0, 0.0);
        for (s, w) in quadrature() {
            let (sin, cos) = polynomial(&c, s).sin_cos();
            z += w * cos;
            x += w * sin;
        }
        c[0] = -self.alpha - x.atan2(z);
        (c, x.hypot(z))
    }

    /// R̂ and γ_crit of the shape with coefficients c2..cM; None when the
    /// shape is stable under any load (no finite critical load).
    pub fn design(&self, rest: &[f64]) -> Option<ArmDesign> {
        self.design_in(&ArmScene::default(), rest)
    }

    /// R̂ and the design load of the shape c2..cM in a scene: λ_crit of the
    /// fixed shape under the scene's loads, lowered to what the actuators
    /// can hold when |κ⁰| is limited; R̂ = L̂(λ) |r̄(1)|.
    pub fn design_in(&self, scene: &ArmScene, rest: &[f64]) -> Option<ArmDesign> {
        let (c, chord) = self.full_coefficients(rest);
        let rod = self.rod_in(scene);
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(c.clone()),
        };
        let crit = critical_load(&rod, &shape, &self.stability).ok()?;
        let mut gamma = crit.load_factor?;
        if scene.max_curvature.is_some() {
            let points: Vec<f64> = (0..=200).map(|i| i as f64 / 200.0).collect();
            let samples = shape.samples(&rod, &points).ok()?;
            let dphi = derivative(&c);
            let phi1: Vec<f64> = points.iter().map(|s| polynomial(&dphi, *s)).collect();
            let m2: Vec<f64> = samples.iter().map(|p| p.moment[1]).collect();
            gamma = scene.operating_load(gamma, &phi1, &m2)?;
        }
        Some(ArmDesign {
            reach: scene.length(gamma) * chord,
            gamma,
            shape_coefficients: c,
        })
    }

    /// Clamps a point into the bounds.
    fn project(&self, p: &[f64]) -> Vec<f64> {
        p.iter()
            .zip(&self.bounds)
            .map(|(v, (lo, hi))| v.clamp(*lo, *hi))
            .collect()
    }

    /// The best design: scrambled Sobol' samples of the box, then
    /// Nelder–Mead from the best few.
    pub fn optimize(&self, opts: &SearchOptions) -> Option<ArmOptimum> {
        self.optimize_until(opts, &|| false).map(|(o, _)| o)
    }

    /// As [`Self::optimize`], stopping early when `stop()` turns true (an
    /// interrupt): then the best design found so far is returned, flagged.
    pub fn optimize_until(
        &self,
        opts: &SearchOptions,
        stop: &dyn Fn() -> bool,
    ) -> Option<(ArmOptimum, bool)> {
        let (optimum, _, interrupted) = self.search(
            &ArmScene::default(),
            opts,
            SearchProgress::default(),
            stop,
            &mut |_| {},
        );
        Some((optimum?, interrupted))
    }

    /// The search in a scene, going on from `progress` (a fresh one, or
    /// what an interrupted run kept): Sobol' samples of the box, then
    /// Nelder–Mead from the best `starts`. Returns the optimum (the best
    /// so far when interrupted), the progress to resume from, and whether
    /// `stop()` interrupted it. Resuming gives the same optimum as an
    /// uninterrupted run: the samples are a fixed sequence and a polish
    /// cut short is redone from its start. `checkpoint` sees the progress
    /// after every sample and every polish (to save it against a kill).
    ///
    /// The optimum is then checked on finer meshes ([`Self::resolve`]):
    /// where the search's mesh does not resolve it, the search is redone on
    /// a finer one, and the optimum reported is that search's, with its
    /// discretization error.
    pub fn search(
        &self,
        scene: &ArmScene,
        opts: &SearchOptions,
        progress: SearchProgress,
        stop: &dyn Fn() -> bool,
        checkpoint: &mut dyn FnMut(&SearchProgress),
    ) -> (Option<ArmOptimum>, SearchProgress, bool) {
        let (optimum, progress, interrupted) =
            self.search_on_mesh(scene, opts, progress, stop, checkpoint);
        if interrupted {
            return (optimum, progress, true);
        }
        let optimum = optimum.map(|o| self.resolve(scene, o, opts, REACH_TOLERANCE, stop));
        (optimum, progress, stop())
    }

    /// The search on this problem's mesh alone, without the mesh check.
    fn search_on_mesh(
        &self,
        scene: &ArmScene,
        opts: &SearchOptions,
        mut progress: SearchProgress,
        stop: &dyn Fn() -> bool,
        checkpoint: &mut dyn FnMut(&SearchProgress),
    ) -> (Option<ArmOptimum>, SearchProgress, bool) {
        let keep = opts.starts.max(1);
        while progress.samples_done < opts.samples && !stop() {
            let i = progress.samples_done + 1;
            let p = self.sample_point(i);
            progress.evaluations += 1;
            if let Some(d) = self.design_in(scene, &p) {
                let at = progress.leaders.partition_point(|(r, _)| *r >= d.reach);
                progress.leaders.insert(at, (d.reach, p));
                progress.leaders.truncate(keep);
            }
            progress.samples_done = i;
            checkpoint(&progress);
        }
        if self.bounds.is_empty() {
            let optimum = self
                .design_in(scene, &[])
                .and_then(|d| self.finish(scene, d, progress.evaluations));
            return (optimum, progress, stop());
        }
        if progress.polishes_done == 0 {
            progress.best = progress
                .leaders
                .first()
                .and_then(|(_, p)| self.design_in(scene, p));
        }
        let starts = opts.starts.min(progress.leaders.len());
        while progress.polishes_done < starts && !stop() {
            let start = progress.leaders[progress.polishes_done].1.clone();
            let (design, used) = self.polish(scene, &start, opts.iterations, stop);
            if stop() {
                break;
            }
            progress.evaluations += used;
            if let Some(d) = design {
                if progress.best.as_ref().is_none_or(|b| d.reach > b.reach) {
                    progress.best = Some(d);
                }
            }
            progress.polishes_done += 1;
            checkpoint(&progress);
        }
        let optimum = self.best_so_far(scene, &progress);
        (optimum, progress, stop())
    }

    /// The best design of a search so far with its shapes: the best polish,
    /// or the best sample while the global stage runs.
    pub fn best_so_far(&self, scene: &ArmScene, progress: &SearchProgress) -> Option<ArmOptimum> {
        let best = match &progress.best {
            Some(b) if progress.polishes_done > 0 || progress.leaders.is_empty() => b.clone(),
            _ => {
                let (_, p) = progress.leaders.first()?;
                self.design_in(scene, p)?
            }
        };
        self.finish(scene, best, progress.evaluations)
    }

    /// The starting simplex around `start`: steps of 5 % of each bound's
    /// width, inwards at the upper bound.
    fn simplex(&self, start: &[f64]) -> Vec<Vec<f64>> {
        self.simplex_sized(start, 0.05)
    }

    /// The simplex with steps of `fraction` of each bound's width.
    fn simplex_sized(&self, start: &[f64], fraction: f64) -> Vec<Vec<f64>> {
        std::iter::once(start.to_vec())
            .chain((0..start.len()).map(|d| {
                let mut p = start.to_vec();
                let (lo, hi) = self.bounds[d];
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

    /// Nelder–Mead from `start` on −R̂ (projected into the bounds).
    fn polish(
        &self,
        scene: &ArmScene,
        start: &[f64],
        iterations: u64,
        stop: &dyn Fn() -> bool,
    ) -> (Option<ArmDesign>, usize) {
        self.nelder_mead(scene, self.simplex(start), iterations, stop)
    }

    /// Nelder–Mead on −R̂ from a simplex; the polished design and the
    /// evaluations used.
    fn nelder_mead(
        &self,
        scene: &ArmScene,
        simplex: Vec<Vec<f64>>,
        iterations: u64,
        stop: &dyn Fn() -> bool,
    ) -> (Option<ArmDesign>, usize) {
        let cost = ReachCost {
            problem: self,
            scene,
            stop,
            calls: std::cell::Cell::new(0),
        };
        let Ok(solver) = NelderMead::new(simplex).with_sd_tolerance(1e-12) else {
            return (None, 0);
        };
        let result = Executor::new(&cost, solver)
            .configure(|state| state.max_iters(iterations))
            .run();
        let calls = cost.calls.get();
        let design = result.ok().and_then(|r| {
            let p = r.state().get_best_param()?.clone();
            self.design_in(scene, &self.project(&p))
        });
        (design, calls)
    }

    /// The optimum with its shapes, intrinsic curvature (43) and its
    /// Taylor fit (59), and the critical load of its shape.
    fn finish(
        &self,
        scene: &ArmScene,
        design: ArmDesign,
        evaluations: usize,
    ) -> Option<ArmOptimum> {
        let rod = self.rod_in(scene);
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(design.shape_coefficients.clone()),
        };
        let critical = critical_load(&rod, &shape, &self.stability)
            .ok()?
            .load_factor?;
        let n = 101;
        let points: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
        let samples = shape.samples(&rod, &points).ok()?;
        let c = &design.shape_coefficients;
        let dphi = derivative(c);
        let kappa0: Vec<f64> = samples
            .iter()
            .map(|p| polynomial(&dphi, p.s) - design.gamma * p.moment[1])
            .collect();
        let scale = scene.length(design.gamma);
        let loaded = samples
            .iter()
            .map(|p| {
                [
                    p.position[0] * scale,
                    p.position[1] * scale,
                    p.position[2] * scale,
                ]
            })
            .collect();
        let unloaded = intrinsic_shape(c[0], &points, &kappa0, scale);
        Some(ArmOptimum {
            curvature_coefficients: least_squares_polynomial(&points, &kappa0, c.len()),
            design,
            loaded_shape: loaded,
            unloaded_shape: unloaded,
            intrinsic_curvature: kappa0,
            evaluations,
            critical_load: critical,
            scene: *scene,
            resolution: None,
        })
    }
}

/// The coefficients of p' for p = Σ c_i s^{i−1}.
fn derivative(c: &[f64]) -> Vec<f64> {
    c.iter()
        .enumerate()
        .skip(1)
        .map(|(i, ci)| i as f64 * ci)
        .collect()
}

/// The unloaded shape: φ⁰ = c1 + ∫κ⁰ (trapezoidal on the fine grid), then
/// positions by the same rule; scaled by √γ.
fn intrinsic_shape(phi0: f64, s: &[f64], kappa0: &[f64], scale: f64) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]];
    let (mut phi, mut x, mut z) = (phi0, 0.0, 0.0);
    for i in 1..s.len() {
        let h = s[i] - s[i - 1];
        let next = phi + 0.5 * h * (kappa0[i] + kappa0[i - 1]);
        x += 0.5 * h * (phi.sin() + next.sin());
        z += 0.5 * h * (phi.cos() + next.cos());
        phi = next;
        out.push([x * scale, 0.0, z * scale]);
    }
    out
}

/// Coefficients b1..bM of the least-squares polynomial Σ b_i s^{i−1}.
fn least_squares_polynomial(s: &[f64], y: &[f64], m: usize) -> Vec<f64> {
    let a = nalgebra::DMatrix::from_fn(s.len(), m, |i, j| s[i].powi(j as i32));
    let b = nalgebra::DVector::from_column_slice(y);
    a.svd(true, true)
        .solve(&b, 1e-14)
        .map(|v| v.as_slice().to_vec())
        .unwrap_or_else(|_| vec![f64::NAN; m])
}

/// −R̂ for Nelder–Mead; points outside the box are projected into it and
/// charged their squared distance.
struct ReachCost<'a> {
    problem: &'a ArmProblem,
    scene: &'a ArmScene,
    stop: &'a dyn Fn() -> bool,
    calls: std::cell::Cell<usize>,
}

impl CostFunction for &ReachCost<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Vec<f64>) -> Result<f64, ArgminError> {
        if (self.stop)() {
            // Stopping: the worst cost, not an error — argmin's Nelder–Mead
            // unwraps the costs of its first simplex (a panic), and the
            // caller discards a polish that ran into a stop.
            return Ok(f64::INFINITY);
        }
        self.calls.set(self.calls.get() + 1);
        let q = self.problem.project(p);
        let outside: f64 = p.iter().zip(&q).map(|(a, b)| (a - b).powi(2)).sum();
        let reach = self
            .problem
            .design_in(self.scene, &q)
            .map_or(0.0, |d| d.reach);
        Ok(-reach + outside)
    }
}

/// The intrinsically straight arm (κ⁰ = 0), solved directly: for each load
/// γ the clamp angle that puts the tip at elevation α (secant on the BVP
/// solution), and the largest γ at which that equilibrium is stable
/// (bisection on the Morse index of the verified second variation).
#[derive(Debug, Clone, PartialEq)]
pub struct StraightArm {
    /// R̂0 = √γ |tip|.
    pub reach: f64,
    /// The load γ of the farthest stable level equilibrium.
    pub gamma: f64,
    /// The clamp angle (rad, d3 turned towards d1).
    pub clamp_angle: f64,
    /// The loaded shape, scaled by √γ.
    pub loaded_shape: Vec<[f64; 3]>,
    /// Whether `stop()` ended the search early: then this is the farthest
    /// stable level equilibrium found so far, a lower bound of R̂0.
    pub interrupted: bool,
    /// What ended the stable level family beyond the largest load reached.
    pub limit: StraightLimit,
}

/// What ends the stable part of the straight arm's level family.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StraightLimit {
    /// The level equilibrium beyond it is unstable.
    StabilityLoss,
    /// No level equilibrium was found beyond it: a fold of the family, or
    /// a load the solver could not reach — R̂0 is then a lower bound, and
    /// said so (never taken silently for a stability limit).
    NoEquilibrium,
    /// The search was stopped before the end was found.
    Interrupted,
}

impl StraightLimit {
    /// `stability_loss`, `no_equilibrium` or `interrupted`.
    pub fn name(self) -> &'static str {
        match self {
            StraightLimit::StabilityLoss => "stability_loss",
            StraightLimit::NoEquilibrium => "no_equilibrium",
            StraightLimit::Interrupted => "interrupted",
        }
    }
}

impl ArmProblem {
    /// The straight rod at load γ with the clamp turned by θ.
    fn straight_rod(&self, gamma: f64, theta: f64) -> Rod {
        let mut rod = self.rod();
        rod.loads = rod.loads.scaled(gamma);
        rod.clamp.frame = rod.clamp.turned_frame(theta);
        rod
    }

    /// The equilibrium at (γ, θ), warm-started from a neighbouring one's
    /// clamp curvature (so that the level family is followed, not whatever
    /// branch a cold start from the straight rod falls onto), and its tip
    /// elevation error.
    fn straight_equilibrium(
        &self,
        gamma: f64,
        theta: f64,
        guess: Option<&[f64]>,
    ) -> Option<(crate::bvp::Equilibrium, f64)> {
        let rod = self.straight_rod(gamma, theta);
        let choice = crate::model::ModelChoice::for_rod(&rod);
        let opts = crate::bvp::SolverOptions {
            method: crate::bvp::Method::Shooting,
            strategy: if guess.is_some() {
                crate::bvp::Strategy::Direct
            } else {
                crate::bvp::Strategy::Auto
            },
            initial_guess: guess.map(|g| g.to_vec()),
            output_points: 101,
            // The elevation must be met to 1e-12 by the secant in θ, also
            // near Euler's load where the column amplifies residuals.
            newton: crate::bvp::newton::NewtonOptions {
                tolerance: 1e-13,
                ..Default::default()
            },
            ..Default::default()
        };
        let eq = crate::bvp::solve(&rod, &choice, &opts).ok()?;
        let tip = eq.tip().position;
        let error = (-tip[0]).atan2(tip[2]) - self.alpha;
        Some((eq, error))
    }

    /// The clamp curvature of an equilibrium as three body components.
    fn clamp_curvature(eq: &crate::bvp::Equilibrium) -> Vec<f64> {
        eq.samples[0].curvature.as_slice().to_vec()
    }

    /// The clamp angle at load γ that puts the tip at elevation α, by the
    /// secant method from (θ, κ(0)) of a neighbouring level equilibrium.
    fn level_clamp(
        &self,
        gamma: f64,
        theta: f64,
        guess: Option<&[f64]>,
    ) -> Option<(f64, crate::bvp::Equilibrium)> {
        let (eq0, mut f0) = self.straight_equilibrium(gamma, theta, guess)?;
        let mut k = Self::clamp_curvature(&eq0);
        let (mut t0, mut t1) = (theta, theta - 0.01 * f0.signum());
        for _ in 0..60 {
            let (eq, f1) = self.straight_equilibrium(gamma, t1, Some(&k))?;
            // Converged when the elevation is met, or when the secant no
            // longer moves θ: near Euler's load the elevation of a column
            // is only as accurate as the BVP's residual times the growing
            // amplification 1/(1 − γ/γ_E), so 1e-12 may be out of reach.
            if f1.abs() < 1e-12 {
                return Some((t1, eq));
            }
            if (t1 - t0).abs() < 1e-12 {
                // A stalled secant is accepted only with the tip level to
                // a micro-radian (the amplified residual near Euler's
                // load); otherwise it is a failure, never a level arm.
                return (f1.abs() < 1e-6).then_some((t1, eq));
            }
            k = Self::clamp_curvature(&eq);
            let next = crate::numerics::scalar::secant_step(t0, f0, t1, f1);
            (t0, f0, t1) = (t1, f1, next.clamp(t1 - 0.1, t1 + 0.1));
        }
        None
    }

    /// R̂0 of the intrinsically straight arm: the largest √γ |tip| over the
    /// stable level equilibria. The level family is followed in γ with warm
    /// starts (steps of 5 %) until its equilibrium loses stability or the
    /// family ends (the limit then bisected); R̂ need not grow all the way,
    /// so its largest value on the stable part is refined by golden-section
    /// search around the best step.
    pub fn straight(&self) -> Option<StraightArm> {
        self.straight_until(&|| false)
    }

    /// As [`Self::straight`], stopping early when `stop()` turns true
    /// (checked before every load step): the result is then the farthest
    /// stable level equilibrium found so far, marked interrupted.
    pub fn straight_until(&self, stop: &dyn Fn() -> bool) -> Option<StraightArm> {
        let opts = crate::bvp::SolverOptions::default();
        type Level = (f64, Vec<f64>);
        let reach =
            |gamma: f64, eq: &crate::bvp::Equilibrium| gamma.sqrt() * eq.tip().position.norm();
        let level = |gamma: f64, from: &Level| -> Option<(bool, Level, f64)> {
            let (theta, eq) = self.level_clamp(gamma, from.0, Some(&from.1))?;
            let rod = self.straight_rod(gamma, theta);
            let st = crate::stability::analyze(&rod, &eq, &opts, &self.stability).ok()?;
            Some((
                st.stable,
                (theta, Self::clamp_curvature(&eq)),
                reach(gamma, &eq),
            ))
        };
        let first = self.level_clamp(0.25, 0.0, None)?;
        let mut state: Level = (first.0, Self::clamp_curvature(&first.1));
        // (γ, state, R̂) of every stable step.
        let mut marched: Vec<(f64, Level, f64)> =
            vec![(0.25, state.clone(), reach(0.25, &first.1))];
        let best_of = |marched: &[(f64, Level, f64)]| {
            (0..marched.len()).max_by(|&a, &b| marched[a].2.total_cmp(&marched[b].2))
        };
        let interrupted = |marched: &[(f64, Level, f64)]| {
            let best = best_of(marched)?;
            self.straight_at(
                marched[best].0,
                &marched[best].1,
                StraightLimit::Interrupted,
            )
        };
        let reason = |found: &Option<(bool, Level, f64)>| match found {
            Some(_) => StraightLimit::StabilityLoss,
            None => StraightLimit::NoEquilibrium,
        };
        let mut limit: StraightLimit;
        let (mut lo, mut hi) = (0.25, 0.25 * 1.05);
        // A load where no level equilibrium is found counts as beyond the
        // limit, like an unstable one.
        loop {
            if stop() {
                return interrupted(&marched);
            }
            let found = level(hi, &state);
            let Some((true, next, r)) = found else {
                limit = reason(&found);
                break;
            };
            marched.push((hi, next.clone(), r));
            (lo, state) = (hi, next);
            hi *= 1.05;
            if hi > 1e4 {
                return None;
            }
        }
        let side = |mid: f64| {
            if stop() {
                return ControlFlow::Break(());
            }
            ControlFlow::Continue(match level(mid, &state) {
                Some((true, next, r)) => {
                    marched.push((mid, next.clone(), r));
                    state = next;
                    true
                }
                found => {
                    limit = reason(&found);
                    false
                }
            })
        };
        if bisect_or_break(lo, hi, 40, side, |lo, hi| hi - lo < 1e-10 * hi).is_break() {
            return interrupted(&marched);
        }
        let best = best_of(&marched)?;
        let (mut gamma, mut from) = (marched[best].0, marched[best].1.clone());
        if best > 0 && best + 1 < marched.len() {
            // Golden-section search for the largest R̂ between the neighbours.
            let (a, b) = (marched[best - 1].0, marched[best + 1].0);
            let f = |x: f64| {
                if stop() {
                    return ControlFlow::Break(());
                }
                ControlFlow::Continue(level(x, &from).map_or(f64::NEG_INFINITY, |l| l.2))
            };
            let ControlFlow::Continue((a, b)) =
                golden_section_max(a, b, 60, f, |a, b| b - a < 1e-9 * b)
            else {
                return interrupted(&marched);
            };
            gamma = 0.5 * (a + b);
            if let Some((_, l, _)) = level(gamma, &from) {
                from = l;
            }
        }
        self.straight_at(gamma, &from, limit)
    }

    /// The level equilibrium at load γ from a neighbouring one's state
    /// (θ, κ(0)), as a [`StraightArm`].
    fn straight_at(
        &self,
        gamma: f64,
        from: &(f64, Vec<f64>),
        limit: StraightLimit,
    ) -> Option<StraightArm> {
        let (theta, eq) = self.level_clamp(gamma, from.0, Some(&from.1))?;
        let scale = gamma.sqrt();
        Some(StraightArm {
            reach: scale * eq.tip().position.norm(),
            gamma,
            clamp_angle: theta,
            loaded_shape: eq
                .samples
                .iter()
                .map(|p| {
                    [
                        p.position[0] * scale,
                        p.position[1] * scale,
                        p.position[2] * scale,
                    ]
                })
                .collect(),
            interrupted: limit == StraightLimit::Interrupted,
            limit,
        })
    }
}

/// The rod of a design at its design load: the intrinsic curvature κ̄⁰2 of
/// (43) as a natural cubic spline through `points` nodes (exact at the
/// nodes), the clamp turned by c1 (the design's tangent at s = 0), the
/// scene's loads scaled by the design load.
pub fn designed_rod(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
) -> Rod {
    let rod0 = problem.rod_in(scene);
    let shape = FixedShape {
        turning_angle: Profile::Polynomial(design.shape_coefficients.clone()),
    };
    let s: Vec<f64> = (0..points)
        .map(|i| i as f64 / (points - 1) as f64)
        .collect();
    let c = &design.shape_coefficients;
    let dphi = derivative(c);
    let kappa0: Vec<f64> = shape
        .samples(&rod0, &s)
        .expect("a design's shape was integrated when its critical load was found")
        .iter()
        .map(|p| polynomial(&dphi, p.s) - design.gamma * p.moment[1])
        .collect();
    let mut rod = rod0.clone();
    rod.energy = Arc::new(LinearElastic {
        stiffness: [problem.b1, 1.0, problem.b3].map(Profile::Constant),
        intrinsic_curvature: [
            Profile::Constant(0.0),
            Profile::spline(s, kappa0),
            Profile::Constant(0.0),
        ],
    });
    rod.clamp.frame = rod.clamp.turned_frame(c[0]);
    rod.loads = rod.loads.scaled(design.gamma);
    rod
}

/// Continues the designed rod in `parameter` from nearly 0 to 1 (the
/// design) with the Hessian tracked on the design's own discretization, so
/// that λ = 1 is its γ_crit.
pub(crate) fn continue_to_design(
    problem: &ArmProblem,
    rod: Rod,
    parameter: crate::continuation::Parameter,
    stop: &dyn Fn() -> bool,
) -> Result<crate::continuation::Diagram, crate::continuation::ContinuationError> {
    let family = crate::continuation::Family::new(
        rod,
        parameter,
        crate::model::ModelLevel::Planar,
        32,
        crate::numerics::integrator::Tolerances::default(),
    );
    continue_family(problem, &family, stop)
}

/// Continues `family` from p = 10⁻³ to 1 with the design's own mesh,
/// stopping at the next point once `stop()` turns true (the diagram's
/// `stop_reason` is then "interrupted").
pub(crate) fn continue_family(
    problem: &ArmProblem,
    family: &crate::continuation::Family,
    stop: &dyn Fn() -> bool,
) -> Result<crate::continuation::Diagram, crate::continuation::ContinuationError> {
    use crate::continuation::{continuation, ContinuationOptions};
    let opts = ContinuationOptions {
        start: 1e-3,
        bounds: (0.0, 1.0),
        step: 0.02,
        max_step: 0.05,
        switch_depth: 0,
        max_points: 4000,
        stability: StabilityOptions {
            eigenvalues: 2,
            ..problem.stability
        },
        ..Default::default()
    };
    continuation(family, &opts, &mut |_, _| !stop())
}

/// The loading path of a designed arm (paper Sec. 5 warns that loading need
/// not reach the design): the rod with the design's intrinsic curvature
/// and clamp angle ([`designed_rod`]), continued in the load factor λ from
/// nearly unloaded to λ = 1 (the design load γ_crit) with the Hessian
/// tracked.
pub fn loading_path(
    problem: &ArmProblem,
    design: &ArmDesign,
    points: usize,
) -> Result<crate::continuation::Diagram, crate::continuation::ContinuationError> {
    loading_path_until(problem, &ArmScene::default(), design, points, &|| false)
}
