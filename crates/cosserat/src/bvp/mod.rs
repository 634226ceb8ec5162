//! Equilibria: the boundary value problem of a clamped rod solved by single
//! or multiple shooting or by Gauss–Legendre collocation on an adapted mesh,
//! each with a damped Newton method, falling back to a load
//! ramp (natural-parameter homotopy from the unloaded rod) when the loads
//! are too large for a direct start.
//!
//! `solve` is the one entry point: problem (a [`Rod`] and its
//! [`ModelChoice`]), algorithm ([`Method`] in [`SolverOptions`]), result
//! ([`Equilibrium`]) — the problem / algorithm / solve split of
//! DifferentialEquations.jl.

mod collocation;
mod gauss_step;
pub use crate::numerics::integrator;
pub mod newton;
mod shooting;

use std::sync::Arc;
use std::time::Instant;

use nalgebra::DMatrix;

use crate::equations::{KirchhoffEquations, PlanarEquations, RodEquations, RodSample};
use crate::model::energy_check;
use crate::model::{ModelChoice, ModelLevel, Rod};
use crate::numerics::integrator::{DenseRecord, IntegrationStats, Tolerances};
pub use collocation::{
    solve_collocation, solve_collocation_from, CollocationError, CollocationOptions,
    CollocationSolution,
};
use newton::{NewtonFailure, NewtonOptions};
pub use shooting::ShootingSystem;

/// How the BVP is discretized.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Single shooting on the curvature at the clamp.
    Shooting,
    /// Multiple shooting on `segments` equal segments.
    MultipleShooting {
        /// Number of equal shooting segments, each with its own unknown initial
        /// state.
        segments: usize,
    },
    /// Gauss–Legendre collocation with `stages` points per interval (order
    /// 2·stages at the nodes) on a mesh adapted until the error estimate
    /// meets [`SolverOptions::collocation`]'s tolerance; the other settings
    /// (starting mesh, tolerance, budget) come from there, its `stages`
    /// field is overridden by this one.
    Collocation {
        /// Gauss points per interval (order 2·stages at the nodes).
        stages: usize,
    },
}

impl Method {
    /// The name used on the command line and in output files.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Shooting => "shooting",
            Method::MultipleShooting { .. } => "multiple-shooting",
            Method::Collocation { .. } => "collocation",
        }
    }

    /// The shooting segments (1 for shooting and collocation).
    pub fn segments(&self) -> usize {
        match *self {
            Method::Shooting | Method::Collocation { .. } => 1,
            Method::MultipleShooting { segments } => segments.max(1),
        }
    }
}

/// Everything that controls a solve.
#[derive(Debug, Clone, PartialEq)]
pub struct SolverOptions {
    /// The discretization.
    pub method: Method,
    /// Newton's tolerance and budget; the residual is scaled by the rod's
    /// moment scale (and matching conditions by L, 1/L), so it is relative.
    pub newton: NewtonOptions,
    /// The integrator's tolerances (shooting).
    pub integration: Tolerances,
    /// Mesh, error tolerance and interval budget of collocation.
    pub collocation: CollocationOptions,
    /// Number of equally spaced output points along the rod (≥ 2).
    pub output_points: usize,
    /// A guess of the curvature at the clamp; the straight-rod balance when
    /// absent.
    pub initial_guess: Option<Vec<f64>>,
    /// A guess of the tip support's reaction force R (global components,
    /// the force the support exerts on the tip) when the support holds the
    /// tip's position; zero when absent. A displacement-controlled rod far
    /// from its unloaded shape needs it: with R = 0 Newton starts from a
    /// rod that no force holds there.
    pub initial_reaction: Option<nalgebra::Vector3<f64>>,
    /// How the loads are applied.
    pub strategy: Strategy,
}

/// How the loads are applied: all at once from the linear guess, or ramped
/// up from the unloaded rod so that Newton follows the branch that loading
/// the real rod follows (a direct start at a large load may converge to
/// another, looped equilibrium).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strategy {
    /// Ramp when the loads' moment exceeds the stiffness moment B_min/L;
    /// otherwise direct, ramping only if the direct solve fails.
    Auto,
    /// All loads at once; fail if Newton fails.
    Direct,
    /// Always ramp from the unloaded rod.
    Ramp,
}

