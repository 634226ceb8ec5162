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

use nalgebra::DMatrix;
#[cfg(test)]
use nalgebra::DVector;

use super::newton::{Convergence, NewtonOptions};
use crate::equations::{RodEquations, RodSample};
use crate::numerics::integrator::{Dop853, Tolerances};

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
        let mut ws = Scratch::new(n, m);
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
            pieces.iter_mut().for_each(|p| p.1 = 2);
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

fn uniform_mesh(length: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| {
            if i == n {
                length
            } else {
                length * i as f64 / n as f64
            }
        })
        .collect()
}

/// A mesh stretched to end exactly at `length`.
fn rescale_mesh(mesh: &[f64], length: f64) -> Vec<f64> {
    let end = *mesh.last().unwrap();
    let mut m: Vec<f64> = mesh.iter().map(|s| s * length / end).collect();
    *m.last_mut().unwrap() = length;
    m
}

/// The mesh with the `flagged` intervals (sorted indices) halved.
#[cfg(test)]
fn refine(mesh: &[f64], flagged: &[usize]) -> Vec<f64> {
    let pieces: Vec<(usize, usize)> = flagged.iter().map(|&i| (i, 2)).collect();
    refine_into(mesh, &pieces)
}

/// The mesh with interval i split into q equal pieces for every (i, q) of
/// `pieces` (sorted by i).
fn refine_into(mesh: &[f64], pieces: &[(usize, usize)]) -> Vec<f64> {
    let mut out = Vec::with_capacity(mesh.len() + pieces.iter().map(|p| p.1).sum::<usize>());
    let mut f = pieces.iter().peekable();
    for i in 0..mesh.len() - 1 {
        out.push(mesh[i]);
        if let Some(&&(_, q)) = f.peek().filter(|p| p.0 == i) {
            f.next();
            let h = mesh[i + 1] - mesh[i];
            out.extend((1..q).map(|j| mesh[i] + h * j as f64 / q as f64));
        }
    }
    out.push(*mesh.last().unwrap());
    out
}

/// The Butcher tableau of Gauss–Legendre collocation with m stages:
/// a_jl = ∫_0^{c_j} ℓ_l, b_l = ∫_0^1 ℓ_l for the Lagrange basis ℓ_l on the
/// Gauss points c (AMR §5.6.1).
#[derive(Debug, Clone)]
pub(crate) struct Tableau {
    pub(crate) m: usize,
    pub(crate) c: Vec<f64>,
    /// m × m, row-major.
    a: Vec<f64>,
    pub(crate) b: Vec<f64>,
}

impl Tableau {
    pub(crate) fn gauss(m: usize) -> Option<Tableau> {
        if m > 3 {
            return None;
        }
        let (c, b) = crate::numerics::quadrature::gauss_legendre(m, 0.0, 1.0)?;
        let a = c
            .iter()
            .flat_map(|&cj| integral_weights(&c, &b, cj))
            .collect();
        Some(Tableau { m, c, a, b })
    }

    pub(crate) fn a(&self, j: usize, l: usize) -> f64 {
        self.a[j * self.m + l]
    }
}

/// The nodes (0, c_1 … c_m) of the collocation polynomial on [0, 1] and
/// their count m + 1 (the Gauss points of [`Tableau::gauss`], without its
/// allocations).
fn interpolation_nodes(m: usize) -> ([f64; 4], usize) {
    let m = if matches!(m, 1 | 2) { m } else { 3 };
    let (c, _) = crate::numerics::quadrature::gauss_legendre_unit(m).expect("tabulated");
    let mut nodes = [0.0; 4];
    nodes[1..=c.len()].copy_from_slice(c);
    (nodes, c.len() + 1)
}

/// ℓ_q(t) for the Lagrange basis on `nodes`.
fn lagrange(nodes: &[f64], q: usize, t: f64) -> f64 {
    nodes
        .iter()
        .enumerate()
        .filter(|&(r, _)| r != q)
        .map(|(_, &x)| (t - x) / (nodes[q] - x))
        .product()
}

/// ∫_0^τ ℓ_l(t) dt for every l, exact by the m-point Gauss rule (c, w)
/// mapped to [0, τ] since ℓ_l has degree m − 1.
fn integral_weights(c: &[f64], w: &[f64], tau: f64) -> Vec<f64> {
    (0..c.len())
        .map(|l| {
            tau * c
                .iter()
                .zip(w)
                .map(|(&cq, &wq)| wq * lagrange(c, l, tau * cq))
                .sum::<f64>()
        })
        .collect()
}

/// The collocation equations on one mesh. Unknown vector layout:
/// [u (p) | y_1 … y_N (n each) | Y_0 … Y_{N−1} (m·n each)].
struct Grid<'a> {
    eq: &'a dyn RodEquations,
    tab: Tableau,
    mesh: Vec<f64>,
    n: usize,
    p: usize,
    /// 1 / state scale, per component.
    w: Vec<f64>,
    /// ∂y_0/∂u.
    sens: DMatrix<f64>,
    /// The n × n identity, column-major: the tangent vectors that make
    /// `rhs_linearized` return the Jacobian ∂f/∂y (one call per point).
    ident: Vec<f64>,
}

/// Buffers of one interval's stage computations, reused across intervals
/// and iterations (no allocation per interval).
struct Scratch {
    /// f at the m stages (m·n).
    f: Vec<f64>,
    /// ∂f/∂y at the m stages, each n × n column-major.
    jac: Vec<f64>,
    /// The stage matrix W (mn × mn, row-major), factored in place.
    w: Vec<f64>,
    piv: Vec<usize>,
    /// A stage-sized right-hand side (m·n).
    g: Vec<f64>,
}

