//! The discretization error of a reported optimum.
//!
//! The reach of a design is γ_crit of a finite-element pencil. Conforming
//! elements overestimate γ_crit (a Rayleigh–Ritz upper bound), and a
//! search maximizes R̂, so on a coarse mesh it drifts to the designs whose
//! γ_crit the mesh overestimates most: with a ±10 box at N = 100 linear
//! elements the Sec. 4.4 arm reports R* inflated by 18 %.
//!
//! Every reported optimum is therefore polished again on 2N and 4N
//! elements ([`MeshStudy`]): the measured convergence order p and
//! Richardson's estimate of the error of R̂_N. When the estimated error
//! (or the spread of the three values) exceeds [`REACH_TOLERANCE`], the
//! search is redone on a finer discretization ([`ArmProblem::refined`]:
//! order-2 elements first, then 4× the elements), and its optimum checked
//! there the same way, until the reported design is an optimum of a
//! discretization that resolves it ([`Verdict::Refined`]) or
//! [`MAX_ELEMENTS`] is reached ([`Verdict::Unresolved`], said so). The
//! optimum is also polished on three meshes of order-2 elements
//! ([`ReachLimit`]): R*(N → ∞) with a bound ~1e-8. Re-polishing the rejected design
//! alone is not enough: from the ±10 box's spurious optimum it ends on a
//! poor local optimum of the finer mesh (R̂ = 1.77 for the circular arm,
//! whose box holds designs reaching 1.9458).

use super::{ArmDesign, ArmOptimum, ArmProblem, ArmScene, SearchOptions, SearchProgress};
use crate::stability::StabilityOptions;

/// The relative discretization error of R̂ a reported optimum may have.
/// The paper gives R* to two or three digits; this is four.
pub const REACH_TOLERANCE: f64 = 1e-4;

/// The most elements a repeated search uses; its check uses 4×.
pub const MAX_ELEMENTS: usize = 1600;

/// The reach of one design on N, 2N and 4N elements.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshStudy {
    /// N, 2N, 4N.
    pub elements: [usize; 3],
    /// R̂ on each (NaN where none was found).
    pub reach: [f64; 3],
    /// Whether the values on 2N and 4N are the optima polished from the
    /// design on those meshes, not the design's own reach.
    pub local_optima: bool,
}

impl MeshStudy {
    /// The measured order p of R̂_N − R̂_∞ ∝ N^−p, from the three meshes;
    /// None (undecided) unless the differences shrink geometrically: same
    /// sign, the second smaller (at round-off they do not).
    pub fn order(&self) -> Option<f64> {
        let [a, b, c] = self.reach;
        let (d1, d2) = (a - b, b - c);
        (d1 * d2 > 0.0 && d2.abs() < d1.abs()).then(|| (d1 / d2).log2())
    }

    /// Richardson's estimate of the error of R̂_N, R̂_N − R̂_∞, with the
    /// measured order: (R̂_N − R̂_2N) 2^p / (2^p − 1). None with the order.
    pub fn error(&self) -> Option<f64> {
        let p = self.order()?;
        let r = 2f64.powf(p);
        Some((self.reach[0] - self.reach[1]) * r / (r - 1.0))
    }

    /// R̂_∞ = R̂_N − error (None with the order).
    pub fn extrapolated(&self) -> Option<f64> {
        Some(self.reach[0] - self.error()?)
    }

    /// The mesh-converged reach with a bound on its error: (R̂_∞, e) with
    /// R̂_∞ Richardson's extrapolation at the measured order and
    /// e = |R̂_4N − R̂_∞|, the estimated error of the finest mesh's value.
    ///
    /// Three meshes measure the order, so they cannot also measure the
    /// error of R̂_∞ (the extrapolations from (N, 2N) and from (2N, 4N) at
    /// the measured order are the same number). Richardson's value removes
    /// the leading term C N^−p; what is left is of higher order and, in the
    /// asymptotic range the geometric differences attest, smaller than that
    /// term on the finest mesh. So e is an estimated bound on the error of
    /// R̂_∞, a conservative one: it is the estimated error of R̂_4N itself.
    /// None with the order.
    pub fn converged(&self) -> Option<(f64, f64)> {
        let limit = self.extrapolated()?;
        Some((limit, (self.reach[2] - limit).abs()))
    }