impl Strategy {
    /// The name used in problem files.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Auto => "auto",
            Strategy::Direct => "direct",
            Strategy::Ramp => "ramp",
        }
    }
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            method: Method::Shooting,
            newton: NewtonOptions::default(),
            integration: Tolerances::default(),
            collocation: CollocationOptions::default(),
            output_points: 201,
            initial_guess: None,
            initial_reaction: None,
            strategy: Strategy::Auto,
        }
    }
}

/// What the solution is stored as, beyond its samples: enough to evaluate
/// it anywhere ([`Equilibrium::resample`]).
#[derive(Debug, Clone)]
pub enum Discretization {
    /// Shooting: the solution is re-integrated from
    /// [`Equilibrium::unknowns`].
    Shooting,
    /// Collocation: the mesh, node states and stage values.
    Collocation(Box<CollocationSolution>),
}

/// A converged equilibrium.
#[derive(Debug, Clone)]
pub struct Equilibrium {
    /// The model level used and why.
    pub model: ModelChoice,
    /// The method used.
    pub method: Method,
    /// The solution at the output points.
    pub samples: Vec<RodSample>,
    /// The free initial values at the solution (κ(0) components).
    pub clamp_curvature: Vec<f64>,
    /// The full vector of shooting unknowns (κ(0) and the interior node
    /// states of multiple shooting): enough to re-integrate the solution.
    /// Empty for collocation (see `discretization`).
    pub unknowns: Vec<f64>,
    /// The scaled shooting Jacobian at the solution; singular exactly where
    /// the linearized BVP is (folds and branch points). 0 × 0 for
    /// collocation.
    pub jacobian: DMatrix<f64>,
    /// The discrete solution behind the samples.
    pub discretization: Discretization,
    /// Newton steps of the final solve.
    pub iterations: usize,
    /// Scaled residual (max-norm) at every Newton iterate of the final solve.
    pub residual_history: Vec<f64>,
    /// The final scaled residual.
    pub residual: f64,
    /// Load-ramp steps used (0 when the direct solve converged).
    pub load_steps: usize,
    /// Largest |d_i·d_j − δ_ij| over the output points.
    pub director_drift: f64,
    /// Integration work over all Newton iterations (zero for collocation).
    pub integration: IntegrationStats,
    /// Wall time of the solve (s).
    pub wall_time: f64,
    /// Shooting: the continuous extension of the integration that sampled
    /// the solution, with the tolerances it was made with (what
    /// [`Equilibrium::resample`] reads instead of integrating again).
    recorded: Option<(Tolerances, Arc<DenseRecord>)>,
}

impl Equilibrium {
    /// The sample at the tip, s = L.
    pub fn tip(&self) -> &RodSample {
        self.samples
            .last()
            .expect("an equilibrium has at least two samples")
    }

    /// The solution at other points (sorted, in [0, L]) of `rod` (the rod
    /// it was solved for): evaluated from the collocation solution
    /// ([`CollocationSolution::sample`]); for shooting read from the
    /// continuous extension recorded when the solve sampled it, where that
    /// integration had the tolerances in `opts` (its steps do not depend
    /// on the points, so this is what integrating again would give), else
    /// re-integrated from the converged unknowns with them. Used by the
    /// stability analysis at its quadrature points.
    pub fn resample(
        &self,
        rod: &Rod,
        opts: &SolverOptions,
        points: &[f64],
    ) -> Result<Vec<RodSample>, SolveError> {
        let eq = equations(rod, self.model.level);
        if let Discretization::Collocation(sol) = &self.discretization {
            return Ok(sol.sample(eq.as_ref(), points));
        }
        if let Some((tol, record)) = &self.recorded {
            if *tol == opts.integration {
                if let Some(samples) =
                    read_record(eq.as_ref(), record, points, |s, y| eq.sample(s, y))
                {
                    return Ok(samples);
                }
            }
        }
        let mut sys = ShootingSystem::new(eq.as_ref(), self.method.segments(), opts.integration);
        let (samples, _) = sys
            .sample(&self.unknowns, points)
            .map_err(SolveError::Sampling)?;
        Ok(samples)
    }