impl Scratch {
    fn new(n: usize, m: usize) -> Self {
        let mn = m * n;
        Scratch {
            f: vec![0.0; mn],
            jac: vec![0.0; m * n * n],
            w: vec![0.0; mn * mn],
            piv: vec![0; mn],
            g: vec![0.0; mn],
        }
    }
}

impl<'a> Grid<'a> {
    fn new(eq: &'a dyn RodEquations, tab: Tableau, mesh: Vec<f64>) -> Self {
        let n = eq.dim();
        Grid {
            eq,
            tab,
            mesh,
            n,
            p: eq.unknowns(),
            w: eq.state_scales().iter().map(|v| 1.0 / v).collect(),
            sens: eq.initial_sensitivity(),
            ident: DMatrix::<f64>::identity(n, n).as_slice().to_vec(),
        }
    }

    fn intervals(&self) -> usize {
        self.mesh.len() - 1
    }

    fn size(&self) -> usize {
        let (n, m, k) = (self.n, self.tab.m, self.intervals());
        self.p + n * k + m * n * k
    }

    /// Offset of the stage values of interval i.
    fn stage_offset(&self, i: usize) -> usize {
        self.p + self.n * self.intervals() + i * self.tab.m * self.n
    }

    /// The node state y_i (y_0 from u).
    fn node(&self, x: &[f64], i: usize) -> Vec<f64> {
        let (n, p) = (self.n, self.p);
        if i == 0 {
            let mut y0 = vec![0.0; n];
            self.eq.initial_state(&x[..p], &mut y0);
            y0
        } else {
            x[p + n * (i - 1)..p + n * i].to_vec()
        }
    }

    /// The node state y_i for i ≥ 1, or `y0` (y_0 computed by the caller).
    fn node_ref<'x>(&self, x: &'x [f64], y0: &'x [f64], i: usize) -> &'x [f64] {
        let (n, p) = (self.n, self.p);
        if i == 0 {
            y0
        } else {
            &x[p + n * (i - 1)..p + n * i]
        }
    }