    /// Whether R̂_N is resolved to `tolerance` (relative): the three values
    /// agree to it and, where the order is measured, so does the estimated
    /// error. A NaN (no critical load on a finer mesh) never agrees.
    pub fn resolved(&self, tolerance: f64) -> bool {
        let [a, b, c] = self.reach;
        if !(a.is_finite() && b.is_finite() && c.is_finite()) {
            return false;
        }
        let scale = tolerance * a.abs();
        let spread = (a - b).abs().max((a - c).abs());
        spread <= scale && self.error().is_none_or(|e| e.abs() <= scale)
    }
}

/// The Lagrange order of the elements of a [`ReachLimit`] (at least; the
/// search's own where higher): eigenvalues converge at O(h⁴) on quadratic
/// elements against O(h²) on linear ones, so three modest meshes give the
/// limit to ~1e-8 where linear elements on N, 2N, 4N leave ~1e-6.
pub const LIMIT_ORDER: usize = 2;

/// The fewest elements of a [`ReachLimit`]'s coarsest mesh.
pub const LIMIT_MIN_ELEMENTS: usize = 8;

/// The mesh-converged optimum R*(N → ∞): the reported optimum polished
/// again on three meshes of [`LIMIT_ORDER`] elements (max(N/4, 8), twice
/// and four times that, N the search's mesh), and Richardson's limit of
/// those optima at their measured order with its bound
/// ([`MeshStudy::converged`]: the finest mesh's estimated error).
#[derive(Debug, Clone, PartialEq)]
pub struct ReachLimit {
    /// The Lagrange order of the study's elements.
    pub order: usize,
    /// The optimum on the three meshes (local optima).
    pub study: MeshStudy,
}

impl ReachLimit {
    /// (R*(N → ∞), its error bound); None where the order is not measured
    /// (undecided, never a value).
    pub fn converged(&self) -> Option<(f64, f64)> {
        self.study.converged()
    }
}

/// What became of the search's optimum on finer meshes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The search mesh resolves the optimum to [`REACH_TOLERANCE`].
    Resolved,
    /// It did not; the search was redone on a finer mesh that does.
    Refined,
    /// No mesh up to [`MAX_ELEMENTS`] resolves it (or an interrupt
    /// stopped the finer search): R̂ carries the error reported with it.
    Unresolved,
}

impl Verdict {
    /// `resolved`, `refined` or `unresolved` (HDF5, sweep labels).
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Resolved => "resolved",
            Verdict::Refined => "refined",
            Verdict::Unresolved => "unresolved",
        }
    }
}

/// The discretization check of a reported design.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolution {
    /// The design's reach on its mesh (`study.elements[0]`, where the
    /// reported design was optimized), 2× and 4× that mesh.
    pub study: MeshStudy,
    /// Resolved, refined or unresolved.
    pub verdict: Verdict,
    /// The designs given up on the way, as (elements, R̂ there, R̂ on 4×
    /// the elements): the first search's optimum first.
    pub rejected: Vec<(usize, f64, f64)>,
}

impl ArmProblem {
    /// This problem on `elements` elements (a refinement of its valid
    /// mesh: at least as many elements).
    fn on_mesh(&self, elements: usize) -> ArmProblem {
        let mut p = self.clone();
        p.stability = p
            .stability
            .with_elements(elements)
            .expect("a refined mesh of valid options is valid");
        p
    }

    /// This problem on `elements` elements of Lagrange order `order`.
    fn on_mesh_of_order(&self, elements: usize, order: usize) -> ArmProblem {
        let mut p = self.clone();
        p.stability = StabilityOptions::new(elements, order, p.stability.eigenvalues())
            .expect("at least one element of order 1 to 3");
        p
    }

    /// R̂ of the design c2..cM on N (its value `reach`, already known), 2N
    /// and 4N elements, N = this problem's mesh; the evaluations used.
    ///
    /// With `iterations` > 0 the design is an optimum on N, and the values
    /// on 2N and 4N are the optima polished from it on each mesh (warm: a
    /// few exact-gradient steps, `iterations` at most), marked
    /// [`MeshStudy::local_optima`], so that Richardson's limit is that of
    /// the optimum R*, not of one design's reach (which the finer meshes
    /// no longer maximize). This also covers an optimum on an actuator
    /// limit, which sits where the limit and λ_crit meet: a finer mesh
    /// lowers λ_crit a little, and the design itself may have no load its
    /// actuators can hold there. With `iterations` = 0 (a design not
    /// chosen for its reach), and in a scene with an actuator limit (no
    /// gradient: a re-polish would be a whole Nelder–Mead) where the design
    /// is feasible on 2N and 4N, the values are the design's own reach.
    pub fn mesh_study(
        &self,
        scene: &ArmScene,
        design: &ArmDesign,
        iterations: u64,
    ) -> (MeshStudy, usize) {
        let (study, _, evaluations) = self.mesh_checks(scene, design, iterations);
        (study, evaluations)
    }