    /// The largest |κ| at `points`, read from the recorded extension
    /// without building whole samples where the record serves (else from
    /// [`Self::resample`]).
    pub fn max_curvature(
        &self,
        rod: &Rod,
        opts: &SolverOptions,
        points: &[f64],
    ) -> Result<f64, SolveError> {
        // NaN-propagating: a non-finite curvature must reach the caller.
        let largest = |k: Vec<f64>| {
            k.into_iter().fold(0.0, |a: f64, b| {
                if a.is_nan() || b.is_nan() {
                    f64::NAN
                } else {
                    a.max(b)
                }
            })
        };
        if let (Discretization::Shooting, Some((tol, record))) =
            (&self.discretization, &self.recorded)
        {
            if *tol == opts.integration {
                let eq = equations(rod, self.model.level);
                let norms = read_record(eq.as_ref(), record, points, |s, y| {
                    eq.curvature(s, y).norm()
                });
                if let Some(norms) = norms {
                    return Ok(largest(norms));
                }
            }
        }
        let samples = self.resample(rod, opts, points)?;
        Ok(largest(
            samples.iter().map(|s| s.curvature.norm()).collect(),
        ))
    }
}

/// `read(s, y)` of each state of `eq` at `points` from a recorded
/// continuous extension, each state projected as the integrator projects
/// its stops; None when a point lies outside the record.
fn read_record<T>(
    eq: &dyn RodEquations,
    record: &DenseRecord,
    points: &[f64],
    read: impl Fn(f64, &[f64]) -> T,
) -> Option<Vec<T>> {
    let mut y = vec![0.0; eq.dim()];
    let mut out = Vec::with_capacity(points.len());
    for &s in points {
        if !record.state_at(s, &mut y) {
            return None;
        }
        eq.project(&mut y);
        out.push(read(s, &y));
    }
    Some(out)
}

/// Why no equilibrium was returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// Newton did not converge.
    #[error("{method} did not converge: {failure}; scaled residual history {history}")]
    NoConvergence {
        /// The method that failed ([`Method::name`]).
        method: &'static str,
        /// Why Newton stopped.
        failure: NewtonFailure,
        /// The scaled residual at every iterate, formatted for the message.
        history: String,
    },
    /// The load ramp stalled.
    #[error(
        "{method} with a load ramp stalled at load factor {reached:.4} (step {step:.2e}): {last}"
    )]
    RampStalled {
        /// The method that failed.
        method: &'static str,
        /// The last load factor in [0, 1] at which an equilibrium was found.
        reached: f64,
        /// The load-factor step when the ramp gave up (below 1e-4, or
        /// after 400 steps).
        step: f64,
        /// The last failure, in words.
        last: String,
    },
    /// The converged solution could not be re-integrated for output.
    #[error("sampling the converged solution failed: {0}")]
    Sampling(integrator::IntegrationError),
    /// Collocation returned no solution (Newton failed, a singular
    /// Jacobian, or the mesh tolerance not reached within the budget).
    #[error("collocation (order {order}) failed: {failure}")]
    Collocation {
        /// Order of the collocation (2·stages).
        order: usize,
        /// Why collocation failed.
        failure: CollocationError,
    },
    /// Options that cannot work.
    #[error("invalid solver options: {0}")]
    Options(String),
    /// A rod the equations cannot represent (a singular energy Hessian).
    #[error("invalid rod: {0}")]
    Model(String),
    /// The solve failed where the shear-extension strain of a general
    /// energy W(s, κ, ν) had no solution of W_ν = N (the material cannot
    /// carry the force there): the first such failure, then the solver's.
    #[error("no shear-extension strain: {strain}; then {after}")]
    ShearStrain {
        /// Why Newton for ν stopped ([`crate::model::StrainError`]).
        strain: String,
        /// The solver's own failure.
        after: Box<SolveError>,
    },
}

/// The equations of a rod at a model level.
pub fn equations(rod: &Rod, level: ModelLevel) -> Box<dyn RodEquations> {
    match level {
        ModelLevel::Planar => Box::new(PlanarEquations::new(rod.clone())),
        ModelLevel::Kirchhoff => Box::new(KirchhoffEquations::new(rod.clone())),
        ModelLevel::Cosserat => Box::new(KirchhoffEquations::cosserat(rod.clone())),
    }
}