    fn stages<'x>(&self, x: &'x [f64], i: usize) -> &'x [f64] {
        let o = self.stage_offset(i);
        &x[o..o + self.tab.m * self.n]
    }

    /// (s_i, h_i).
    fn span(&self, i: usize) -> (f64, f64) {
        (self.mesh[i], self.mesh[i + 1] - self.mesh[i])
    }

    /// The starting unknowns: interpolated from a warm start, or else a
    /// cold start from the guessed clamp curvature u: the initial value
    /// problem from u integrated with DOP853 (tolerance 1e-8) through the
    /// nodes and stage points — for an unloaded rod that is its intrinsic
    /// shape, however much it spirals — with the straight rod beyond a
    /// blow-up; or, with `straight`, the straight rod.
    fn start_from(
        &self,
        warm: Option<&CollocationSolution>,
        guess: Option<&[f64]>,
        straight: bool,
    ) -> Vec<f64> {
        let u = match warm {
            Some(w) => self.eq.unknowns_of(&w.states[0]),
            None => guess.map_or_else(|| self.eq.initial_guess(), <[f64]>::to_vec),
        };
        // Points in order: per interval its stage points, then its right node.
        let k = self.intervals();
        let mut points = Vec::with_capacity(k * (self.tab.m + 1));
        for i in 0..k {
            let (s, h) = self.span(i);
            points.extend(self.tab.c.iter().map(|c| s + c * h));
            points.push(self.mesh[i + 1]);
        }
        let (n, m) = (self.n, self.tab.m);
        let mut x = u;
        x.reserve(self.size());
        if let Some(w) = warm {
            // Interpolated straight into x: the nodes, then the stages.
            let (p, o) = (x.len(), x.len() + n * k);
            x.resize(self.size(), 0.0);
            for i in 0..k {
                for (j, &s) in points[i * (m + 1)..(i + 1) * (m + 1)].iter().enumerate() {
                    let r = if j == m {
                        p + n * i..p + n * (i + 1)
                    } else {
                        o + (i * m + j) * n..o + (i * m + j + 1) * n
                    };
                    w.interpolate_into(s, &mut x[r]);
                }
            }
            return x;
        }
        let states: Vec<Vec<f64>> = if straight {
            points.iter().map(|&s| self.eq.straight_state(s)).collect()
        } else {
            self.integrate_guess(&x, &points)
        };
        for i in 0..k {
            x.extend_from_slice(&states[i * (m + 1) + m]);
        }
        for i in 0..k {
            for j in 0..m {
                x.extend_from_slice(&states[i * (m + 1) + j]);
            }
        }
        debug_assert!(states.iter().all(|y| y.len() == n));
        debug_assert_eq!(x.len(), self.size());
        x
    }

    /// y(s; u) of the initial value problem at sorted `points`.
    fn integrate_guess(&self, u: &[f64], points: &[f64]) -> Vec<Vec<f64>> {
        let n = self.n;
        let mut y = vec![0.0; n];
        self.eq.initial_state(u, &mut y);
        let tol = Tolerances {
            rtol: 1e-8,
            atol: 1e-8,
            max_steps: 100_000,
        };
        let eq = self.eq;
        let mut out = Vec::with_capacity(points.len());
        let _ = Dop853::new(n).integrate(
            |s, y: &[f64], d: &mut [f64]| eq.rhs(s, y, d),
            0.0,
            eq.length(),
            &mut y,
            n,
            &tol,
            points,
            |_, y| out.push(y.to_vec()),
            |y| eq.project(y),
        );
        let usable = out.len().min(points.len());
        out.truncate(usable);
        let finite = out
            .iter()
            .position(|y| y.iter().any(|v| !v.is_finite()))
            .unwrap_or(usable);
        out.truncate(finite);
        out.extend(points[finite..].iter().map(|&s| eq.straight_state(s)));
        out
    }

    /// f at the m stages `st` of the step of width h from s, into `f`.
    fn stage_rates(&self, s: f64, h: f64, st: &[f64], f: &mut [f64]) {
        let n = self.n;
        for (j, c) in self.tab.c.iter().enumerate() {
            let r = j * n..(j + 1) * n;
            self.eq.rhs(s + c * h, &st[r.clone()], &mut f[r]);
        }
    }

    /// f and ∂f/∂y at the m stages `st` (one `rhs_linearized` call each),
    /// into `f` and `jac` (n × n column-major per stage).
    fn stage_jacobians(&self, s: f64, h: f64, st: &[f64], f: &mut [f64], jac: &mut [f64]) {
        let n = self.n;
        for (j, c) in self.tab.c.iter().enumerate() {
            let r = j * n..(j + 1) * n;
            self.eq.rhs_linearized(
                s + c * h,
                &st[r.clone()],
                n,
                &self.ident,
                &mut f[r],
                &mut jac[j * n * n..(j + 1) * n * n],
            );
        }
    }

    /// W = I − h (A ⊗ I) diag(J_l) (row-major, into `w`): the stage block of
    /// the Jacobian.
    fn stage_matrix(&self, h: f64, jac: &[f64], w: &mut [f64]) {
        let (n, m) = (self.n, self.tab.m);
        let mn = m * n;
        for j in 0..m {
            for l in 0..m {
                let coef = h * self.tab.a(j, l);
                let jl = &jac[l * n * n..(l + 1) * n * n];
                for r in 0..n {
                    let row = &mut w[(j * n + r) * mn + l * n..(j * n + r) * mn + (l + 1) * n];
                    for (c, v) in row.iter_mut().enumerate() {
                        let id = if j == l && r == c { 1.0 } else { 0.0 };
                        *v = id - jl[c * n + r] * coef;
                    }
                }
            }
        }
    }

    /// The scaled residual: per interval the m·n stage equations and the n
    /// node equations, then the p tip conditions.
    fn residual(&self, x: &[f64]) -> Vec<f64> {
        let (n, m, p) = (self.n, self.tab.m, self.p);
        let mut r = Vec::with_capacity(self.size());
        let mut y0 = vec![0.0; n];
        self.eq.initial_state(&x[..p], &mut y0);
        let mut f = vec![0.0; m * n];
        for i in 0..self.intervals() {
            let (s, h) = self.span(i);
            let st = self.stages(x, i);
            self.stage_rates(s, h, st, &mut f);
            let y = self.node_ref(x, &y0, i);
            for j in 0..m {
                for k in 0..n {
                    let acc: f64 = (0..m).map(|l| self.tab.a(j, l) * f[l * n + k]).sum();
                    r.push((st[j * n + k] - y[k] - h * acc) * self.w[k]);
                }
            }
            let next = self.node_ref(x, &y0, i + 1);
            for k in 0..n {
                let acc: f64 = (0..m).map(|j| self.tab.b[j] * f[j * n + k]).sum();
                r.push((next[k] - y[k] - h * acc) * self.w[k]);
            }
        }
        let mut g = vec![0.0; p];
        self.eq
            .tip_residual(self.node_ref(x, &y0, self.intervals()), &mut g);
        r.extend_from_slice(&g);
        r
    }

    /// Storage for the Newton matrix of this mesh.
    fn new_linearization(&self) -> Linearization {
        let (n, m, p, k) = (self.n, self.tab.m, self.p, self.intervals());
        let mn = m * n;
        Linearization {
            lu: vec![0.0; k * mn * mn],
            piv: vec![0; k * mn],
            z: vec![0.0; k * mn * n],
            hbj: vec![0.0; k * m * n * n],
            band: BandLu::zeros(p + n * k, 2 * n - 1 - p, n + p - 1),
            valid: false,
        }
    }

    /// The Newton matrix at x, condensed and factored into `lin` (reusing
    /// its storage); false if singular.
    fn linearize(&self, x: &[f64], lin: &mut Linearization, ws: &mut Scratch) -> bool {
        lin.valid = false;
        let (n, p, k) = (self.n, self.p, self.intervals());
        lin.band.clear();
        let mut gamma = vec![0.0; n * n];
        let mut gamma0 = vec![0.0; n * p];
        for i in 0..k {
            if !self.condense(i, self.stages(x, i), lin, ws, &mut gamma) {
                return false;
            }
            let (g, cols): (&[f64], usize) = if i == 0 {
                // Γ_0 S (n × p, row-major).
                for r in 0..n {
                    for c in 0..p {
                        gamma0[r * p + c] =
                            (0..n).map(|q| gamma[r * n + q] * self.sens[(q, c)]).sum();
                    }
                }
                (&gamma0, p)
            } else {
                (&gamma, n)
            };
            let col = if i == 0 { 0 } else { p + n * (i - 1) };
            for r in 0..n {
                for c in 0..cols {
                    lin.band
                        .add(n * i + r, col + c, -g[r * cols + c] * self.w[r]);
                }
                lin.band.add(n * i + r, p + n * i + r, self.w[r]);
            }
        }
        let y_tip = self.node(x, k);
        let gt = self.eq.tip_residual_jacobian(&y_tip);
        for r in 0..p {
            for c in 0..n {
                lin.band.add(n * k + r, p + n * (k - 1) + c, gt[(r, c)]);
            }
        }
        lin.valid = lin.band.factor().is_ok();
        lin.valid
    }

    /// Condensation of interval i into `lin`: δY = v + Z δy_i with W Z = E
    /// (stacked identities), and Γ = I + h Σ_j b_j J_j Z_j (AMR §7.2.1),
    /// into `gamma` (n × n, row-major); false if W is singular.
    fn condense(
        &self,
        i: usize,
        st: &[f64],
        lin: &mut Linearization,
        ws: &mut Scratch,
        gamma: &mut [f64],
    ) -> bool {
        let (n, m, (s, h)) = (self.n, self.tab.m, self.span(i));
        let (mn, nn) = (m * n, n * n);
        self.stage_jacobians(s, h, st, &mut ws.f, &mut ws.jac);
        let lu = &mut lin.lu[i * mn * mn..(i + 1) * mn * mn];
        let piv = &mut lin.piv[i * mn..(i + 1) * mn];
        self.stage_matrix(h, &ws.jac, lu);
        if !dense_lu(lu, mn, piv) {
            return false;
        }
        let z = &mut lin.z[i * mn * n..(i + 1) * mn * n];
        for c in 0..n {
            let col = &mut z[c * mn..(c + 1) * mn];
            col.iter_mut()
                .enumerate()
                .for_each(|(r, v)| *v = if r % n == c { 1.0 } else { 0.0 });
            dense_solve(lu, mn, piv, col);
        }
        if !z.iter().all(|v| v.is_finite()) {
            return false;
        }
        let hbj = &mut lin.hbj[i * m * nn..(i + 1) * m * nn];
        for j in 0..m {
            let hb = h * self.tab.b[j];
            hbj[j * nn..(j + 1) * nn]
                .iter_mut()
                .zip(&ws.jac[j * nn..(j + 1) * nn])
                .for_each(|(a, b)| *a = b * hb);
        }
        for r in 0..n {
            for c in 0..n {
                gamma[r * n + c] = if r == c { 1.0 } else { 0.0 };
            }
        }
        for j in 0..m {
            let hb = &hbj[j * nn..(j + 1) * nn];
            for r in 0..n {
                for c in 0..n {
                    let zc = &z[c * mn + j * n..c * mn + (j + 1) * n];
                    let t: f64 = (0..n).map(|q| hb[q * n + r] * zc[q]).sum();
                    gamma[r * n + c] += t;
                }
            }
        }
        true
    }

    /// −J⁻¹F for a scaled residual F, in the unknowns' layout.
    fn newton_correction(&self, lin: &Linearization, f: &[f64]) -> Vec<f64> {
        let (n, m, p, k) = (self.n, self.tab.m, self.p, self.intervals());
        let (mn, nn) = (m * n, n * n);
        let mut dx = vec![0.0; self.size()];
        let (head, stages) = dx.split_at_mut(p + n * k);
        for i in 0..k {
            let base = i * (m + 1) * n;
            let v = &mut stages[i * mn..(i + 1) * mn];
            v.iter_mut()
                .enumerate()
                .for_each(|(r, a)| *a = -f[base + r] / self.w[r % n]);
            dense_solve(
                &lin.lu[i * mn * mn..(i + 1) * mn * mn],
                mn,
                &lin.piv[i * mn..(i + 1) * mn],
                v,
            );
            let hbj = &lin.hbj[i * m * nn..(i + 1) * m * nn];
            for r in 0..n {
                let mut acc = -f[base + mn + r] / self.w[r];
                for j in 0..m {
                    let hb = &hbj[j * nn..(j + 1) * nn];
                    let vj = &v[j * n..(j + 1) * n];
                    acc += (0..n).map(|q| hb[q * n + r] * vj[q]).sum::<f64>();
                }
                head[n * i + r] = acc * self.w[r];
            }
        }
        for q in 0..p {
            head[n * k + q] = -f[k * (m + 1) * n + q];
        }
        lin.band.solve(head);
        let mut dy0 = vec![0.0; n];
        for (r, d) in dy0.iter_mut().enumerate() {
            *d = (0..p).map(|c| self.sens[(r, c)] * head[c]).sum();
        }
        for i in 0..k {
            let dyi = if i == 0 {
                &dy0[..]
            } else {
                &head[p + n * (i - 1)..p + n * i]
            };
            let z = &lin.z[i * mn * n..(i + 1) * mn * n];
            let v = &mut stages[i * mn..(i + 1) * mn];
            for (r, a) in v.iter_mut().enumerate() {
                let t: f64 = (0..n).map(|c| z[c * mn + r] * dyi[c]).sum();
                *a += t;
            }
        }
        dx
    }

    /// A weighted Euclidean norm of a correction (δy_0 = S δu, nodes and
    /// stages, each component divided by its scale).
    /// The typical magnitude of each unknown: the free initial values in
    /// the scale of the state component they set, node states in the
    /// state scales.
    fn unknown_scales(&self) -> Vec<f64> {
        let (n, p) = (self.n, self.p);
        let total = p + n * self.intervals();
        (0..total)
            .map(|q| {
                let row = if q < p {
                    (0..n).find(|&r| self.sens[(r, q)] != 0.0).unwrap_or(0)
                } else {
                    (q - p) % n
                };
                1.0 / self.w[row]
            })
            .collect()
    }

    fn step_norm(&self, dx: &[f64]) -> f64 {
        let (n, p) = (self.n, self.p);
        let head: f64 = (0..n)
            .map(|r| {
                let d: f64 = (0..p).map(|c| self.sens[(r, c)] * dx[c]).sum();
                (d * self.w[r]).powi(2)
            })
            .sum();
        let rest: f64 = dx[p..]
            .iter()
            .enumerate()
            .map(|(q, d)| (d * self.w[q % n]).powi(2))
            .sum();
        (head + rest).sqrt()
    }

    /// One collocation step of width h from y at s: its stage equations
    /// solved in `st` (holding the guess) by Newton, the end state into
    /// `out`; false if that fails. The stage matrix is factored at the
    /// guess and refreshed only while the iteration contracts slowly
    /// (Θ > 1/4); `frozen`, a factored stage matrix of this width at nearby
    /// stages, is used instead while it contracts fast. The iteration stops
    /// once the remainder is below round-off (see the test below), at the
    /// latest one correction after the first of at most 1e-13 (scaled).
    #[allow(clippy::too_many_arguments)]
    fn local_step(
        &self,
        s: f64,
        h: f64,
        y: &[f64],
        st: &mut [f64],
        out: &mut [f64],
        ws: &mut Scratch,
        frozen: Option<(&[f64], &[usize])>,
    ) -> bool {
        let (n, m) = (self.n, self.tab.m);
        let mn = m * n;
        let mut use_frozen = frozen.is_some();
        let (mut factored, mut refresh) = (false, !use_frozen);
        let (mut small, mut prev) = (false, f64::NAN);
        for _ in 0..30 {
            if refresh {
                self.stage_jacobians(s, h, st, &mut ws.f, &mut ws.jac);
                self.stage_matrix(h, &ws.jac, &mut ws.w);
                if !dense_lu(&mut ws.w, mn, &mut ws.piv) {
                    return false;
                }
                (factored, use_frozen) = (true, false);
            } else {
                self.stage_rates(s, h, st, &mut ws.f);
            }
            for (r, (g, v)) in ws.g.iter_mut().zip(st.iter()).enumerate() {
                let (j, k) = (r / n, r % n);
                let acc: f64 = (0..m).map(|l| self.tab.a(j, l) * ws.f[l * n + k]).sum();
                *g = y[k] + h * acc - v;
            }
            match frozen.filter(|_| use_frozen) {
                Some((lu, piv)) => dense_solve(lu, mn, piv, &mut ws.g),
                None => dense_solve(&ws.w, mn, &ws.piv, &mut ws.g),
            }
            st.iter_mut().zip(&ws.g).for_each(|(a, b)| *a += b);
            let size =
                ws.g.iter()
                    .enumerate()
                    .map(|(r, v)| (v * self.w[r % n]).abs())
                    .fold(0.0, f64::max);
            if !size.is_finite() {
                return false;
            }
            let theta = size / prev;
            // Converged: after the correction following one of at most
            // 1e-13 (the rule of a plain Newton iteration), or as soon as
            // the remainder is below round-off: Θ·‖δ‖ ≤ 1e-17 with a reliable
            // Θ ≤ 1/4, or ‖δ‖ ≤ 1e-15 at the first correction of a matrix
            // factored at (nearly) these stages.
            if small || size <= 1e-15 || (theta <= 0.25 && theta * size <= 1e-17) {
                break;
            }
            small = size <= 1e-13;
            // Slow contraction: refactor at the current stages.
            // (Θ is NaN after the first correction: refresh then only if
            // nothing is factored yet.)
            let slow = theta.is_nan() || theta > 0.25;
            refresh = slow && !(prev.is_nan() && (factored || use_frozen));
            prev = size;
        }
        self.stage_rates(s, h, st, &mut ws.f);
        for k in 0..n {
            out[k] = y[k] + h * (0..m).map(|j| self.tab.b[j] * ws.f[j * n + k]).sum::<f64>();
        }
        true
    }

    /// Local error of every interval by step doubling from the converged
    /// node state: one step of width h against two of h/2, the difference
    /// scaled by 1/(1 − 2^{−2m}) (the local error is O(h^{2m+1})). The
    /// full step starts from the converged stages (with `lin`'s factored
    /// stage matrices when given), the half steps from the collocation
    /// polynomial.
    fn local_errors(&self, x: &[f64], lin: Option<&Linearization>) -> Vec<f64> {
        let (n, m, p) = (self.n, self.tab.m, self.p);
        let mn = m * n;
        let factor = 1.0 / (1.0 - 0.5f64.powi(2 * m as i32));
        let lin = lin.filter(|l| l.valid);
        // Lagrange weights on the nodes (0, c_1 … c_m) at the stage points of
        // the two half steps, t = c_j / 2 and 1/2 + c_j / 2.
        let (nodes, _) = interpolation_nodes(m);
        let nodes = &nodes[..=m];
        let weights: Vec<f64> = [0.0, 0.5]
            .iter()
            .flat_map(|&a| {
                self.tab
                    .c
                    .iter()
                    .flat_map(move |&c| (0..=m).map(move |q| lagrange(nodes, q, a + 0.5 * c)))
            })
            .collect();
        let guess = |half: usize, y: &[f64], stv: &[f64], g: &mut [f64]| {
            for j in 0..m {
                let wj = &weights[(half * m + j) * (m + 1)..(half * m + j + 1) * (m + 1)];
                for k in 0..n {
                    let mut acc = wj[0] * y[k];
                    for q in 1..=m {
                        acc += wj[q] * stv[(q - 1) * n + k];
                    }
                    g[j * n + k] = acc;
                }
            }
        };
        let mut ws = Scratch::new(n, m);
        let mut y0 = vec![0.0; n];
        self.eq.initial_state(&x[..p], &mut y0);
        let (mut st, mut a, mut mid, mut b) =
            (vec![0.0; mn], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        (0..self.intervals())
            .map(|i| {
                let (s, h) = self.span(i);
                let y = self.node_ref(x, &y0, i);
                let stv = self.stages(x, i);
                st.copy_from_slice(stv);
                let frozen = lin.map(|l| {
                    (
                        &l.lu[i * mn * mn..(i + 1) * mn * mn],
                        &l.piv[i * mn..(i + 1) * mn],
                    )
                });
                let full = self.local_step(s, h, y, &mut st, &mut a, &mut ws, frozen);
                guess(0, y, stv, &mut st);
                let mut half = self.local_step(s, 0.5 * h, y, &mut st, &mut mid, &mut ws, None);
                if half {
                    guess(1, y, stv, &mut st);
                    half =
                        self.local_step(s + 0.5 * h, 0.5 * h, &mid, &mut st, &mut b, &mut ws, None);
                }
                if full && half {
                    factor
                        * (0..n)
                            .map(|k| ((a[k] - b[k]) * self.w[k]).abs())
                            .fold(0.0, f64::max)
                } else {
                    f64::INFINITY
                }
            })
            .collect()
    }

    /// Intervals whose estimate exceeds their share tolerance · h / L.
    fn flagged(&self, errors: &[f64], tolerance: f64) -> Vec<usize> {
        let l = self.eq.length();
        errors
            .iter()
            .enumerate()
            .filter(|&(i, &e)| e.is_nan() || e > tolerance * self.span(i).1 / l)
            .map(|(i, _)| i)
            .collect()
    }

    /// Node states and stage values of x, with empty statistics.
    fn solution_parts(&self, x: &[f64]) -> CollocationSolution {
        CollocationSolution {
            mesh: self.mesh.clone(),
            states: (0..=self.intervals()).map(|i| self.node(x, i)).collect(),
            iterations: 0,
            residual: f64::NAN,
            residual_history: Vec::new(),
            newton_steps: 0,
            damped_steps: 0,
            contraction: 0.0,
            error_estimate: f64::NAN,
            director_drift: 0.0,
            stage_values: (0..self.intervals())
                .map(|i| self.stages(x, i).to_vec())
                .collect(),
            stage_count: self.tab.m,
        }
    }

    /// The solution with Newton's statistics, the error estimate and the
    /// director drift.
    fn solution(&self, out: &NewtonOutcome, errors: &[f64]) -> CollocationSolution {
        let mut sol = self.solution_parts(&out.x);
        sol.iterations = out.iterations;
        sol.residual = *out.history.last().unwrap_or(&f64::NAN);
        sol.residual_history = out.history.clone();
        sol.error_estimate = errors.iter().sum();
        if self.n == 12 {
            sol.director_drift = sol
                .samples(self.eq)
                .iter()
                .map(RodSample::director_drift)
                .fold(0.0, f64::max);
        }
        sol
    }
}