    /// [`Self::mesh_study`] and, where the values are re-polished optima,
    /// the [`ReachLimit`] of the optimum from meshes of order-2 elements;
    /// the evaluations used by both.
    ///
    /// The order-2 polish on the coarsest limit mesh goes first, from the
    /// design; its final quasi-Newton Hessian (R̂'s curvature hardly depends
    /// on the mesh) warm-starts the four others, which run in parallel:
    /// the order-2 meshes from its optimum, 2N and 4N from the design.
    fn mesh_checks(
        &self,
        scene: &ArmScene,
        design: &ArmDesign,
        iterations: u64,
    ) -> (MeshStudy, Option<ReachLimit>, usize) {
        let n = self.stability.elements();
        let rest = &design.shape_coefficients[1..];
        // Without a gradient (an actuator limit) a re-polish is a whole
        // Nelder–Mead per mesh: the design's own reach is kept where it
        // exists, as before the gradient polish.
        let own = iterations == 0 || scene.max_curvature.is_some();
        let reach = |m: usize| self.on_mesh(m).design_in(scene, rest).map(|d| d.reach);
        let (r2, r4) = if own {
            (reach(2 * n), reach(4 * n))
        } else {
            (None, None)
        };
        if iterations == 0 || (r2.is_some() && r4.is_some()) {
            // NaN marks a reach that does not exist (never read as a value:
            // `resolved` refuses it).
            let study = MeshStudy {
                elements: [n, 2 * n, 4 * n],
                reach: [design.reach, r2.unwrap_or(f64::NAN), r4.unwrap_or(f64::NAN)],
                local_optima: false,
            };
            return (study, None, 2);
        }
        let mut evaluations = if own { 2 } else { 0 };
        let order = self.stability.order().max(LIMIT_ORDER);
        let base = (n / 4).max(LIMIT_MIN_ELEMENTS);
        let coarse = self.on_mesh_of_order(base, order).polish_from(
            scene,
            rest,
            iterations,
            &|| false,
            None,
        );
        evaluations += coarse.evaluations;
        let hessian = coarse.hessian.as_ref();
        let from_coarse = coarse
            .design
            .as_ref()
            .map_or(rest, |d| &d.shape_coefficients[1..]);
        let jobs = [
            (self.on_mesh_of_order(2 * base, order), from_coarse),
            (self.on_mesh_of_order(4 * base, order), from_coarse),
            (self.on_mesh(2 * n), rest),
            (self.on_mesh(4 * n), rest),
        ];
        let polished = super::search::in_parallel(jobs.len(), &|| false, |k, _| {
            let (problem, start) = &jobs[k];
            Some(problem.polish_from(scene, start, iterations, &|| false, hessian))
        });
        let mut value = |p: Option<super::search::Polished>| {
            let p = p.expect("a job without a stop test runs");
            evaluations += p.evaluations;
            p.design.map_or(f64::NAN, |d| d.reach)
        };
        let values: Vec<f64> = polished.into_iter().map(&mut value).collect();
        let [l2, l4, r2, r4] = <[f64; 4]>::try_from(values).expect("four jobs");
        let study = MeshStudy {
            elements: [n, 2 * n, 4 * n],
            reach: [design.reach, r2, r4],
            local_optima: true,
        };
        let limit = coarse.design.map(|d| ReachLimit {
            order,
            study: MeshStudy {
                elements: [base, 2 * base, 4 * base],
                reach: [d.reach, l2, l4],
                local_optima: true,
            },
        });
        (study, limit, evaluations)
    }