/// Solves for the equilibrium of `rod` with the level in `model`.
pub fn solve(
    rod: &Rod,
    model: &ModelChoice,
    opts: &SolverOptions,
) -> Result<Equilibrium, SolveError> {
    if opts.output_points < 2 {
        return Err(SolveError::Options(
            "output_points must be at least 2".into(),
        ));
    }
    check_energy(rod)?;
    if rod.clamp().hinge && model.level != ModelLevel::Planar {
        return Err(SolveError::Model(format!(
            "a hinged base (clamp.hinge) is implemented in the planar model only; this scene \
             runs the {} model ({})",
            model.level.name(),
            model.reason
        )));
    }
    let start = Instant::now();
    let mut stats = IntegrationStats::default();
    let (solved, load_steps) = match opts.strategy {
        Strategy::Direct => (
            solve_at(rod, model.level, opts, None, Role::Final, &mut stats)?,
            0,
        ),
        Strategy::Ramp => ramp(rod, model.level, opts, &mut stats, None)?,
        // A direct start above B_min/L may converge, even cleanly, to
        // another (looped) equilibrium: the long rod of
        // tests/failure_regimes.rs does.
        Strategy::Auto if load_ratio(rod) > 1.0 => ramp(rod, model.level, opts, &mut stats, None)?,
        Strategy::Auto => match solve_at(rod, model.level, opts, None, Role::Final, &mut stats) {
            Ok(solved) => (solved, 0),
            Err(e) if e.ramp_may_help() => ramp(rod, model.level, opts, &mut stats, Some(e))?,
            Err(e) => return Err(e),
        },
    };
    let eq = equations(rod, model.level);
    let points = output_grid(rod.length(), opts.output_points);
    let drift_of = |samples: &[RodSample]| {
        samples
            .iter()
            .map(RodSample::director_drift)
            .fold(0.0, f64::max)
    };
    let equilibrium = match solved {
        Solved::Shooting { x, report } => {
            let mut sys =
                ShootingSystem::new(eq.as_ref(), opts.method.segments(), opts.integration);
            let (samples, drift, record) = sys
                .sample_recorded(&x, &points)
                .map_err(SolveError::Sampling)?;
            stats += sys.stats;
            Equilibrium {
                model: model.clone(),
                method: opts.method,
                samples,
                clamp_curvature: sys.free_values(&x).to_vec(),
                unknowns: x.clone(),
                jacobian: report.jacobian.clone(),
                discretization: Discretization::Shooting,
                iterations: report.iterations,
                residual: *report.history.last().unwrap_or(&f64::NAN),
                residual_history: report.history,
                load_steps,
                director_drift: drift,
                integration: stats,
                wall_time: 0.0,
                recorded: Some((opts.integration, Arc::new(record))),
            }
        }
        Solved::Collocation(sol) => {
            let samples = sol.sample(eq.as_ref(), &points);
            let drift = drift_of(&samples).max(sol.director_drift);
            Equilibrium {
                model: model.clone(),
                method: opts.method,
                clamp_curvature: eq.unknowns_of(&sol.states[0]),
                samples,
                unknowns: Vec::new(),
                jacobian: DMatrix::zeros(0, 0),
                iterations: sol.iterations,
                residual: sol.residual,
                residual_history: sol.residual_history.clone(),
                discretization: Discretization::Collocation(Box::new(sol)),
                load_steps,
                director_drift: drift,
                integration: stats,
                wall_time: 0.0,
                recorded: None,
            }
        }
    };
    check_derivatives_along(rod, &equilibrium.samples)?;
    Ok(Equilibrium {
        wall_time: start.elapsed().as_secs_f64(),
        ..equilibrium
    })
}

/// Whether the energy's derivatives are checked before and after a solve:
/// a program's own energy always (its hand-written derivatives are what a
/// wrong answer would come from), every energy in debug builds.
fn derivatives_checked(rod: &Rod) -> bool {
    cfg!(debug_assertions) || !rod.energy().derivatives_trusted()
}

/// The material along the solution, before it is reported: H positive
/// definite at every sample (where it is not, the material itself is
/// unstable — a material instability, not a structural one — and the
/// equations κ' = H⁻¹(…) do not hold), and, for an energy whose derivatives
/// are not trusted, the derivatives at (at most 17 of) the samples' strains.
fn check_derivatives_along(rod: &Rod, samples: &[RodSample]) -> Result<(), SolveError> {
    let energy = rod.energy();
    if let Some(x) = samples
        .iter()
        .find(|x| !positive_definite(&energy.stiffness(x.s, &x.curvature)))
    {
        return Err(SolveError::Model(format!(
            "the {} energy's Hessian is not positive definite at s = {}, κ = ({:e}, {:e}, {:e})              of the solution: the material is unstable there (a material instability, not a              structural one), and no equilibrium of this model is reported",
            energy.name(),
            x.s,
            x.curvature[0],
            x.curvature[1],
            x.curvature[2]
        )));
    }
    if !derivatives_checked(rod) || samples.is_empty() {
        return Ok(());
    }
    let every = samples.len().div_ceil(17);
    let at: Vec<_> = samples
        .iter()
        .step_by(every)
        .map(|x| (x.s, x.curvature))
        .collect();
    let scale = energy_check::typical_curvature(rod);
    let report = energy_check::check_at(energy.as_ref(), rod.length(), scale, &at);
    derivative_verdict(rod, "along the solution", &report)
}

