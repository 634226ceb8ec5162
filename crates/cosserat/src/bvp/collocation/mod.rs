//! Gauss–Legendre collocation for the rod BVP, with mesh adaptation.
//!
//! On a mesh 0 = s_0 < … < s_N = L the unknowns are the free initial values
//! u (so y_0 = y(0; u), affine in u), the states y_1 … y_N at the nodes and
//! the m stage values Y_ij of every interval. The equations are, per
//! interval of width h (the implicit Runge–Kutta form of collocation at the
//! m Gauss points, Ascher, Mattheij & Russell, "Numerical Solution of
//! Boundary Value Problems for ODEs", §5.6.1 and §5.7),
//!
//!   Y_ij = y_i + h Σ_l a_jl f(s_i + c_l h, Y_il),   j = 1 … m,
//!   y_{i+1} = y_i + h Σ_j b_j f(s_i + c_j h, Y_ij),
//!
//! and the tip conditions g(y_N) = 0; the nodes are superconvergent, of
//! order 2m. Residuals are scaled as in shooting (state components by L,
//! 1/L or 1, tip residuals by the moment scale).
//!
//! Newton's linear systems are solved in O(N): the stage corrections of
//! each interval are condensed onto its left node (AMR §7.2, "parameter
//! condensation"), which leaves the block-bidiagonal system
//! δy_{i+1} − Γ_i δy_i = c_i closed by δy_0 = S δu and the tip rows; it is
//! banded, and factored by Gaussian elimination with row partial pivoting
//! (AMR §7.2.2: stable, unlike the forward recursion of compactification).
//!
//! The mesh is refined by halving the intervals whose local error, estimated
//! by step doubling of the collocation step from the converged node state,
//! exceeds the tolerance per unit length (so the accumulated local error
//! stays below the tolerance).
//!
//! Submodules: `tableau` (the Gauss–Legendre tableau), `mesh` (the mesh and
//! its refinement), `grid` (the equations on one mesh and the condensed
//! Newton step), `stage_lu` (an interval's stage matrix factored without
//! the position, which f does not depend on), `lu` (the dense and banded
//! factorizations), `iteration`
//! (damped Newton) and `error_estimate` (step doubling); this module holds
//! the options, the solution and the adaptation loop.

mod error_estimate;
mod grid;
mod iteration;
pub(super) mod lu;
mod mesh;
mod stage_lu;
mod tableau;

use super::newton::NewtonOptions;
use crate::equations::{RodEquations, RodSample};
use grid::{Grid, Scratch};
use iteration::damped_newton;
use mesh::{refine_into, rescale_mesh, uniform_mesh, with_nodes_at};
pub(crate) use tableau::Tableau;
use tableau::{interpolation_nodes, lagrange};

/// Settings of the collocation method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollocationOptions {
    /// Gauss points per interval, 1 ≤ m ≤ 3 (order 2m at the nodes).
    pub stages: usize,
    /// Intervals of the starting uniform mesh.
    pub intervals: usize,
    /// Target of the accumulated local error (scaled state, max-norm); each
    /// interval of width h must reach tolerance · h / L.
    pub tolerance: f64,
    /// The most intervals adaptation may use.
    pub max_intervals: usize,
    /// Refine the mesh until the tolerance is met.
    pub adapt: bool,
}

impl Default for CollocationOptions {
    fn default() -> Self {
        CollocationOptions {
            stages: 3,
            intervals: 16,
            tolerance: 1e-10,
            max_intervals: 4096,
            adapt: true,
        }
    }
}