/// The factored Newton matrix: per interval the condensed stage block, in
/// flat storage reused across Newton iterations.
struct Linearization {
    /// LU factors of the stage matrices W (mn × mn each, row-major).
    lu: Vec<f64>,
    /// Their row interchanges.
    piv: Vec<usize>,
    /// W⁻¹E (mn × n each, column-major): the stage corrections' response
    /// to δy_i.
    z: Vec<f64>,
    /// h b_j J_j (m blocks of n × n each, column-major).
    hbj: Vec<f64>,
    band: BandLu,
    /// Whether the last `linearize` succeeded.
    valid: bool,
}

struct NewtonOutcome {
    x: Vec<f64>,
    iterations: usize,
    history: Vec<f64>,
    damped_steps: usize,
    contraction: f64,
    /// The last successful factorization (at x or the iterate before).
    lin: Option<Linearization>,
}

fn max_norm(r: &[f64]) -> f64 {
    r.iter().fold(
        0.0,
        |m, v| if v.is_nan() { f64::NAN } else { m.max(v.abs()) },
    )
}

/// Damped Newton with Deuflhard's natural monotonicity test (as in
/// `newton::solve`): accept λ when ‖J(x)⁻¹F(x + λδ)‖ ≤ (1 − λ/4)‖δ‖, using
/// the already factored J; every linear solve is O(N).
fn damped_newton(
    grid: &Grid,
    x0: Vec<f64>,
    opts: &NewtonOptions,
) -> Result<NewtonOutcome, CollocationError> {
    let intervals = grid.intervals();
    let mut x = x0;
    let mut f = grid.residual(&x);
    let mut history = vec![max_norm(&f)];
    let (mut damped_steps, mut contraction, mut last_norm) = (0, 0.0f64, f64::NAN);
    let fail = |reason: String, history: Vec<f64>| CollocationError::NoConvergence {
        intervals,
        reason,
        history,
    };
    if !history[0].is_finite() {
        return Err(fail(
            "the initial guess is inadmissible (non-finite residual)".into(),
            history,
        ));
    }
    let mut lin = grid.new_linearization();
    let mut ws = Scratch::new(grid.n, grid.tab.m);
    let test = Convergence::new(opts.tolerance, grid.unknown_scales());
    for iteration in 0..=opts.max_iterations {
        let singular = |history| CollocationError::SingularJacobian {
            iteration,
            intervals,
            history,
        };
        let linearized = grid.linearize(&x, &mut lin, &mut ws);
        let step = grid.newton_correction(&lin, &f);
        let step_ok = linearized && step.iter().all(|v| v.is_finite());
        if step_ok && test.met(*history.last().unwrap(), &x, &step) {
            let mut out = polish(grid, x, f, history, lin, &mut ws);
            out.damped_steps = damped_steps;
            out.contraction = contraction;
            return Ok(out);
        }
        if iteration == opts.max_iterations {
            break;
        }
        if !step_ok {
            return Err(singular(history));
        }
        let step_norm = grid.step_norm(&step);
        if last_norm > 0.0 {
            contraction = contraction.max(step_norm / last_norm);
        }
        last_norm = step_norm;
        let mut lambda = 1.0;
        loop {
            let trial: Vec<f64> = x.iter().zip(&step).map(|(a, b)| a + lambda * b).collect();
            let f_try = grid.residual(&trial);
            let accepted = max_norm(&f_try).is_finite()
                && grid.step_norm(&grid.newton_correction(&lin, &f_try))
                    <= (1.0 - 0.25 * lambda) * step_norm;
            if accepted {
                (x, f) = (trial, f_try);
                break;
            }
            lambda *= 0.5;
            if lambda < opts.min_damping {
                let reason = format!(
                    "no damped step (down to λ = {}) passed the natural monotonicity test at iteration {iteration}; last trial residual {:.3e}",
                    opts.min_damping,
                    max_norm(&f_try)
                );
                return Err(fail(reason, history));
            }
        }
        if lambda < 1.0 {
            damped_steps += 1;
        }
        history.push(max_norm(&f));
    }
    Err(fail(
        format!(
            "{} iterations without reaching the tolerance",
            opts.max_iterations
        ),
        history,
    ))
}

