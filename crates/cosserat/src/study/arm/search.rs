//! The search for the farthest-reaching design: Owen-scrambled Sobol'
//! samples of the box of c2..cM (the global stage), then projected BFGS on
//! R̂ with its exact gradient from the best few (the polish, `polish.rs`
//! `ascend_in_box`; where R̂ has no gradient — a double critical load, an
//! actuator limit — Nelder–Mead (argmin) on −R̂ goes on from there, points
//! outside the box projected into it and charged their squared distance);
//! with the progress kept so that an interrupted search can be resumed.
//!
//! Samples and polishes run in parallel (rayon), each on its own data, and
//! are folded in their sequence order: the optimum is the same bit for bit
//! on any number of threads, and the same as a resumed run's.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::OnceLock;
use std::time::Duration;

use nalgebra::DMatrix;

use crate::model::Profile;
use crate::stability::{critical_load, FixedShape};

use super::design::{intrinsic_shape, least_squares_polynomial};
use super::polish::{ascend_in_box, box_simplex, polish_in_box, AscentEnd};
use super::{
    derivative, polynomial, ArmDesign, ArmOptimum, ArmProblem, ArmScene, SearchOptions,
    SearchProgress, REACH_TOLERANCE,
};

impl ArmProblem {
    /// Clamps a point into the bounds: the projection of Nelder–Mead's
    /// moves onto the search box `arm.bounds` (the domain of the search,
    /// not a change of a value the user gave).
    pub(super) fn project(&self, p: &[f64]) -> Vec<f64> {
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
    pub(super) fn search_on_mesh(
        &self,
        scene: &ArmScene,
        opts: &SearchOptions,
        mut progress: SearchProgress,
        stop: &dyn Fn() -> bool,
        checkpoint: &mut dyn FnMut(&SearchProgress),
    ) -> (Option<ArmOptimum>, SearchProgress, bool) {
        let keep = opts.starts.max(1);
        while progress.samples_done < opts.samples && !stop() {
            let first = progress.samples_done + 1;
            let count = SAMPLE_BATCH.min(opts.samples - progress.samples_done);
            let reaches = in_parallel(count, stop, |k, _| {
                let p = self.sample_point(first + k);
                Some(self.design_in(scene, &p).map(|d| d.reach))
            });
            // In sample order, so that the leaders (ties included) are those
            // of a sequential run, whatever the threads did first.
            for (k, reach) in reaches.into_iter().enumerate() {
                let Some(reach) = reach else { break };
                progress.evaluations += 1;
                if let Some(r) = reach {
                    let at = progress.leaders.partition_point(|(q, _)| *q >= r);
                    progress
                        .leaders
                        .insert(at, (r, self.sample_point(first + k)));
                    progress.leaders.truncate(keep);
                }
                progress.samples_done = first + k;
                checkpoint(&progress);
            }
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
        if progress.polishes_done < starts && !stop() {
            let first = progress.polishes_done;
            let leaders = &progress.leaders;
            let polished = in_parallel(starts - first, stop, |k, halt| {
                let start = &leaders[first + k].1;
                let halted = || halt.load(Ordering::Relaxed);
                let result = self.polish(scene, start, opts.iterations, &halted);
                // A polish that ran into a stop is redone on resumption.
                (!halted()).then_some(result)
            });
            // Folded in start order (the first of equal reaches kept), as a
            // sequential run does.
            for result in polished {
                let Some((design, used)) = result else { break };
                progress.evaluations += used;
                if let Some(d) = design {
                    if progress.best.as_ref().is_none_or(|b| d.reach > b.reach) {
                        progress.best = Some(d);
                    }
                }
                progress.polishes_done += 1;
                checkpoint(&progress);
            }
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
    pub(super) fn simplex(&self, start: &[f64]) -> Vec<Vec<f64>> {
        self.simplex_sized(start, 0.05)
    }

    /// The simplex with steps of `fraction` of each bound's width.
    pub(super) fn simplex_sized(&self, start: &[f64], fraction: f64) -> Vec<Vec<f64>> {
        box_simplex(start, &self.bounds, fraction)
    }

    /// The local optimum of R̂ from the shape c2..cM `start` on this
    /// problem's mesh, as the search polishes its leaders (below); the
    /// evaluations used. For checks on other meshes.
    pub fn polished(
        &self,
        scene: &ArmScene,
        start: &[f64],
        iterations: u64,
    ) -> (Option<ArmDesign>, usize) {
        self.polish(scene, start, iterations, &|| false)
    }

    /// The local optimum from `start`: projected BFGS on R̂ with its exact
    /// gradient ([`ascend_in_box`], at most `iterations` steps), and where
    /// the reach has no gradient on the way (a double critical load, an
    /// actuator limit) Nelder–Mead on −R̂ from where it stopped, at most
    /// `iterations` more.
    pub(super) fn polish(
        &self,
        scene: &ArmScene,
        start: &[f64],
        iterations: u64,
        stop: &dyn Fn() -> bool,
    ) -> (Option<ArmDesign>, usize) {
        let p = self.polish_from(scene, start, iterations, stop, None);
        (p.design, p.evaluations)
    }

    /// [`Self::polish`] with the ascent's Hessian model started from `warm`
    /// (where given) and returned with the design.
    pub(super) fn polish_from(
        &self,
        scene: &ArmScene,
        start: &[f64],
        iterations: u64,
        stop: &dyn Fn() -> bool,
        warm: Option<&DMatrix<f64>>,
    ) -> Polished {
        let ascent = ascend_in_box(
            start,
            &self.bounds,
            usize::try_from(iterations).unwrap_or(usize::MAX),
            &|x| self.reach_slope(scene, x).map(|r| r.branches),
            stop,
            warm,
        );
        let from = match (&ascent.end, &ascent.best) {
            (AscentEnd::Stopped, _) => {
                return Polished {
                    design: None,
                    evaluations: ascent.evaluations,
                    hessian: None,
                }
            }
            (AscentEnd::NoGradient, Some((x, _))) => x.clone(),
            // An infeasible start: the simplex may find feasible designs
            // around it.
            (AscentEnd::Infeasible, _) | (_, None) => start.to_vec(),
            (_, Some((x, _))) => {
                return Polished {
                    design: self.design_in(scene, x),
                    evaluations: ascent.evaluations + 1,
                    hessian: ascent.hessian,
                }
            }
        };
        let (design, used) = self.nelder_mead(scene, self.simplex(&from), iterations, stop);
        Polished {
            design,
            evaluations: ascent.evaluations + used,
            hessian: None,
        }
    }

    /// Nelder–Mead on −R̂ from a simplex; the polished design and the
    /// evaluations used.
    pub(super) fn nelder_mead(
        &self,
        scene: &ArmScene,
        simplex: Vec<Vec<f64>>,
        iterations: u64,
        stop: &dyn Fn() -> bool,
    ) -> (Option<ArmDesign>, usize) {
        let (best, calls) = polish_in_box(
            simplex,
            iterations,
            &|p| self.project(p),
            &|q| self.design_in(scene, q).map(|d| d.reach),
            stop,
        );
        let design = best.and_then(|q| self.design_in(scene, &q));
        (design, calls)
    }

    /// The optimum with its shapes, intrinsic curvature (43) and its
    /// Taylor fit (59), and the critical load of its shape.
    pub(super) fn finish(
        &self,
        scene: &ArmScene,
        design: ArmDesign,
        evaluations: usize,
    ) -> Option<ArmOptimum> {
        let rod = self.rod_in(scene).ok()?;
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(design.shape_coefficients.clone()),
        };
        let critical = critical_load(&rod, &shape, &self.stability)
            .ok()?
            .load_factor?;
        let n = 101;
        let points: Vec<f64> = (0..n).map(|i| f64::from(i) / f64::from(n - 1)).collect();
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
            limit: None,
            mesh: self.stability,
        })
    }
}

/// A polish's result: the design, the evaluations used, and the ascent's
/// final Hessian model where it ended by gradient steps.
pub(super) struct Polished {
    pub design: Option<ArmDesign>,
    pub evaluations: usize,
    pub hessian: Option<DMatrix<f64>>,
}

/// Samples evaluated between two looks at the stop test and checkpoints.
const SAMPLE_BATCH: usize = 64;

/// `job(k, halt)` for k = 0..count on rayon's threads, the results in k
/// order; `None` for a job that `stop()` cut short (it returned `None`
/// after seeing `halt`, or never started).
///
/// `stop` is the caller's test and need not be `Sync` (a Python or sweep
/// interrupt lives on its own thread), so only the calling thread calls it:
/// it polls `stop()` between running queued jobs itself
/// (`rayon::yield_now`: on a one-thread pool it runs them all) and raises
/// `halt`, which the jobs read.
pub(super) fn in_parallel<T, F>(count: usize, stop: &dyn Fn() -> bool, job: F) -> Vec<Option<T>>
where
    T: Send + Sync,
    F: Fn(usize, &AtomicBool) -> Option<T> + Sync,
{
    let halt = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let slots: Vec<OnceLock<Option<T>>> = (0..count).map(|_| OnceLock::new()).collect();
    rayon::in_place_scope(|scope| {
        for (k, slot) in slots.iter().enumerate() {
            let (halt, done, job) = (&halt, &done, &job);
            scope.spawn(move |_| {
                // Counted even when the job panics (the scope re-raises it),
                // so that the polling below ends.
                let _finished = Finished(done);
                let result = if halt.load(Ordering::Relaxed) {
                    None
                } else {
                    job(k, halt)
                };
                let _ = slot.set(result);
            });
        }
        while done.load(Ordering::Acquire) < count {
            if !halt.load(Ordering::Relaxed) && stop() {
                halt.store(true, Ordering::Relaxed);
            }
            if rayon::yield_now() != Some(rayon::Yield::Executed) {
                std::thread::sleep(Duration::from_micros(200));
            }
        }
    });
    slots
        .into_iter()
        .map(|slot| slot.into_inner().flatten())
        .collect()
}

/// Counts a job as finished when dropped.
struct Finished<'a>(&'a AtomicUsize);

impl Drop for Finished<'_> {
    fn drop(&mut self) {
        self.0.fetch_add(1, Ordering::Release);
    }
}