fn derivative_verdict(
    rod: &Rod,
    place: &str,
    report: &energy_check::EnergyCheck,
) -> Result<(), SolveError> {
    // Positive definiteness has its own check and message (a material
    // instability); this verdict is about the derivatives.
    let wrong = report
        .failures()
        .find(|f| f.property != energy_check::Property::Convexity);
    match wrong {
        None => Ok(()),
        Some(f) => Err(SolveError::Model(format!(
            "the {} energy's {} disagrees with a difference of the quantity it derives              (by {:.2e} relative at s = {}, κ = ({:e}, {:e}, {:e}), {place}): a wrong              hand-written derivative gives a wrong equilibrium; `cosserat check-energy`              lists every sample",
            rod.energy().name(),
            f.property.name(),
            f.error,
            f.s,
            f.kappa[0],
            f.kappa[1],
            f.kappa[2]
        ))),
    }
}

impl SolveError {
    /// Whether a load ramp could cure this failure of a direct solve: not
    /// for bad options or a mesh budget that is too small.
    fn ramp_may_help(&self) -> bool {
        match self {
            SolveError::Options(_) | SolveError::Model(_) => false,
            SolveError::Collocation { failure, .. } => !matches!(
                failure,
                CollocationError::Options(_)
                    | CollocationError::ToleranceNotReached { .. }
                    | CollocationError::CoarseMesh { .. }
            ),
            _ => true,
        }
    }
}

/// A converged discrete solution, before sampling.
enum Solved {
    Shooting {
        x: Vec<f64>,
        report: newton::NewtonReport,
    },
    Collocation(CollocationSolution),
}

impl Solved {
    /// Newton converged as a load-ramp step must: no damping, at most
    /// `RAMP_ITERATIONS` steps and contraction Θ ≤ `theta`.
    fn ramp_step(&self, theta: f64) -> bool {
        let (damped, iterations, contraction) = match self {
            Solved::Shooting { report, .. } => {
                (report.damped_steps, report.iterations, report.contraction)
            }
            Solved::Collocation(sol) => (sol.damped_steps, sol.iterations, sol.contraction),
        };
        damped == 0 && iterations <= RAMP_ITERATIONS && contraction <= theta
    }
}

/// The energy Hessian H = ∂²W/∂κ² must be positive definite for
/// κ' = H⁻¹(M' − ∂s∇W) to exist (see [`crate::model::StoredEnergy`]);
/// checked on the undeformed rod at 65
/// points, and along the solution by the integrator (a singular H there
/// makes the state non-finite, reported as a blow-up). An energy whose
/// derivatives are not trusted has them checked first
/// ([`energy_check::check`]).
fn check_energy(rod: &Rod) -> Result<(), SolveError> {
    if derivatives_checked(rod) {
        let report = energy_check::check(
            rod.energy().as_ref(),
            rod.length(),
            energy_check::typical_curvature(rod),
        );
        derivative_verdict(rod, "before the solve", &report)?;
    }
    let kappa = nalgebra::Vector3::zeros();
    for i in 0..=64 {
        let s = rod.length() * f64::from(i) / 64.0;
        let h = rod.energy().stiffness(s, &kappa);
        if !positive_definite(&h) {
            return Err(SolveError::Model(format!(
                "the Hessian of the {} energy is not positive definite at s = {s} \
                 (diagonal {:e}, {:e}, {:e}); check energy.stiffness and the energy's parameters",
                rod.energy().name(),
                h[(0, 0)],
                h[(1, 1)],
                h[(2, 2)]
            )));
        }
        if let Some(strain) = rod.energy().strain_energy() {
            let h = strain
                .strain_jet(s, &kappa, &nalgebra::Vector3::z())
                .hessian;
            if !h.iter().all(|v| v.is_finite()) || h.cholesky().is_none() {
                return Err(SolveError::Model(format!(
                    "the 6 × 6 tangent stiffness of the {} energy in (κ, ν) is not positive \
                     definite at s = {s} on the unstrained rod (material instability); check \
                     the energy's shear and extension terms",
                    rod.energy().name()
                )));
            }
        }
    }
    Ok(())
}