/// Polishing steps after the residual meets the tolerance.
const POLISH_STEPS: usize = 2;

/// Up to `POLISH_STEPS` full Newton steps after convergence, each kept only
/// if it reduces the residual by a factor 10 (so they stop at round-off).
/// They cost O(N) each and leave a solution that satisfies the discrete
/// equations to round-off, so that what remains (e.g. the director drift)
/// is discretization error rather than Newton's stopping point.
fn polish(
    grid: &Grid,
    mut x: Vec<f64>,
    mut f: Vec<f64>,
    mut history: Vec<f64>,
    mut lin: Linearization,
    ws: &mut Scratch,
) -> NewtonOutcome {
    let iterations = history.len() - 1;
    for _ in 0..POLISH_STEPS {
        if !grid.linearize(&x, &mut lin, ws) {
            break;
        }
        let step = grid.newton_correction(&lin, &f);
        let trial: Vec<f64> = x.iter().zip(&step).map(|(a, b)| a + b).collect();
        let f_try = grid.residual(&trial);
        let norm = max_norm(&f_try);
        if norm.is_nan() || norm > 0.1 * history.last().unwrap() {
            break;
        }
        (x, f) = (trial, f_try);
        history.push(norm);
    }
    NewtonOutcome {
        x,
        iterations: iterations.max(history.len() - 1),
        history,
        damped_steps: 0,
        contraction: 0.0,
        lin: lin.valid.then_some(lin),
    }
}