/// A converged collocation solution.
#[derive(Debug, Clone, PartialEq)]
pub struct CollocationSolution {
    /// The final mesh s_0 = 0 < … < s_N = L.
    pub mesh: Vec<f64>,
    /// The state y at every mesh node.
    pub states: Vec<Vec<f64>>,
    /// Newton steps of the final solve (on the final mesh), including up to
    /// two polishing steps taken after the tolerance was met.
    pub iterations: usize,
    /// The final scaled residual (max-norm).
    pub residual: f64,
    /// Scaled residual at every Newton iterate of the final solve.
    pub residual_history: Vec<f64>,
    /// Newton steps over all meshes of the adaptation (the total work).
    pub newton_steps: usize,
    /// Newton steps that needed damping, over all meshes.
    pub damped_steps: usize,
    /// The largest ratio of successive Newton corrections (Deuflhard's
    /// contraction Θ) on any mesh: well below 1 inside the region of
    /// quadratic convergence.
    pub contraction: f64,
    /// Accumulated local error estimate Σ_i est_i (scaled state, max-norm).
    pub error_estimate: f64,
    /// Largest |d_i·d_j − δ_ij| over the nodes (0 for the planar model).
    /// Discretization error, not round-off: with d3 = d1 × d2 computed,
    /// only |d1|² + |d2|² is a quadratic first integral of y' = f(y) (kept
    /// to round-off by Gauss collocation); d1·d2 and |d1|² − |d2|² are not.
    pub director_drift: f64,
    /// Stage values of every interval (m·dim numbers each), for
    /// interpolation.
    stage_values: Vec<Vec<f64>>,
    /// Stages m of the method that produced this solution.
    stage_count: usize,
}

impl CollocationSolution {
    /// The solution at the mesh nodes in user quantities.
    pub fn samples(&self, eq: &dyn RodEquations) -> Vec<RodSample> {
        self.mesh
            .iter()
            .zip(&self.states)
            .map(|(&s, y)| eq.sample(s, y))
            .collect()
    }

    /// The states at sorted points of [0, L] to the accuracy of the nodes:
    /// from the node s_i left of each point, one Gauss collocation step of
    /// width s − s_i (its stages started from [`Self::interpolate`]). The
    /// collocation polynomial itself is only O(h^{m+1}) accurate between
    /// nodes; this step keeps the superconvergent O(h^{2m}) of the nodes
    /// (local error O(h^{2m+1})) and, on a linear rotation, keeps the
    /// directors orthonormal. Falls back to the polynomial if the step's
    /// Newton iteration fails.
    pub fn sample_states(&self, eq: &dyn RodEquations, points: &[f64]) -> Vec<Vec<f64>> {
        let tab = Tableau::gauss(self.stage_count).expect("stored stage count is valid");
        let grid = Grid::new(eq, tab, self.mesh.clone());
        let (n, m) = (grid.n, grid.tab.m);
        let mut ws = Scratch::new(&grid);
        let last = self.mesh.len() - 1;
        points
            .iter()
            .map(|&s| {
                if s >= self.mesh[last] {
                    return self.states[last].clone();
                }
                let i = self.mesh.partition_point(|&x| x <= s).clamp(1, last) - 1;
                let t = s - self.mesh[i];
                if t <= 0.0 {
                    return self.states[i].clone();
                }
                let mut st = vec![0.0; m * n];
                for (j, c) in grid.tab.c.iter().enumerate() {
                    self.interpolate_into(self.mesh[i] + c * t, &mut st[j * n..(j + 1) * n]);
                }
                let mut y = vec![0.0; n];
                if grid.local_step(
                    self.mesh[i],
                    t,
                    &self.states[i],
                    &mut st,
                    &mut y,
                    &mut ws,
                    None,
                ) {
                    y
                } else {
                    self.interpolate(s)
                }
            })
            .collect()
    }

    /// [`Self::sample_states`] in user quantities.
    pub fn sample(&self, eq: &dyn RodEquations, points: &[f64]) -> Vec<RodSample> {
        points
            .iter()
            .zip(self.sample_states(eq, points))
            .map(|(&s, y)| eq.sample(s, &y))
            .collect()
    }

    /// Gauss points per interval.
    pub fn stages(&self) -> usize {
        self.stage_count
    }

    /// Intervals of the mesh.
    pub fn intervals(&self) -> usize {
        self.mesh.len() - 1
    }

    /// The collocation polynomial at s ∈ [0, L]: on interval i it is the
    /// degree-m polynomial through y_i and the stage values.
    pub fn interpolate(&self, s: f64) -> Vec<f64> {
        let mut y = vec![0.0; self.states[0].len()];
        self.interpolate_into(s, &mut y);
        y
    }

