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

use nalgebra::{DMatrix, DVector, Dyn, LU};

use super::integrator::{Dop853, Tolerances};
use super::newton::NewtonOptions;
use crate::equations::{RodEquations, RodSample};

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
                let guess: Vec<f64> = grid
                    .tab
                    .c
                    .iter()
                    .flat_map(|c| self.interpolate(self.mesh[i] + c * t))
                    .collect();
                grid.local_step(self.mesh[i], t, &self.states[i], guess)
                    .unwrap_or_else(|| self.interpolate(s))
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
        let last = self.mesh.len() - 1;
        if s >= self.mesh[last] {
            return self.states[last].clone();
        }
        let i = self.mesh.partition_point(|&x| x <= s).clamp(1, last) - 1;
        let h = self.mesh[i + 1] - self.mesh[i];
        let t = (s - self.mesh[i]) / h;
        let tab = Tableau::gauss(self.stage_count).expect("stored stage count is valid");
        let mut nodes = vec![0.0];
        nodes.extend_from_slice(&tab.c);
        let n = self.states[i].len();
        let mut y = vec![0.0; n];
        for (q, _) in nodes.iter().enumerate() {
            let w = lagrange(&nodes, q, t);
            let v = if q == 0 {
                &self.states[i][..]
            } else {
                &self.stage_values[i][(q - 1) * n..q * n]
            };
            y.iter_mut().zip(v).for_each(|(a, b)| *a += w * b);
        }
        y
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
        intervals: usize,
        reason: String,
        history: Vec<f64>,
    },
    /// The condensed Jacobian could not be factored.
    #[error("singular collocation Jacobian at Newton iteration {iteration} on {intervals} intervals (a fold or bifurcation, or a degenerate guess); scaled residual history {}", format_history(.history))]
    SingularJacobian {
        iteration: usize,
        intervals: usize,
        history: Vec<f64>,
    },
    /// Without adaptation, the fixed mesh is too coarse for the tolerance
    /// (returned by [`crate::bvp::solve`], which never passes off such a
    /// solution as converged; [`solve_collocation`] returns it with its
    /// `error_estimate`).
    #[error("error estimate {estimate:.3e} on the fixed mesh of {intervals} intervals exceeds the tolerance {tolerance:.1e} (mesh adaptation is off)")]
    CoarseMesh {
        tolerance: f64,
        estimate: f64,
        intervals: usize,
    },
    /// Adaptation would need more than `max_intervals` intervals.
    #[error("mesh error tolerance {tolerance:.1e} not reached within {max_intervals} intervals: error estimate {estimate:.3e} on {intervals} intervals, {flagged} of them above their share")]
    ToleranceNotReached {
        tolerance: f64,
        estimate: f64,
        intervals: usize,
        max_intervals: usize,
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
        let errors = grid.local_errors(&outcome.x);
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
struct Tableau {
    m: usize,
    c: Vec<f64>,
    /// m × m, row-major.
    a: Vec<f64>,
    b: Vec<f64>,
}

impl Tableau {
    fn gauss(m: usize) -> Option<Tableau> {
        let (c, b) = match m {
            1 => (vec![0.5], vec![1.0]),
            2 => {
                let d = 3f64.sqrt() / 6.0;
                (vec![0.5 - d, 0.5 + d], vec![0.5, 0.5])
            }
            3 => {
                let d = 15f64.sqrt() / 10.0;
                (
                    vec![0.5 - d, 0.5, 0.5 + d],
                    vec![5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0],
                )
            }
            _ => return None,
        };
        let a = c
            .iter()
            .flat_map(|&cj| integral_weights(&c, &b, cj))
            .collect();
        Some(Tableau { m, c, a, b })
    }

    fn a(&self, j: usize, l: usize) -> f64 {
        self.a[j * self.m + l]
    }
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
    moment_scale: f64,
    /// ∂y_0/∂u.
    sens: DMatrix<f64>,
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
            moment_scale: eq.moment_scale(),
            sens: eq.initial_sensitivity(),
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
        let states: Vec<Vec<f64>> = match warm {
            Some(w) => points.iter().map(|&s| w.interpolate(s)).collect(),
            None if straight => points.iter().map(|&s| self.eq.straight_state(s)).collect(),
            None => self.integrate_guess(&u, &points),
        };
        let (n, m) = (self.n, self.tab.m);
        let mut x = u;
        x.reserve(self.size());
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

    /// f at the stages of interval i (m·n numbers).
    fn stage_rates(&self, i: usize, stages: &[f64]) -> Vec<f64> {
        let (n, (s, h)) = (self.n, self.span(i));
        let mut f = vec![0.0; stages.len()];
        for (j, c) in self.tab.c.iter().enumerate() {
            let r = j * n..(j + 1) * n;
            self.eq.rhs(s + c * h, &stages[r.clone()], &mut f[r]);
        }
        f
    }

    /// The scaled residual: per interval the m·n stage equations and the n
    /// node equations, then the p tip conditions.
    fn residual(&self, x: &[f64]) -> Vec<f64> {
        let (n, m) = (self.n, self.tab.m);
        let mut r = Vec::with_capacity(self.size());
        let mut y = self.node(x, 0);
        for i in 0..self.intervals() {
            let h = self.span(i).1;
            let st = self.stages(x, i);
            let f = self.stage_rates(i, st);
            for j in 0..m {
                for k in 0..n {
                    let acc: f64 = (0..m).map(|l| self.tab.a(j, l) * f[l * n + k]).sum();
                    r.push((st[j * n + k] - y[k] - h * acc) * self.w[k]);
                }
            }
            let next = self.node(x, i + 1);
            for k in 0..n {
                let acc: f64 = (0..m).map(|j| self.tab.b[j] * f[j * n + k]).sum();
                r.push((next[k] - y[k] - h * acc) * self.w[k]);
            }
            y = next;
        }
        let mut g = vec![0.0; self.p];
        self.eq.tip_residual(&y, &mut g);
        r.extend(g.iter().map(|v| v / self.moment_scale));
        r
    }

    /// ∂f/∂y at (s, y), from the linearization applied to the identity.
    fn jacobian(&self, s: f64, y: &[f64]) -> DMatrix<f64> {
        let n = self.n;
        let id = DMatrix::<f64>::identity(n, n);
        let (mut dy, mut dphi) = (vec![0.0; n], vec![0.0; n * n]);
        self.eq
            .rhs_linearized(s, y, n, id.as_slice(), &mut dy, &mut dphi);
        DMatrix::from_column_slice(n, n, &dphi)
    }

    /// W = I − h (A ⊗ I) diag(J_l): the stage block of the Jacobian.
    fn stage_matrix(&self, h: f64, jacs: &[DMatrix<f64>]) -> DMatrix<f64> {
        let (n, m) = (self.n, self.tab.m);
        let mut w = DMatrix::identity(m * n, m * n);
        for j in 0..m {
            for (l, jl) in jacs.iter().enumerate() {
                let mut blk = w.view_mut((j * n, l * n), (n, n));
                blk -= jl * (h * self.tab.a(j, l));
            }
        }
        w
    }

    /// The Newton matrix at x, condensed and factored; None if singular.
    fn linearize(&self, x: &[f64]) -> Option<Linearization> {
        let (n, p, k) = (self.n, self.p, self.intervals());
        let mut band = BandLu::zeros(p + n * k, 2 * n - 1 - p, n + p - 1);
        let mut blocks = Vec::with_capacity(k);
        for i in 0..k {
            let blk = self.condense(i, self.stages(x, i))?;
            let gamma = if i == 0 {
                &blk.gamma * &self.sens
            } else {
                blk.gamma.clone()
            };
            let col = if i == 0 { 0 } else { p + n * (i - 1) };
            for r in 0..n {
                for c in 0..gamma.ncols() {
                    band.add(n * i + r, col + c, -gamma[(r, c)] * self.w[r]);
                }
                band.add(n * i + r, p + n * i + r, self.w[r]);
            }
            blocks.push(blk);
        }
        let y_tip = self.node(x, k);
        let gt = self.eq.tip_residual_jacobian(&y_tip) / self.moment_scale;
        for r in 0..p {
            for c in 0..n {
                band.add(n * k + r, p + n * (k - 1) + c, gt[(r, c)]);
            }
        }
        band.factor().ok()?;
        Some(Linearization { blocks, band })
    }

    /// Condensation of interval i: δY = v + Z δy_i with W Z = E (stacked
    /// identities), and Γ = I + h Σ_j b_j J_j Z_j (AMR §7.2.1).
    fn condense(&self, i: usize, st: &[f64]) -> Option<Condensed> {
        let (n, m, (s, h)) = (self.n, self.tab.m, self.span(i));
        let jacs: Vec<DMatrix<f64>> = (0..m)
            .map(|j| self.jacobian(s + self.tab.c[j] * h, &st[j * n..(j + 1) * n]))
            .collect();
        let lu = self.stage_matrix(h, &jacs).lu();
        let e = DMatrix::from_fn(m * n, n, |r, c| if r % n == c { 1.0 } else { 0.0 });
        let z = lu.solve(&e)?;
        let hbj: Vec<DMatrix<f64>> = jacs
            .into_iter()
            .enumerate()
            .map(|(j, jj)| jj * (h * self.tab.b[j]))
            .collect();
        let mut gamma = DMatrix::identity(n, n);
        for (j, hb) in hbj.iter().enumerate() {
            gamma += hb * z.rows(j * n, n);
        }
        z.iter()
            .all(|v| v.is_finite())
            .then_some(Condensed { lu, z, hbj, gamma })
    }

    /// −J⁻¹F for a scaled residual F, in the unknowns' layout.
    fn newton_correction(&self, lin: &Linearization, f: &[f64]) -> Vec<f64> {
        let (n, m, p, k) = (self.n, self.tab.m, self.p, self.intervals());
        let mut rhs = vec![0.0; p + n * k];
        let mut vs = Vec::with_capacity(k);
        for (i, blk) in lin.blocks.iter().enumerate() {
            let base = i * (m + 1) * n;
            let g = DVector::from_fn(m * n, |r, _| -f[base + r] / self.w[r % n]);
            let v = blk.lu.solve(&g).unwrap_or_else(|| g.map(|_| f64::NAN));
            for r in 0..n {
                let mut acc = -f[base + m * n + r] / self.w[r];
                for (j, hb) in blk.hbj.iter().enumerate() {
                    acc += (hb.row(r) * v.rows(j * n, n))[0];
                }
                rhs[n * i + r] = acc * self.w[r];
            }
            vs.push(v);
        }
        for q in 0..p {
            rhs[n * k + q] = -f[k * (m + 1) * n + q];
        }
        lin.band.solve(&mut rhs);
        let mut dx = rhs.clone();
        for (i, (blk, v)) in lin.blocks.iter().zip(vs).enumerate() {
            let dyi = if i == 0 {
                &self.sens * DVector::from_column_slice(&rhs[..p])
            } else {
                DVector::from_column_slice(&rhs[p + n * (i - 1)..p + n * i])
            };
            dx.extend((v + &blk.z * dyi).iter());
        }
        dx
    }

    /// A weighted Euclidean norm of a correction (δy_0 = S δu, nodes and
    /// stages, each component divided by its scale).
    fn step_norm(&self, dx: &[f64]) -> f64 {
        let (n, p) = (self.n, self.p);
        let dy0 = &self.sens * DVector::from_column_slice(&dx[..p]);
        let head: f64 = dy0.iter().zip(&self.w).map(|(d, w)| (d * w).powi(2)).sum();
        let rest: f64 = dx[p..]
            .iter()
            .enumerate()
            .map(|(q, d)| (d * self.w[q % n]).powi(2))
            .sum();
        (head + rest).sqrt()
    }

    /// One collocation step of width h from y at s, its stage equations
    /// solved by Newton from `guess`; None if that fails.
    fn local_step(&self, s: f64, h: f64, y: &[f64], guess: Vec<f64>) -> Option<Vec<f64>> {
        let (n, m) = (self.n, self.tab.m);
        let mut st = guess;
        let rates = |st: &[f64]| -> Vec<f64> {
            let mut f = vec![0.0; m * n];
            for j in 0..m {
                let r = j * n..(j + 1) * n;
                self.eq
                    .rhs(s + self.tab.c[j] * h, &st[r.clone()], &mut f[r]);
            }
            f
        };
        let mut small = false;
        for _ in 0..30 {
            let f = rates(&st);
            let g = DVector::from_fn(m * n, |r, _| {
                let (j, k) = (r / n, r % n);
                let acc: f64 = (0..m).map(|l| self.tab.a(j, l) * f[l * n + k]).sum();
                y[k] + h * acc - st[r]
            });
            let jacs: Vec<_> = (0..m)
                .map(|j| self.jacobian(s + self.tab.c[j] * h, &st[j * n..(j + 1) * n]))
                .collect();
            let d = self.stage_matrix(h, &jacs).lu().solve(&g)?;
            st.iter_mut().zip(d.iter()).for_each(|(a, b)| *a += b);
            let size = d
                .iter()
                .enumerate()
                .map(|(r, v)| (v * self.w[r % n]).abs())
                .fold(0.0, f64::max);
            if !size.is_finite() {
                return None;
            }
            if small {
                break;
            }
            small = size <= 1e-13;
        }
        let f = rates(&st);
        Some(
            (0..n)
                .map(|k| y[k] + h * (0..m).map(|j| self.tab.b[j] * f[j * n + k]).sum::<f64>())
                .collect(),
        )
    }

    /// Local error of every interval by step doubling from the converged
    /// node state: one step of width h against two of h/2, the difference
    /// scaled by 1/(1 − 2^{−2m}) (the local error is O(h^{2m+1})).
    fn local_errors(&self, x: &[f64]) -> Vec<f64> {
        let (n, m) = (self.n, self.tab.m);
        let sol = self.solution_parts(x);
        let factor = 1.0 / (1.0 - 0.5f64.powi(2 * m as i32));
        (0..self.intervals())
            .map(|i| {
                let (s, h) = self.span(i);
                let y = &sol.states[i];
                let guess = |a: f64, w: f64| -> Vec<f64> {
                    self.tab
                        .c
                        .iter()
                        .flat_map(|c| sol.interpolate(a + c * w))
                        .collect()
                };
                let full = self.local_step(s, h, y, guess(s, h));
                let half = self
                    .local_step(s, 0.5 * h, y, guess(s, 0.5 * h))
                    .and_then(|mid| {
                        self.local_step(s + 0.5 * h, 0.5 * h, &mid, guess(s + 0.5 * h, 0.5 * h))
                    });
                match (full, half) {
                    (Some(a), Some(b)) => {
                        factor
                            * (0..n)
                                .map(|k| ((a[k] - b[k]) * self.w[k]).abs())
                                .fold(0.0, f64::max)
                    }
                    _ => f64::INFINITY,
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

/// The condensed stage block of one interval.
struct Condensed {
    lu: LU<f64, Dyn, Dyn>,
    /// W⁻¹E: the stage corrections' response to δy_i.
    z: DMatrix<f64>,
    /// h b_j J_j.
    hbj: Vec<DMatrix<f64>>,
    /// The interval's propagator δy_i ↦ δy_{i+1}.
    gamma: DMatrix<f64>,
}

/// The factored Newton matrix.
struct Linearization {
    blocks: Vec<Condensed>,
    band: BandLu,
}

struct NewtonOutcome {
    x: Vec<f64>,
    iterations: usize,
    history: Vec<f64>,
    damped_steps: usize,
    contraction: f64,
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
    for iteration in 0..=opts.max_iterations {
        if *history.last().unwrap() <= opts.tolerance {
            let mut out = polish(grid, x, f, history);
            out.damped_steps = damped_steps;
            out.contraction = contraction;
            return Ok(out);
        }
        if iteration == opts.max_iterations {
            break;
        }
        let singular = |history| CollocationError::SingularJacobian {
            iteration,
            intervals,
            history,
        };
        let Some(lin) = grid.linearize(&x) else {
            return Err(singular(history));
        };
        let step = grid.newton_correction(&lin, &f);
        if step.iter().any(|v| !v.is_finite()) {
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
fn polish(grid: &Grid, mut x: Vec<f64>, mut f: Vec<f64>, mut history: Vec<f64>) -> NewtonOutcome {
    let iterations = history.len() - 1;
    for _ in 0..POLISH_STEPS {
        let Some(lin) = grid.linearize(&x) else { break };
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