/// In-place LU with row partial pivoting (as nalgebra's `LU`) of the d × d
/// row-major matrix `a`, interchanges in `piv`; false at a zero or
/// non-finite pivot. The stage sizes m·n of the planar (n = 4) and spatial
/// (n = 12) models are compiled for their size.
fn dense_lu(a: &mut [f64], d: usize, piv: &mut [usize]) -> bool {
    match d {
        4 => lu_sized::<4>(a, piv),
        8 => lu_sized::<8>(a, piv),
        12 => lu_sized::<12>(a, piv),
        24 => lu_sized::<24>(a, piv),
        36 => lu_sized::<36>(a, piv),
        _ => lu_any(a, d, piv),
    }
}

/// Solves A x = b in place with the factors of [`dense_lu`].
fn dense_solve(a: &[f64], d: usize, piv: &[usize], b: &mut [f64]) {
    match d {
        4 => solve_sized::<4>(a, piv, b),
        8 => solve_sized::<8>(a, piv, b),
        12 => solve_sized::<12>(a, piv, b),
        24 => solve_sized::<24>(a, piv, b),
        36 => solve_sized::<36>(a, piv, b),
        _ => solve_any(a, d, piv, b),
    }
}

/// [`dense_lu`] for a dimension known at compile time (unrolled loops).
fn lu_sized<const D: usize>(a: &mut [f64], piv: &mut [usize]) -> bool {
    // Inlined with a constant dimension, so the loops unroll.
    lu_any(&mut a[..D * D], D, &mut piv[..D])
}