    /// [`Self::interpolate`] into `y`.
    fn interpolate_into(&self, s: f64, y: &mut [f64]) {
        let last = self.mesh.len() - 1;
        if s >= self.mesh[last] {
            y.copy_from_slice(&self.states[last]);
            return;
        }
        let i = self.mesh.partition_point(|&x| x <= s).clamp(1, last) - 1;
        let h = self.mesh[i + 1] - self.mesh[i];
        let t = (s - self.mesh[i]) / h;
        let (nodes, count) = interpolation_nodes(self.stage_count);
        let nodes = &nodes[..count];
        let n = y.len();
        y.fill(0.0);
        for q in 0..count {
            let w = lagrange(nodes, q, t);
            let v = if q == 0 {
                &self.states[i][..]
            } else {
                &self.stage_values[i][(q - 1) * n..q * n]
            };
            y.iter_mut().zip(v).for_each(|(a, b)| *a += w * b);
        }
    }
}

/// Why collocation returned no solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CollocationError {
    /// Options that cannot work.
    #[error("invalid collocation options: {0}")]
    Options(String),
    /// Newton stopped without reaching its tolerance.
    #[error("collocation Newton did not converge on {intervals} intervals: {reason}; scaled residual history {}", format_history(.history))]
    NoConvergence {
        /// Mesh intervals of the failed Newton solve.
        intervals: usize,
        /// Why Newton stopped (the `NewtonFailure` in words).
        reason: String,
        /// Scaled residual (max-norm) at every Newton iterate, the last at the
        /// failure.
        history: Vec<f64>,
    },
    /// The condensed Jacobian could not be factored.
    #[error("singular collocation Jacobian at Newton iteration {iteration} on {intervals} intervals (a fold or bifurcation, or a degenerate guess); scaled residual history {}", format_history(.history))]
    SingularJacobian {
        /// The Newton iteration whose condensed Jacobian was singular.
        iteration: usize,
        /// Mesh intervals at the failure.
        intervals: usize,
        /// Scaled residual (max-norm) at every Newton iterate, the last at the
        /// failure.
        history: Vec<f64>,
    },
    /// Without adaptation, the fixed mesh is too coarse for the tolerance
    /// (returned by [`crate::bvp::solve`], which never passes off such a
    /// solution as converged; [`solve_collocation`] returns it with its
    /// `error_estimate`).
    #[error("error estimate {estimate:.3e} on the fixed mesh of {intervals} intervals exceeds the tolerance {tolerance:.1e} (mesh adaptation is off)")]
    CoarseMesh {
        /// The mesh error tolerance asked for.
        tolerance: f64,
        /// The largest error estimate on the fixed mesh.
        estimate: f64,
        /// Intervals of the fixed mesh.
        intervals: usize,
    },
    /// Adaptation would need more than `max_intervals` intervals.
    #[error("mesh error tolerance {tolerance:.1e} not reached within {max_intervals} intervals: error estimate {estimate:.3e} on {intervals} intervals, {flagged} of them above their share")]
    ToleranceNotReached {
        /// The mesh error tolerance asked for.
        tolerance: f64,
        /// The largest error estimate on the last mesh.
        estimate: f64,
        /// Intervals of the last mesh.
        intervals: usize,
        /// The budget of intervals adaptation may use.
        max_intervals: usize,
        /// Intervals whose estimate exceeds their share of the tolerance (those
        /// to be split).
        flagged: usize,
    },
}

fn format_history(h: &[f64]) -> String {
    let items: Vec<String> = h.iter().map(|v| format!("{v:.2e}")).collect();
    format!("[{}]", items.join(", "))
}

/// Solves the rod BVP by Gauss–Legendre collocation.
///
/// The start is `warm_start` interpolated onto the mesh (with adaptation the
/// warm start's own mesh is kept, since it was adapted to a nearby problem),
/// or else the straight rod with the clamp curvature of
/// `eq.initial_guess()`. Newton's tolerance and budget come from `newton`.
pub fn solve_collocation(
    eq: &dyn RodEquations,
    opts: &CollocationOptions,
    newton: &NewtonOptions,
    warm_start: Option<&CollocationSolution>,
) -> Result<CollocationSolution, CollocationError> {
    solve_collocation_from(eq, opts, newton, warm_start, None)
}