/// Whether the symmetric 3 × 3 matrix `h` is positive definite, by
/// Sylvester's criterion (its leading principal minors h11, h11 h22 − h12²
/// and det h all positive; false for a non-finite entry). The solver asks
/// this at 65 points before and at every sample after a solve: the minors
/// cost a tenth of a Cholesky factorization, which showed as 9 % of a
/// 30 µs shooting solve.
fn positive_definite(h: &nalgebra::Matrix3<f64>) -> bool {
    let minor2 = h[(0, 0)] * h[(1, 1)] - h[(0, 1)] * h[(1, 0)];
    // `> 0.0` is false for NaN.
    h[(0, 0)] > 0.0 && minor2 > 0.0 && h.determinant() > 0.0 && h.iter().all(|v| v.is_finite())
}

/// `n` equally spaced points on [0, L], the last exactly L.
fn output_grid(length: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            if i + 1 == n {
                length
            } else {
                length * i as f64 / (n - 1) as f64
            }
        })
        .collect()
}

/// What a Newton solve is for: the equilibrium returned, or a load-ramp
/// step that only starts the next one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    /// The returned equilibrium: shooting polishes its root to round-off
    /// ([`newton::solve_polished`]), so that it does not depend on how
    /// close the start was.
    Final,
    /// An intermediate ramp step: converged to its options' tolerance and
    /// no further.
    WarmStart,
}

/// One Newton solve from a warm start (a solution of the same method at a
/// nearby load) or from the guess in the options.
fn solve_at(
    rod: &Rod,
    level: ModelLevel,
    opts: &SolverOptions,
    warm: Option<&Solved>,
    role: Role,
    stats: &mut IntegrationStats,
) -> Result<Solved, SolveError> {
    let eq = equations(rod, level);
    attempt(eq.as_ref(), level, opts, warm, role, stats).map_err(|after| match eq.failure() {
        Some(strain) => SolveError::ShearStrain {
            strain,
            after: Box::new(after),
        },
        None => after,
    })
}

/// One Newton solve of `eq` ([`solve_at`]).
fn attempt(
    eq: &dyn RodEquations,
    level: ModelLevel,
    opts: &SolverOptions,
    warm: Option<&Solved>,
    role: Role,
    stats: &mut IntegrationStats,
) -> Result<Solved, SolveError> {
    let guess = |eq: &dyn RodEquations| {
        let mut u = match &opts.initial_guess {
            Some(g) => guess_for_level(g, eq, level)?,
            None => eq.initial_guess(),
        };
        if let Some(r) = &opts.initial_reaction {
            if !eq.set_reaction(&mut u, r) {
                return Err(SolveError::Options(
                    "initial_reaction needs a tip support that holds the tip's position".into(),
                ));
            }
        }
        Ok(u)
    };
    if let Method::Collocation { stages } = opts.method {
        let copts = CollocationOptions {
            stages,
            ..opts.collocation
        };
        let warm = match warm {
            Some(Solved::Collocation(sol)) => Some(sol),
            _ => None,
        };
        let u = match warm {
            Some(_) => None,
            None => Some(guess(eq)?),
        };
        let fail = |failure| SolveError::Collocation {
            order: 2 * stages,
            failure,
        };
        let sol =
            solve_collocation_from(eq, &copts, &opts.newton, warm, u.as_deref()).map_err(fail)?;
        if !copts.adapt && (sol.error_estimate.is_nan() || sol.error_estimate > copts.tolerance) {
            return Err(fail(CollocationError::CoarseMesh {
                tolerance: copts.tolerance,
                estimate: sol.error_estimate,
                intervals: sol.intervals(),
            }));
        }
        return Ok(Solved::Collocation(sol));
    }
    let mut sys = ShootingSystem::new(eq, opts.method.segments(), opts.integration);
    let x0 = if let Some(Solved::Shooting { x, .. }) = warm {
        x.clone()
    } else {
        let u = guess(eq)?;
        sys.initial_unknowns(&u)
    };
    let outcome = match role {
        Role::Final => newton::solve_polished(&mut sys, &x0, &opts.newton),
        Role::WarmStart => newton::solve(&mut sys, &x0, &opts.newton),
    };
    *stats += sys.stats;
    match outcome {
        Ok(report) => Ok(Solved::Shooting {
            x: report.x.clone(),
            report,
        }),
        Err(failure) => Err(SolveError::NoConvergence {
            method: opts.method.name(),
            history: format_history(failure.history()),
            failure,
        }),
    }
}