    /// A reported design that is not a reach optimum (the map's 'Q', the
    /// least-Σb² design) with its discretization check: R̂ on 2N and 4N,
    /// resolved or not to [`REACH_TOLERANCE`]; never re-polished (it was
    /// not chosen for its reach).
    pub fn checked(&self, scene: &ArmScene, mut optimum: ArmOptimum) -> ArmOptimum {
        let (study, used) = self.mesh_study(scene, &optimum.design, 0);
        optimum.evaluations += used;
        optimum.resolution = Some(Resolution {
            verdict: if study.resolved(REACH_TOLERANCE) {
                Verdict::Resolved
            } else {
                Verdict::Unresolved
            },
            study,
            rejected: vec![],
        });
        optimum
    }

    /// The mesh a search is redone on where this problem's does not resolve
    /// its optimum: the same elements of order [`LIMIT_ORDER`] where they
    /// are of a lower order (p-refinement: the eigenvalue error drops from
    /// O(h²) to O(h⁴), as 4× the linear elements would only quarter it, at
    /// twice the cost of an evaluation instead of four times), else 4× the
    /// elements; None past [`MAX_ELEMENTS`].
    pub fn refined(&self) -> Option<ArmProblem> {
        let (n, order) = (self.stability.elements(), self.stability.order());
        if order < LIMIT_ORDER {
            Some(self.on_mesh_of_order(n, LIMIT_ORDER))
        } else {
            (4 * n <= MAX_ELEMENTS).then(|| self.on_mesh(4 * n))
        }
    }

    /// The optimum `optimum` (found on this problem's mesh by a search with
    /// `opts`), checked on finer meshes and, where they disagree beyond
    /// `tolerance`, searched for again on the [`Self::refined`] mesh — the
    /// whole search (the coarse mesh's ranking of the samples is what
    /// misled it), plus a polish from the rejected design, the better of
    /// the two kept — and checked there, until resolved or past
    /// [`MAX_ELEMENTS`]. Returns the reported optimum (its shapes from the
    /// mesh it was optimized on, [`ArmOptimum::mesh`]) with its
    /// [`Resolution`] and [`ReachLimit`]; the evaluations used are added to
    /// its count. `stop()` ends a finer search: the optimum so far is then
    /// returned, unresolved.
    pub fn resolve(
        &self,
        scene: &ArmScene,
        optimum: ArmOptimum,
        opts: &SearchOptions,
        tolerance: f64,
        stop: &dyn Fn() -> bool,
    ) -> ArmOptimum {
        let mut problem = self.clone();
        let mut optimum = optimum;
        let mut rejected = vec![];
        loop {
            let (study, limit, used) = problem.mesh_checks(scene, &optimum.design, opts.iterations);
            optimum.evaluations += used;
            optimum.limit = limit;
            optimum.mesh = problem.stability;
            let finer = problem.refined();
            let verdict = if study.resolved(tolerance) {
                Some(if rejected.is_empty() {
                    Verdict::Resolved
                } else {
                    Verdict::Refined
                })
            } else if finer.is_none() || stop() {
                Some(Verdict::Unresolved)
            } else {
                None
            };
            let (None, Some(finer)) = (verdict, finer) else {
                optimum.resolution = Some(Resolution {
                    study,
                    verdict: verdict.unwrap_or(Verdict::Unresolved),
                    rejected,
                });
                return optimum;
            };
            rejected.push((study.elements[0], study.reach[0], study.reach[2]));
            let (searched, progress, interrupted) =
                finer.search_on_mesh(scene, opts, SearchProgress::default(), stop, &mut |_| {});
            let start = &optimum.design.shape_coefficients[1..];
            let (polished, used) = if interrupted {
                (None, 0)
            } else {
                finer.polish(scene, start, opts.iterations, stop)
            };
            let evaluations = optimum.evaluations + progress.evaluations + used;
            let polished = polished.and_then(|d| finer.finish(scene, d, 0));
            let better = match (searched, polished) {
                (Some(a), Some(b)) => Some(if b.design.reach > a.design.reach {
                    b
                } else {
                    a
                }),
                (a, b) => a.or(b),
            };
            let Some(mut next) = better.filter(|_| !stop()) else {
                // Interrupted, or no design of the box has a critical load
                // on the finer mesh: the optimum stays, unresolved.
                optimum.evaluations = evaluations;
                optimum.resolution = Some(Resolution {
                    study,
                    verdict: Verdict::Unresolved,
                    rejected,
                });
                return optimum;
            };
            next.evaluations = evaluations;
            problem = finer;
            optimum = next;
        }
    }
}