/// [`solve_collocation`] with a guess `u` of the free values (the clamp
/// curvature) for a cold start; ignored when a warm start is given.
pub fn solve_collocation_from(
    eq: &dyn RodEquations,
    opts: &CollocationOptions,
    newton: &NewtonOptions,
    warm_start: Option<&CollocationSolution>,
    guess: Option<&[f64]>,
) -> Result<CollocationSolution, CollocationError> {
    let tab = check_options(opts)?;
    if eq.state_jumps() {
        // The global collocation equations hold the state continuous at
        // every node: a point couple's jump of the curvature is not built
        // there (never a couple silently dropped).
        return Err(CollocationError::Options(
            "a point couple (loads.point[k].couple) makes the state jump, which collocation \
             does not carry; use solver.method = \"shooting\" or \"multiple-shooting\""
                .into(),
        ));
    }
    if let Some(u) = guess {
        if u.len() != eq.unknowns() {
            return Err(CollocationError::Options(format!(
                "the guess has {} free values, the equations {}",
                u.len(),
                eq.unknowns()
            )));
        }
    }
    let (mut steps, mut damped, mut contraction) = (0, 0, 0.0f64);
    let mut mesh = match warm_start {
        Some(w) if opts.adapt && w.mesh.len() >= 2 => rescale_mesh(&w.mesh, eq.length()),
        _ => uniform_mesh(eq.length(), opts.intervals),
    };
    mesh = with_nodes_at(mesh, &eq.jumps());
    let mut warm = warm_start.cloned();
    loop {
        let grid = Grid::new(eq, tab.clone(), mesh);
        let x0 = grid.start_from(warm.as_ref(), guess, false);
        // A cold start tries the initial value problem's shape first and
        // the straight rod if Newton fails from it (at large loads the IVP
        // from the linear guess can be far off).
        let outcome = match damped_newton(&grid, x0, newton) {
            Err(e) if warm.is_none() => {
                let x1 = grid.start_from(None, guess, true);
                damped_newton(&grid, x1, newton).map_err(|_| e)?
            }
            other => other?,
        };
        steps += outcome.iterations;
        damped += outcome.damped_steps;
        contraction = contraction.max(outcome.contraction);
        let errors = grid.local_errors(&outcome.x, outcome.lin.as_ref());
        let mut sol = grid.solution(&outcome, &errors);
        sol.newton_steps = steps;
        sol.damped_steps = damped;
        sol.contraction = contraction;
        let flagged = grid.flagged(&errors, opts.tolerance);
        if !opts.adapt || flagged.is_empty() {
            return Ok(sol);
        }
        if grid.intervals() + flagged.len() > opts.max_intervals {
            return Err(CollocationError::ToleranceNotReached {
                tolerance: opts.tolerance,
                estimate: sol.error_estimate,
                intervals: grid.intervals(),
                max_intervals: opts.max_intervals,
                flagged: flagged.len(),
            });
        }
        // Split each flagged interval into q pieces with q^{2m} ≥ est/share
        // (the local error is O(h^{2m+1}), its share O(h)), 2 ≤ q ≤ 8, so
        // that one or two refinements usually suffice; plain halving if
        // that would exceed the budget.
        let l = eq.length();
        let mut pieces: Vec<(usize, usize)> = flagged
            .iter()
            .map(|&i| {
                let share = opts.tolerance * grid.span(i).1 / l;
                let ratio = errors[i] / share;
                let q = if ratio.is_finite() {
                    (1.1 * ratio.powf(0.5 / tab.m as f64))
                        .ceil()
                        .clamp(2.0, 8.0) as usize
                } else {
                    2
                };
                (i, q)
            })
            .collect();
        let added: usize = pieces.iter().map(|&(_, q)| q - 1).sum();
        if grid.intervals() + added > opts.max_intervals {
            for p in &mut pieces {
                p.1 = 2;
            }
        }
        mesh = refine_into(&grid.mesh, &pieces);
        warm = Some(sol);
    }
}

/// The tableau for valid options, or why they are invalid.
fn check_options(opts: &CollocationOptions) -> Result<Tableau, CollocationError> {
    let bad = |m: &str| Err(CollocationError::Options(m.to_string()));
    if opts.intervals == 0 {
        return bad("intervals must be at least 1");
    }
    if opts.adapt && (opts.tolerance.is_nan() || opts.tolerance <= 0.0) {
        return bad("tolerance must be positive");
    }
    if opts.adapt && opts.max_intervals < opts.intervals {
        return bad("max_intervals must be at least intervals");
    }
    Tableau::gauss(opts.stages).map_or_else(|| bad("stages must be 1, 2 or 3"), Ok)
}