/// A user's κ(0) guess (three body components) for the level's unknowns.
fn guess_for_level(
    g: &[f64],
    eq: &dyn RodEquations,
    level: ModelLevel,
) -> Result<Vec<f64>, SolveError> {
    if g.len() != 3 {
        return Err(SolveError::Options(
            "initial_curvature needs three components".into(),
        ));
    }
    // The curvature components the level carries, then a zero reaction
    // when the tip support holds the position.
    let mut u = match level {
        ModelLevel::Planar => vec![g[1]],
        ModelLevel::Kirchhoff | ModelLevel::Cosserat => g.to_vec(),
    };
    u.resize(eq.unknowns(), 0.0);
    Ok(u)
}

/// The loads' moment over the stiffness moment B_min/L: the size of the
/// deflection in radians that linear theory predicts.
fn load_ratio(rod: &Rod) -> f64 {
    let h = rod.energy().stiffness(0.0, &nalgebra::Vector3::zeros());
    let b_min = h.symmetric_eigenvalues().min();
    rod.loads().moment_scale(rod.length()) * rod.length() / b_min
}

/// The most Newton steps a load-ramp step may take.
const RAMP_ITERATIONS: usize = 8;
/// The largest contraction Θ of a load-ramp step's Newton iteration
/// (Deuflhard's continuation step control).
const RAMP_CONTRACTION: f64 = 0.25;
/// Newton's tolerance at the ramp's steps ([`warm_start_options`]).
/// With the integrator at [`RAMP_INTEGRATION_TOLERANCE`] this takes 15 %
/// (k = 3) to 59 % (k = 30) fewer evaluations than 1e-6 for both on the
/// cantilever, with the same ramp steps; the final solve's polish
/// ([`Role::Final`]) makes the equilibrium independent of how loosely the
/// ramp ran.
const RAMP_TOLERANCE: f64 = 1e-3;
/// The integrator's rtol and atol at the ramp's steps: a decade below
/// Newton's tolerance, so that the integration's noise in the residual
/// cannot stall Newton (at 1e-3 for both, the twisted shaft of
/// `tests/twist_resolution.rs`, κ3 = 500, stalled at λ = 0.25 with every
/// damped step refused at residual 1.06e-3).
const RAMP_INTEGRATION_TOLERANCE: f64 = 1e-4;