/// [`dense_solve`] for a dimension known at compile time.
fn solve_sized<const D: usize>(a: &[f64], piv: &[usize], b: &mut [f64]) {
    solve_any(&a[..D * D], D, &piv[..D], &mut b[..D])
}

/// [`dense_lu`] for any dimension.
#[inline(always)]
fn lu_any(a: &mut [f64], d: usize, piv: &mut [usize]) -> bool {
    for k in 0..d {
        let (mut p, mut best) = (k, a[k * d + k].abs());
        for i in k + 1..d {
            let v = a[i * d + k].abs();
            if v > best {
                (p, best) = (i, v);
            }
        }
        piv[k] = p;
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if p != k {
            for c in 0..d {
                a.swap(k * d + c, p * d + c);
            }
        }
        let (upper, lower) = a.split_at_mut((k + 1) * d);
        let row_k = &upper[k * d..];
        let pivot = row_k[k];
        for row in lower.chunks_exact_mut(d) {
            let l = row[k] / pivot;
            row[k] = l;
            if l != 0.0 {
                row[k + 1..]
                    .iter_mut()
                    .zip(&row_k[k + 1..])
                    .for_each(|(v, u)| *v -= l * u);
            }
        }
    }
    true
}

/// [`dense_solve`] for any dimension.
#[inline(always)]
fn solve_any(a: &[f64], d: usize, piv: &[usize], b: &mut [f64]) {
    for (k, &p) in piv.iter().enumerate() {
        b.swap(k, p);
    }
    for i in 1..d {
        let row = &a[i * d..i * d + i];
        let acc: f64 = row.iter().zip(&b[..i]).map(|(l, v)| l * v).sum();
        b[i] -= acc;
    }
    for i in (0..d).rev() {
        let row = &a[i * d..(i + 1) * d];
        let acc: f64 = row[i + 1..]
            .iter()
            .zip(&b[i + 1..])
            .map(|(u, v)| u * v)
            .sum();
        b[i] = (b[i] - acc) / row[i];
    }
}

/// A banded matrix factored by Gaussian elimination with row partial
/// pivoting in LAPACK's `gbtrf` layout: column-major band storage with kl
/// extra rows above for the fill-in of row interchanges. Work
/// O(size · kl · (kl + ku)), storage O(size · (2kl + ku + 1)).
struct BandLu {
    size: usize,
    kl: usize,
    ku: usize,
    ld: usize,
    data: Vec<f64>,
    piv: Vec<usize>,
}

impl BandLu {
    fn zeros(size: usize, kl: usize, ku: usize) -> Self {
        let ld = 2 * kl + ku + 1;
        BandLu {
            size,
            kl,
            ku,
            ld,
            data: vec![0.0; ld * size],
            piv: vec![0; size],
        }
    }