/// Natural-parameter continuation in a load factor λ from 0 to 1, each step
/// started from the secant through the last two equilibria ([`secant`];
/// from the last one at the second step), every step solved to warm-start
/// accuracy ([`warm_start_options`]), the one at λ = 1 then refined to the
/// asked tolerances and polished ([`Role::Final`]): from there Newton needs
/// two or three evaluations at the asked tolerances instead of three or
/// four from the secant's prediction. A step counts only when Newton converges
/// cleanly (no damping, at most `RAMP_ITERATIONS` steps, contraction
/// Θ ≤ 1/4 as in Deuflhard's continuation step control), so that the ramp
/// does not jump to another branch; the step halves otherwise and grows after
/// a success.
fn ramp(
    rod: &Rod,
    level: ModelLevel,
    opts: &SolverOptions,
    stats: &mut IntegrationStats,
    first_error: Option<SolveError>,
) -> Result<(Solved, usize), SolveError> {
    let (mut lambda, mut step): (f64, f64) = (0.0, 0.25);
    let mut x: Option<Solved> = None;
    // (λ, unknowns) of the step before the last: the secant predictor's
    // second point.
    let mut before: Option<(f64, Vec<f64>)> = None;
    let mut last_error = first_error;
    let mut steps = 0;
    let step_opts = SolverOptions {
        initial_guess: None,
        initial_reaction: None,
        newton: NewtonOptions {
            max_iterations: opts.newton.max_iterations.min(RAMP_ITERATIONS),
            ..opts.newton
        },
        ..opts.clone()
    };
    let warm_opts = warm_start_options(&step_opts);
    let mut refine_at_end = warm_opts != step_opts;
    while step >= 1e-4 && steps < 400 {
        let target = (lambda + step).min(1.0);
        // λ ≤ 1 scales finite loads: never refused.
        let scaled = rod
            .with_load_factor(target)
            .map_err(|e| SolveError::Model(e.to_string()))?;
        let predicted = secant(x.as_ref(), before.as_ref(), lambda, target);
        let start = predicted.as_ref().or(x.as_ref());
        // Collocation has no loose settings: its step at λ = 1 is the
        // final solve itself.
        let (at, role) = if target >= 1.0 && !refine_at_end {
            (&step_opts, Role::Final)
        } else {
            (&warm_opts, Role::WarmStart)
        };
        match solve_at(&scaled, level, at, start, role, stats) {
            Ok(solved) if solved.ramp_step(RAMP_CONTRACTION) => {
                steps += 1;
                if target >= 1.0 {
                    if !refine_at_end {
                        return Ok((solved, steps));
                    }
                    // The loose equilibrium at λ = 1 is on the branch; the
                    // asked tolerances only refine it, and the refinement
                    // must pass the ramp's test too (an ill-conditioned
                    // rod's loose equilibrium can lie in another root's
                    // basin). Otherwise the step is taken again as before
                    // the refinement existed: to the asked tolerances from
                    // the secant's prediction.
                    let at_one = Some(&solved);
                    match solve_at(&scaled, level, &step_opts, at_one, Role::Final, stats) {
                        Ok(fin) if fin.ramp_step(RAMP_CONTRACTION) => return Ok((fin, steps)),
                        Ok(_) => {}
                        Err(e) if !e.ramp_may_help() => return Err(e),
                        Err(e) => last_error = Some(e),
                    }
                    refine_at_end = false;
                    steps -= 1;
                    continue;
                }
                before = match &x {
                    Some(Solved::Shooting { x, .. }) => Some((lambda, x.clone())),
                    _ => None,
                };
                lambda = target;
                x = Some(solved);
                step = (step * 1.5).min(0.5);
            }
            Ok(_) => step *= 0.5,
            Err(e) if !e.ramp_may_help() => return Err(e),
            Err(e) => {
                last_error = Some(e);
                step *= 0.5;
            }
        }
    }
    Err(SolveError::RampStalled {
        method: opts.method.name(),
        reached: lambda,
        step,
        last: last_error.map_or_else(|| "step too small".to_string(), |e| e.to_string()),
    })
}

/// The settings of the ramp's steps, whose equilibria only start the next
/// step (at λ = 1, the final solve): shooting solves them to
/// `RAMP_TOLERANCE` (Newton's residual) and `RAMP_INTEGRATION_TOLERANCE`
/// (the integrator's rtol, atol) — or the asked ones where tighter — then the equilibrium at λ = 1 refined
/// to the asked tolerances and polished to round-off
/// ([`newton::solve_polished`]). Each
/// step still has to pass the ramp's test (undamped, Θ ≤ 1/4), so the
/// branch is followed as before. Collocation keeps its settings (its mesh
/// adapts at every step).
fn warm_start_options(step_opts: &SolverOptions) -> SolverOptions {
    if matches!(step_opts.method, Method::Collocation { .. }) {
        return step_opts.clone();
    }
    let (newton, integration) = (step_opts.newton, step_opts.integration);
    SolverOptions {
        newton: NewtonOptions {
            tolerance: newton.tolerance.max(RAMP_TOLERANCE),
            ..newton
        },
        integration: Tolerances {
            rtol: integration.rtol.max(RAMP_INTEGRATION_TOLERANCE),
            atol: integration.atol.max(RAMP_INTEGRATION_TOLERANCE),
            ..integration
        },
        ..step_opts.clone()
    }
}

/// The secant predictor of natural-parameter continuation: the shooting
/// unknowns at `target` extrapolated linearly in λ from the last two ramp
/// equilibria (at `lambda` and `before`); None before the second step and
/// for collocation, which then starts from the last equilibrium.
fn secant(
    last: Option<&Solved>,
    before: Option<&(f64, Vec<f64>)>,
    lambda: f64,
    target: f64,
) -> Option<Solved> {
    let (Some(Solved::Shooting { x, report }), Some((l0, x0))) = (last, before) else {
        return None;
    };
    let t = (target - lambda) / (lambda - l0);
    let x = x.iter().zip(x0).map(|(a, b)| a + t * (a - b)).collect();
    Some(Solved::Shooting {
        x,
        report: report.clone(),
    })
}

fn format_history(h: &[f64]) -> String {
    let items: Vec<String> = h.iter().map(|v| format!("{v:.2e}")).collect();
    format!("[{}]", items.join(", "))
}