    /// Storage index of (i, j), for j − i ≤ kl + ku and i − j ≤ kl.
    fn idx(&self, i: usize, j: usize) -> usize {
        debug_assert!(
            i <= j + self.kl && j <= i + self.kl + self.ku,
            "({i}, {j}) outside the band"
        );
        j * self.ld + self.kl + self.ku + i - j
    }

    /// Zeros the matrix for a new factorization.
    fn clear(&mut self) {
        self.data.fill(0.0);
    }

    fn add(&mut self, i: usize, j: usize, v: f64) {
        let k = self.idx(i, j);
        self.data[k] += v;
    }

    fn get(&self, i: usize, j: usize) -> f64 {
        self.data[self.idx(i, j)]
    }

    /// In-place LU with partial pivoting; Err(column) at a zero pivot.
    fn factor(&mut self) -> Result<(), usize> {
        let (kl, ku) = (self.kl, self.ku);
        for k in 0..self.size {
            let last = (k + kl).min(self.size - 1);
            let right = (k + kl + ku).min(self.size - 1);
            let p = (k..=last).fold(k, |b, i| {
                if self.get(i, k).abs() > self.get(b, k).abs() {
                    i
                } else {
                    b
                }
            });
            let pivot = self.get(p, k);
            if pivot == 0.0 || !pivot.is_finite() {
                return Err(k);
            }
            self.piv[k] = p;
            if p != k {
                for c in k..=right {
                    let (a, b) = (self.idx(k, c), self.idx(p, c));
                    self.data.swap(a, b);
                }
            }
            // Multipliers below the pivot, then the rank-one update column
            // by column (contiguous in the column-major band storage),
            // skipping the zero columns of the pivot row.
            let (lo, hi) = (self.idx(k + 1, k), self.idx(last, k) + 1);
            for v in &mut self.data[lo..hi] {
                *v /= pivot;
            }
            for c in k + 1..=right {
                let v = self.get(k, c);
                if v == 0.0 {
                    continue;
                }
                let start = self.idx(k + 1, c);
                for (off, i) in (k + 1..=last).enumerate() {
                    let l = self.data[lo + i - (k + 1)];
                    self.data[start + off] -= l * v;
                }
            }
        }
        Ok(())
    }

    /// Solves A x = b in place with the factors.
    fn solve(&self, b: &mut [f64]) {
        let (kl, ku, n) = (self.kl, self.ku, self.size);
        for k in 0..n {
            b.swap(k, self.piv[k]);
            for i in k + 1..=(k + kl).min(n - 1) {
                b[i] -= self.get(i, k) * b[k];
            }
        }
        for k in (0..n).rev() {
            let right = (k + kl + ku).min(n - 1);
            let acc: f64 = (k + 1..=right).map(|c| self.get(k, c) * b[c]).sum();
            b[k] = (b[k] - acc) / self.get(k, k);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The band LU against nalgebra's dense LU on a random banded matrix
    /// that needs pivoting (zero diagonal).
    #[test]
    fn band_lu_matches_dense_lu() {
        let (size, kl, ku) = (23, 4, 3);
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut dense = DMatrix::zeros(size, size);
        let mut band = BandLu::zeros(size, kl, ku);
        for i in 0..size {
            for j in i.saturating_sub(kl)..=(i + ku).min(size - 1) {
                let v = if i == j { 0.0 } else { rnd() };
                dense[(i, j)] = v;
                band.add(i, j, v);
            }
        }
        let b: Vec<f64> = (0..size).map(|_| rnd()).collect();
        let exact = dense
            .clone()
            .lu()
            .solve(&DVector::from_column_slice(&b))
            .unwrap();
        band.factor().unwrap();
        let mut x = b.clone();
        band.solve(&mut x);
        let err = x
            .iter()
            .zip(exact.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-10, "{err}");
    }

    /// The dense LU (compiled sizes and the general one) against nalgebra's.
    #[test]
    fn dense_lu_matches_nalgebra() {
        let mut seed = 987u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for d in [7, 12, 36] {
            let a: Vec<f64> = (0..d * d).map(|_| rnd()).collect();
            let b: Vec<f64> = (0..d).map(|_| rnd()).collect();
            let exact = DMatrix::from_row_slice(d, d, &a)
                .lu()
                .solve(&DVector::from_column_slice(&b))
                .unwrap();
            let (mut f, mut piv, mut x) = (a.clone(), vec![0; d], b.clone());
            assert!(dense_lu(&mut f, d, &mut piv));
            dense_solve(&f, d, &piv, &mut x);
            let err = x
                .iter()
                .zip(exact.iter())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-10, "d {d}: {err}");
        }
    }

    /// The tableau integrates polynomials of degree ≤ m − 1 exactly on
    /// [0, c_j] (stage order m) and of degree ≤ 2m − 1 on [0, 1].
    #[test]
    fn gauss_tableaus_have_their_orders() {
        for m in 1..=3 {
            let t = Tableau::gauss(m).unwrap();
            for q in 0..2 * m {
                let quad: f64 = (0..m).map(|j| t.b[j] * t.c[j].powi(q as i32)).sum();
                assert!((quad - 1.0 / (q as f64 + 1.0)).abs() < 1e-14, "m {m} q {q}");
            }
            for j in 0..m {
                for q in 0..m {
                    let s: f64 = (0..m).map(|l| t.a(j, l) * t.c[l].powi(q as i32)).sum();
                    let exact = t.c[j].powi(q as i32 + 1) / (q as f64 + 1.0);
                    assert!((s - exact).abs() < 1e-14, "m {m} j {j} q {q}");
                }
            }
        }
    }

    #[test]
    fn refine_halves_flagged_intervals() {
        assert_eq!(refine(&[0.0, 1.0, 2.0], &[1]), vec![0.0, 1.0, 1.5, 2.0]);
    }
}
