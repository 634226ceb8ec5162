//! Shooting: single (one segment) and multiple (K segments) in one
//! formulation.
//!
//! Unknowns: the free initial values u (the curvature at the clamp) and the
//! full state y_j at the interior nodes s_j = jL/K. Residuals: the matching
//! conditions Y_j(s_{j+1}; y_j) − y_{j+1} and the tip conditions g(Y(L)).
//! The Jacobian comes from the variational equations integrated on the same
//! steps as the state (exact derivative of the discrete flow), with the
//! step size controlled on both, never from finite differences. With K = 1 this is single shooting; with K > 1 the
//! products of segment sensitivities that make single shooting ill
//! conditioned on long, soft or heavily loaded rods are never formed.

use nalgebra::{DMatrix, DVector};

use super::collocation::Tableau;
use super::gauss_step::GaussStepper;
use super::newton::NonlinearSystem;
use crate::equations::{PlanarKernel, RodEquations, RodSample};
use crate::model::RodTangent;
use crate::numerics::integrator::{
    DenseRecord, Dop853, FixedDop853, FixedRecorder, IntegrationError, IntegrationStats, Stops,
    Tolerances,
};
use crate::numerics::staircase::Staircase;

/// The shooting formulation of a rod BVP on K segments.
pub struct ShootingSystem<'a> {
    eq: &'a dyn RodEquations,
    segments: usize,
    tol: Tolerances,
    /// The generic integrator, built on first use: a planar solve whose
    /// segments all take the fixed-size path ([`PlanarKernel`]) never
    /// needs its fourteen stage vectors until it samples.
    dop: Option<Dop853>,
    scales: Vec<f64>,
    /// Segments as single Gauss–Legendre steps (the collocation equations
    /// of the segment mesh) instead of adaptive DOP853 integration.
    gauss: Option<GaussStepper>,
    /// The interior points where the right-hand side jumps
    /// ([`RodEquations::jumps`]): every integration stops there.
    jumps: Vec<f64>,
    /// The planar right-hand side as one value
    /// ([`RodEquations::planar_kernel`]): a segment with one sensitivity
    /// column and no jump inside is then integrated on fixed-size arrays
    /// (`fixed`), the same steps and result as `dop`'s.
    kernel: Option<PlanarKernel>,
    fixed: FixedDop853<8>,
    /// The planar kernel's state alone, for the recorded sampling
    /// ([`ShootingSystem::sample_recorded`]); built on first use.
    recorder: Option<FixedRecorder<4>>,
    /// The buffers of one evaluation, kept for the next.
    work: Workspace,
    /// Integration work so far.
    pub stats: IntegrationStats,
}

/// The end of an integrated segment: the state and its sensitivity
/// columns Φ (dim × cols).
struct SegmentEnd {
    state: Vec<f64>,
    phi: DMatrix<f64>,
}

impl Default for SegmentEnd {
    fn default() -> Self {
        SegmentEnd {
            state: Vec::new(),
            phi: DMatrix::zeros(0, 0),
        }
    }
}

/// What [`ShootingSystem::evaluate_staircase_forced`] and
/// [`NonlinearSystem::evaluate`] reuse from one evaluation to the next, so
/// that a Newton iteration of single shooting allocates only inside the
/// equations' tip Jacobian and the LU: the constant seeds of Φ, the
/// segment's start and end, the tip residual g and g' Φ, and the
/// staircase.
#[derive(Default)]
struct Workspace {
    /// ∂y(0)/∂u ([`RodEquations::initial_sensitivity`], a constant of
    /// the equations): the first segment's Φ(0).
    seed: DMatrix<f64>,
    /// The identity, the interior segments' Φ(0); built on first use.
    identity: Option<DMatrix<f64>>,
    start: Vec<f64>,
    end: SegmentEnd,
    g: Vec<f64>,
    g_phi: DMatrix<f64>,
    staircase: Option<Staircase>,
}

impl<'a> ShootingSystem<'a> {
    /// K ≥ 1 segments of equal length.
    pub fn new(eq: &'a dyn RodEquations, segments: usize, tol: Tolerances) -> Self {
        let scales = eq.state_scales();
        ShootingSystem {
            eq,
            segments: segments.max(1),
            tol,
            dop: None,
            scales,
            gauss: None,
            jumps: eq.jumps(),
            kernel: eq.planar_kernel(),
            fixed: FixedDop853::default(),
            recorder: None,
            work: Workspace {
                seed: eq.initial_sensitivity(),
                ..Workspace::default()
            },
            stats: IntegrationStats::default(),
        }
    }

    /// The collocation equations of Gauss–Legendre collocation with
    /// `stages` points (1 to 3; order 2·stages at the nodes) on `intervals`
    /// equal intervals, posed as multiple shooting whose segments are
    /// single Gauss steps (the private `bvp/gauss_step.rs`); None for a stage count
    /// without a tableau. Samples between the nodes are integrated from
    /// the node states by DOP853.
    pub fn collocation(
        eq: &'a dyn RodEquations,
        intervals: usize,
        stages: usize,
        tol: Tolerances,
    ) -> Option<Self> {
        let tab = Tableau::gauss(stages)?;
        Some(ShootingSystem {
            gauss: Some(GaussStepper::new(tab)),
            ..ShootingSystem::new(eq, intervals, tol)
        })
    }

    /// The generic integrator, with room for the longest integrated vector
    /// ([`sensitivity_dimension`]).
    fn dop<'d>(
        dop: &'d mut Option<Dop853>,
        eq: &dyn RodEquations,
        segments: usize,
    ) -> &'d mut Dop853 {
        dop.get_or_insert_with(|| Dop853::with_room(eq.dim(), sensitivity_dimension(eq, segments)))
    }

    fn node(&self, j: usize) -> f64 {
        if j == self.segments {
            self.eq.length()
        } else {
            self.eq.length() * j as f64 / self.segments as f64
        }
    }

    /// The state at node j (j = 0 from u) taken from the unknown vector.
    fn node_state(&self, x: &[f64], j: usize) -> Vec<f64> {
        let mut y = Vec::new();
        self.node_state_into(x, j, &mut y);
        y
    }

    /// [`ShootingSystem::node_state`] into `y`, reusing its storage.
    fn node_state_into(&self, x: &[f64], j: usize, y: &mut Vec<f64>) {
        let (n, p) = (self.eq.dim(), self.eq.unknowns());
        y.clear();
        if j == 0 {
            y.resize(n, 0.0);
            self.eq.initial_state(&x[..p], y);
        } else {
            y.extend_from_slice(self.interior_node(x, j));
        }
    }

    /// The state at interior node j ≥ 1: a slice of the unknowns.
    fn interior_node<'x>(&self, x: &'x [f64], j: usize) -> &'x [f64] {
        let (n, p) = (self.eq.dim(), self.eq.unknowns());
        &x[p + n * (j - 1)..p + n * j]
    }

    /// Integrates segment j from `start` with `cols` sensitivity columns
    /// initialised to `phi0` (dim × cols); returns the end state and Φ.
    fn segment(
        &mut self,
        j: usize,
        start: &[f64],
        phi0: &DMatrix<f64>,
    ) -> Result<(Vec<f64>, DMatrix<f64>), IntegrationError> {
        let mut end = SegmentEnd::default();
        self.forced_segment(j, start, phi0, None, &mut end)?;
        Ok((end.state, end.phi))
    }

    /// [`ShootingSystem::segment`] into `out` (its storage reused), with
    /// `forcing` the last column the parameter sensitivity
    /// z' = f_y z + ∂f/∂p ([`RodEquations::rhs_parameter`]).
    fn forced_segment(
        &mut self,
        j: usize,
        start: &[f64],
        phi0: &DMatrix<f64>,
        forcing: Option<&RodTangent>,
        out: &mut SegmentEnd,
    ) -> Result<(), IntegrationError> {
        let n = self.eq.dim();
        let (a, b) = (self.node(j), self.node(j + 1));
        let cols = phi0.ncols();
        if let (None, Some(kernel), None, 1) = (&self.gauss, self.kernel, forcing, cols) {
            // One piece without a jump ([`pieces`]), found without
            // building the list.
            if !self.jumps.iter().any(|&s| s > a && s <= b) {
                return self.planar_segment(kernel, (a, b), start, phi0, out);
            }
        }
        let span = pieces(&self.jumps, a, b);
        if let Some(stepper) = &mut self.gauss {
            // A jump inside the interval splits the Gauss step there: the
            // pieces chain through the state's jump (the identity at a
            // point force, the curvature's at a point couple).
            let mut y = (start.to_vec(), phi0.clone());
            for piece in span {
                if piece.to > piece.from {
                    self.stats.accepted += 1;
                    y = stepper.step(
                        self.eq,
                        piece.from,
                        piece.to - piece.from,
                        &y.0,
                        &y.1,
                        forcing,
                    )?;
                }
                if let Some(s) = piece.jump {
                    let cols = y.1.ncols();
                    self.eq.jump(s, &mut y.0, cols, y.1.as_mut_slice())?;
                }
            }
            (out.state, out.phi) = y;
            return Ok(());
        }
        let y = &mut out.state;
        y.clear();
        y.extend_from_slice(start);
        y.extend_from_slice(phi0.as_slice());
        let eq = self.eq;
        let mut fp = vec![0.0; if forcing.is_some() { n } else { 0 }];
        let mut rhs = |s: f64, y: &[f64], d: &mut [f64]| {
            let (dy, dphi) = d.split_at_mut(n);
            eq.rhs_linearized(s, &y[..n], cols, &y[n..], dy, dphi);
            if let Some(t) = forcing {
                eq.rhs_parameter(s, &y[..n], dy, t, &mut fp);
                let last = &mut dphi[n * (cols - 1)..];
                last.iter_mut().zip(&fp).for_each(|(a, b)| *a += b);
            }
        };
        // Error control covers the sensitivities too (CVODES' "full" error
        // control): a trivial state (a straight column) would otherwise let
        // the steps grow until Φ, and so the Jacobian and the location of
        // its singularities, is wrong.
        let controlled = y.len();
        // The pieces between jumps chain with the same y, carried across
        // each jump with Φ (continuous at a point force).
        for piece in span {
            if piece.to <= piece.from {
                jump_with_sensitivities(eq, piece.jump, y, n, cols)?;
                continue;
            }
            let stats = Self::dop(&mut self.dop, self.eq, self.segments).integrate(
                &mut rhs,
                piece.from,
                piece.to,
                y,
                controlled,
                &self.tol,
                &[],
                |_, _| {},
                |y| {
                    // Interior nodes are free unknowns off the orthonormal
                    // manifold during Newton: projecting there would make Φ
                    // inconsistent with the flow. The exact flow preserves
                    // d_i·d_j, so nothing drifts that the clamp did not set.
                    if j == 0 {
                        eq.project(&mut y[..n]);
                    }
                },
            )?;
            self.stats += stats;
            jump_with_sensitivities(eq, piece.jump, y, n, cols)?;
        }
        if out.phi.shape() != (n, cols) {
            out.phi = DMatrix::zeros(n, cols);
        }
        out.phi.as_mut_slice().copy_from_slice(&y[n..]);
        y.truncate(n);
        Ok(())
    }

    /// A segment of the planar kernel's equations with one sensitivity
    /// column, on [`FixedDop853`]: the state and the column as one
    /// 8-array, every component controlled, no projection (the planar
    /// state has no invariant to restore) — the steps and the result of
    /// the generic path of [`ShootingSystem::forced_segment`], bit for bit
    /// (tested), with no heap storage and loops of known length.
    fn planar_segment(
        &mut self,
        kernel: PlanarKernel,
        (from, to): (f64, f64),
        start: &[f64],
        phi0: &DMatrix<f64>,
        out: &mut SegmentEnd,
    ) -> Result<(), IntegrationError> {
        let mut y = [0.0; 8];
        y[..4].copy_from_slice(start);
        y[4..].copy_from_slice(phi0.as_slice());
        let stats = self.fixed.integrate(
            |s, y, d| kernel.rates_with_column(s, y, d),
            from,
            to,
            &mut y,
            &self.tol,
        )?;
        self.stats += stats;
        out.state.clear();
        out.state.extend_from_slice(&y[..4]);
        if out.phi.shape() != (4, 1) {
            out.phi = DMatrix::zeros(4, 1);
        }
        out.phi.as_mut_slice().copy_from_slice(&y[4..]);
        Ok(())
    }

    /// A starting vector of unknowns from free values u: the interior nodes
    /// are filled by integrating from u, and by the straight rod beyond a
    /// blow-up.
    pub fn initial_unknowns(&mut self, u: &[f64]) -> Vec<f64> {
        let (n, p) = (self.eq.dim(), self.eq.unknowns());
        let mut x = u.to_vec();
        let mut y = vec![0.0; n];
        self.eq.initial_state(u, &mut y);
        let mut alive = true;
        for j in 1..self.segments {
            if alive {
                let eq = self.eq;
                for piece in pieces(&self.jumps, self.node(j - 1), self.node(j)) {
                    if piece.to > piece.from {
                        let out = Self::dop(&mut self.dop, eq, self.segments).integrate(
                            |s, y: &[f64], d: &mut [f64]| eq.rhs(s, y, d),
                            piece.from,
                            piece.to,
                            &mut y,
                            n,
                            &self.tol,
                            &[],
                            |_, _| {},
                            |y| eq.project(y),
                        );
                        alive = alive && out.is_ok();
                    }
                    if let (Some(s), true) = (piece.jump, alive) {
                        alive = eq.jump(s, &mut y, 0, &mut []).is_ok();
                    }
                }
            }
            if !alive {
                y = self.eq.straight_state(self.node(j));
            }
            x.extend_from_slice(&y);
        }
        debug_assert_eq!(x.len(), p + n * (self.segments - 1));
        x
    }

    /// The unknowns of the same BVP on `segments` equal segments, from
    /// unknowns `x` on this system's: the free values kept, each new
    /// interior node state integrated (DOP853, projected onto orthonormal
    /// directors) from the start of the segment of this system that holds
    /// it. O(segments) work: a fine mesh started from a coarse solve.
    pub fn refined_unknowns(
        &mut self,
        x: &[f64],
        segments: usize,
    ) -> Result<Vec<f64>, IntegrationError> {
        let (n, p) = (self.eq.dim(), self.eq.unknowns());
        let length = self.eq.length();
        let fine: Vec<f64> = (1..segments.max(1))
            .map(|i| length * i as f64 / segments as f64)
            .collect();
        let mut out = Vec::with_capacity(p + n * fine.len());
        out.extend_from_slice(&x[..p]);
        for j in 0..self.segments {
            let (a, b) = (self.node(j), self.node(j + 1));
            let stops: Vec<f64> = fine.iter().copied().filter(|&s| s >= a && s < b).collect();
            if stops.is_empty() {
                continue;
            }
            let mut y = self.node_state(x, j);
            let eq = self.eq;
            // The new nodes read from the continuous extension: a fine mesh
            // costs the steps the tolerance needs, not one per node.
            for (piece, stops) in served_pieces(&self.jumps, a, b, &stops, false) {
                if piece.to > piece.from {
                    let stats = Self::dop(&mut self.dop, eq, self.segments).integrate_serving(
                        |s, y: &[f64], d: &mut [f64]| eq.rhs(s, y, d),
                        (piece.from, piece.to, n),
                        &mut y,
                        &self.tol,
                        stops,
                        Stops::Interpolated,
                        |_, y| out.extend_from_slice(&y[..n]),
                        |y| eq.project(y),
                    )?;
                    self.stats += stats;
                }
                jump_with_sensitivities(eq, piece.jump, &mut y, n, 0)?;
            }
        }
        debug_assert_eq!(out.len(), p + n * fine.len());
        Ok(out)
    }

    /// The residual alone (no sensitivities, so the Kirchhoff model
    /// integrates 12 instead of 48 equations): what finite differences in a
    /// parameter need.
    pub fn residual(&mut self, x: &[f64], r: &mut DVector<f64>) -> Result<(), IntegrationError> {
        let (n, p, k) = (self.eq.dim(), self.eq.unknowns(), self.segments);
        let none = DMatrix::zeros(n, 0);
        for j in 0..k {
            let start = self.node_state(x, j);
            let (end, _) = self.segment(j, &start, &none)?;
            if j + 1 < k {
                let next = self.node_state(x, j + 1);
                for i in 0..n {
                    r[n * j + i] = (end[i] - next[i]) / self.scales[i];
                }
            } else {
                let mut g = vec![0.0; p];
                self.eq.tip_residual(&end, &mut g);
                for i in 0..p {
                    r[n * (k - 1) + i] = g[i];
                }
            }
        }
        Ok(())
    }

    /// The zero Jacobian of this system in its almost block diagonal
    /// shape: the free values u and K − 1 node states as unknowns,
    /// K − 1 matching blocks and the tip conditions as rows.
    pub fn staircase(&self) -> Staircase {
        Staircase::zeros(self.eq.unknowns(), self.eq.dim(), self.segments)
    }

    /// The residual and its exact Jacobian in the almost block diagonal
    /// shape of [`ShootingSystem::staircase`]: segment j contributes
    /// ∂r_j/∂x_j = W Φ_j (W the inverse state scales) and
    /// ∂r_j/∂x_{j+1} = −W, the last segment g'(Y(L)) Φ. O(K) memory, so
    /// continuation on fine collocation meshes never forms the dense
    /// matrix of [`NonlinearSystem::evaluate`].
    pub fn evaluate_staircase(
        &mut self,
        x: &[f64],
        r: &mut DVector<f64>,
        a: &mut Staircase,
    ) -> Result<(), IntegrationError> {
        self.evaluate_staircase_forced(x, r, a, None)
    }

    /// [`ShootingSystem::evaluate_staircase`], and with `forcing` = (t, F_p)
    /// also F_p of [`ShootingSystem::parameter_derivative`] from the same
    /// integration: the sensitivity z is one more column of Φ (z(0) =
    /// ∂y(0)/∂p after the free values' columns, zero after the identity at
    /// interior nodes), so F, F_x and F_p share one step sequence and F_p
    /// costs no integration of its own. Only where
    /// [`ShootingSystem::differentiates`] `t`.
    pub fn evaluate_staircase_forced(
        &mut self,
        x: &[f64],
        r: &mut DVector<f64>,
        a: &mut Staircase,
        forcing: Option<(&RodTangent, &mut DVector<f64>)>,
    ) -> Result<(), IntegrationError> {
        let mut work = std::mem::take(&mut self.work);
        let outcome = self.evaluate_in(&mut work, x, r, a, forcing);
        self.work = work;
        outcome
    }

    /// [`ShootingSystem::evaluate_staircase_forced`] on the buffers of
    /// `work`.
    fn evaluate_in(
        &mut self,
        work: &mut Workspace,
        x: &[f64],
        r: &mut DVector<f64>,
        a: &mut Staircase,
        mut forcing: Option<(&RodTangent, &mut DVector<f64>)>,
    ) -> Result<(), IntegrationError> {
        let (n, p, k) = (self.eq.dim(), self.eq.unknowns(), self.segments);
        let scale_rates = match &forcing {
            Some((t, _)) => self.eq.state_scales_parameter(t),
            None => Vec::new(),
        };
        for j in 0..k {
            self.node_state_into(x, j, &mut work.start);
            let seed = if j == 0 {
                &work.seed
            } else {
                work.identity.get_or_insert_with(|| DMatrix::identity(n, n))
            };
            let cols = seed.ncols();
            let forced;
            let phi0 = match &forcing {
                None => seed,
                Some((t, _)) => {
                    let mut phi0 = seed.clone().insert_column(cols, 0.0);
                    if j == 0 {
                        let mut z0 = vec![0.0; n];
                        self.eq.initial_state_parameter(&x[..p], t, &mut z0);
                        phi0.column_mut(cols).copy_from_slice(&z0);
                    }
                    forced = phi0;
                    &forced
                }
            };
            let tangent = forcing.as_ref().map(|(t, _)| *t);
            self.forced_segment(j, &work.start, phi0, tangent, &mut work.end)?;
            let (end, phi) = (&work.end.state, &work.end.phi);
            if j + 1 < k {
                let next = self.interior_node(x, j + 1);
                let block = a.block_mut(j);
                for i in 0..n {
                    let w = 1.0 / self.scales[i];
                    r[n * j + i] = (end[i] - next[i]) * w;
                    for c in 0..cols {
                        block[(i, c)] = phi[(i, c)] * w;
                    }
                    if let Some((_, fp)) = forcing.as_mut() {
                        fp[n * j + i] = (phi[(i, cols)] - r[n * j + i] * scale_rates[i]) * w;
                    }
                }
                for (d, s) in a.coupling_mut(j).iter_mut().zip(&self.scales) {
                    *d = -1.0 / s;
                }
            } else {
                work.g.resize(p, 0.0);
                self.eq.tip_residual(end, &mut work.g);
                let g_y = self.eq.tip_residual_jacobian(end);
                if work.g_phi.shape() != (p, phi.ncols()) {
                    work.g_phi = DMatrix::zeros(p, phi.ncols());
                }
                g_y.mul_to(phi, &mut work.g_phi);
                let gj = &work.g_phi;
                for i in 0..p {
                    r[n * (k - 1) + i] = work.g[i];
                }
                a.block_mut(j).copy_from(&gj.columns(0, cols));
                if let Some((t, fp)) = forcing.as_mut() {
                    let mut gp = vec![0.0; p];
                    self.eq.tip_residual_parameter(end, t, &mut gp);
                    for i in 0..p {
                        fp[n * (k - 1) + i] = gj[(i, cols)] + gp[i];
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether [`ShootingSystem::parameter_derivative`] is exact for the
    /// rod moving along `t` ([`RodEquations::differentiates`]).
    pub fn differentiates(&self, t: &RodTangent) -> bool {
        self.eq.differentiates(t)
    }

    /// F_p = ∂r/∂p at fixed unknowns x for the rod moving along `t`, by the
    /// sensitivity equations: on each segment z' = f_y z + ∂f/∂p with
    /// z(s_0) = ∂y(0)/∂p on the first segment (the clamp's motion) and
    /// z(s_j) = 0 at the interior nodes (unknowns, fixed); matching rows
    /// ((Y_j − y_{j+1})/w)_p = z/w − r w_p/w, tip rows g_y z + g_p. One
    /// integration of 2n equations instead of a difference's two of n,
    /// and exact: no step h, no truncation error. Only where
    /// [`ShootingSystem::differentiates`] `t`.
    pub fn parameter_derivative(
        &mut self,
        x: &[f64],
        t: &RodTangent,
        fp: &mut DVector<f64>,
    ) -> Result<(), IntegrationError> {
        let (n, p, k) = (self.eq.dim(), self.eq.unknowns(), self.segments);
        let scale_rates = self.eq.state_scales_parameter(t);
        for j in 0..k {
            let start = self.node_state(x, j);
            let mut z0 = DMatrix::zeros(n, 1);
            if j == 0 {
                self.eq
                    .initial_state_parameter(&x[..p], t, z0.as_mut_slice());
            }
            let mut out = SegmentEnd::default();
            self.forced_segment(j, &start, &z0, Some(t), &mut out)?;
            let (end, z) = (out.state, out.phi);
            if j + 1 < k {
                let next = self.node_state(x, j + 1);
                for i in 0..n {
                    let w = self.scales[i];
                    let r = (end[i] - next[i]) / w;
                    fp[n * j + i] = z[(i, 0)] / w - r * scale_rates[i] / w;
                }
            } else {
                let mut gp = vec![0.0; p];
                self.eq.tip_residual_parameter(&end, t, &mut gp);
                let gz = self.eq.tip_residual_jacobian(&end) * &z;
                for i in 0..p {
                    fp[n * (k - 1) + i] = gz[(i, 0)] + gp[i];
                }
            }
        }
        Ok(())
    }

    /// The free values u in the unknown vector.
    pub fn free_values<'x>(&self, x: &'x [f64]) -> &'x [f64] {
        &x[..self.eq.unknowns()]
    }

    /// Samples the solution at `points` (sorted, in [0, L]) and measures the
    /// largest departure of the directors from orthonormality. The points
    /// between steps are read from the integrator's continuous extension
    /// ([`Stops::Interpolated`]): the steps are those the tolerance needs,
    /// whatever the number of points, so that a stability mesh of 10⁵
    /// elements (3·10⁵ quadrature points) costs no more steps than 10²
    /// (landing a step on every point once ran out of the step budget).
    pub fn sample(
        &mut self,
        x: &[f64],
        points: &[f64],
    ) -> Result<(Vec<RodSample>, f64), IntegrationError> {
        self.sample_served(x, points)
    }

    /// [`ShootingSystem::sample`] (the name continuation calls it by).
    pub fn sample_interpolated(
        &mut self,
        x: &[f64],
        points: &[f64],
    ) -> Result<(Vec<RodSample>, f64), IntegrationError> {
        self.sample(x, points)
    }

    /// [`ShootingSystem::sample`], and the continuous extension of every
    /// step of the integration ([`DenseRecord`], segments and pieces in
    /// order of s): the solution anywhere on [0, L] afterwards without
    /// integrating again ([`crate::bvp::Equilibrium::resample`]). Same
    /// steps and samples as [`ShootingSystem::sample`]; three more
    /// evaluations on each step that holds no output point.
    pub fn sample_recorded(
        &mut self,
        x: &[f64],
        points: &[f64],
    ) -> Result<(Vec<RodSample>, f64, DenseRecord), IntegrationError> {
        self.served(x, points, Stops::Recorded)
    }

    fn sample_served(
        &mut self,
        x: &[f64],
        points: &[f64],
    ) -> Result<(Vec<RodSample>, f64), IntegrationError> {
        let (samples, drift, _) = self.served(x, points, Stops::Interpolated)?;
        Ok((samples, drift))
    }

    fn served(
        &mut self,
        x: &[f64],
        points: &[f64],
        serve: Stops,
    ) -> Result<(Vec<RodSample>, f64, DenseRecord), IntegrationError> {
        let n = self.eq.dim();
        let mut samples = Vec::with_capacity(points.len());
        let mut record = DenseRecord::new(n);
        for j in 0..self.segments {
            let (a, b) = (self.node(j), self.node(j + 1));
            let last = j + 1 == self.segments;
            let stops: Vec<f64> = points
                .iter()
                .copied()
                .filter(|&s| s >= a && (s < b || (last && s <= b)))
                .collect();
            let mut y = self.node_state(x, j);
            let eq = self.eq;
            for (piece, stops) in served_pieces(&self.jumps, a, b, &stops, last) {
                let fixed = match (self.kernel, serve) {
                    (Some(kernel), Stops::Recorded) if n == 4 => Some(kernel),
                    _ => None,
                };
                if let (Some(kernel), true) = (fixed, piece.to > piece.from) {
                    // The planar state on a 4-array: the generic path's
                    // steps, samples and record, bit for bit (its `rhs`
                    // is this kernel's, its projection nothing).
                    let mut state = [0.0; 4];
                    state.copy_from_slice(&y);
                    let recorder = self.recorder.get_or_insert_with(FixedRecorder::default);
                    let stats = recorder.integrate_recorded(
                        |s, y, d| kernel.state_rates_fixed(s, y, d),
                        (piece.from, piece.to),
                        &mut state,
                        &self.tol,
                        stops,
                        |s, y| samples.push(eq.sample(s, y)),
                        &mut record,
                    )?;
                    y.copy_from_slice(&state);
                    self.stats += stats;
                } else if piece.to > piece.from {
                    let stats = Self::dop(&mut self.dop, eq, self.segments).integrate_serving(
                        |s, y: &[f64], d: &mut [f64]| eq.rhs(s, y, d),
                        (piece.from, piece.to, n),
                        &mut y,
                        &self.tol,
                        stops,
                        serve,
                        |s, y| samples.push(eq.sample(s, y)),
                        |y| eq.project(y),
                    )?;
                    record.append(Self::dop(&mut self.dop, eq, self.segments).take_record());
                    self.stats += stats;
                }
                jump_with_sensitivities(eq, piece.jump, &mut y, n, 0)?;
            }
        }
        let drift = samples
            .iter()
            .map(RodSample::director_drift)
            .fold(0.0, f64::max);
        Ok((samples, drift, record))
    }
}

/// The length of the integrated vector with the most sensitivity columns
/// a system of `segments` segments integrates: the state, a column per
/// free value (n per interior node's identity seed) and the parameter
/// column of [`ShootingSystem::evaluate_staircase_forced`].
fn sensitivity_dimension(eq: &dyn RodEquations, segments: usize) -> usize {
    let (n, p) = (eq.dim(), eq.unknowns());
    let columns = if segments > 1 { n.max(p) } else { p };
    n * (columns + 2)
}

/// Carries `y` (the state, then `cols` sensitivity columns of it) across
/// `jump` where there is one ([`RodEquations::jump`]).
fn jump_with_sensitivities(
    eq: &dyn RodEquations,
    jump: Option<f64>,
    y: &mut [f64],
    n: usize,
    cols: usize,
) -> Result<(), IntegrationError> {
    let Some(s) = jump else {
        return Ok(());
    };
    let (state, phi) = y.split_at_mut(n);
    eq.jump(s, state, cols, &mut phi[..n * cols])
}

/// One piece of an integration: [from, to] on which the right-hand side
/// is smooth, and the jump s_k that follows it, if any.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    from: f64,
    to: f64,
    /// The point s_k just above `to` across which the state is carried by
    /// [`RodEquations::jump`] before the next piece (or the next segment's
    /// node, a right limit) starts there.
    jump: Option<f64>,
}

/// The pieces of [a, b] on which the right-hand side is smooth: a jump s_k
/// in (a, b] ends a piece at the float just below s_k (so that every
/// evaluation on it, the step's last stage included, sees the left limit
/// n(s_k⁻)), the state is carried across s_k ([`RodEquations::jump`]: a
/// point couple's moment jump; the identity at a point force) and, if
/// s_k < b, the next piece starts at s_k (where the right-hand side is the
/// right limit, [`crate::model::DeadLoads::internal_force`]). A jump at b
/// itself is applied at the end: node states are right limits, so the
/// matching condition at a node on s_k compares right limits. The ulp left
/// out moves the state by O(ε |y'|). One piece without jumps; a piece
/// with `to ≤ from` (two jumps an ulp apart) is not integrated, its jump
/// still applied.
fn pieces(jumps: &[f64], a: f64, b: f64) -> Vec<Piece> {
    let mut out = Vec::with_capacity(1);
    let mut start = a;
    for &s in jumps.iter().filter(|&&s| s > a && s <= b) {
        out.push(Piece {
            from: start,
            to: s.next_down(),
            jump: Some(s),
        });
        start = s;
    }
    if start < b {
        out.push(Piece {
            from: start,
            to: b,
            jump: None,
        });
    }
    out
}

/// [`pieces`] of [a, b], each with the points of `stops` (sorted, in
/// [a, b)) it serves: those in [start, next start); the last piece serves
/// b too when `closed`.
fn served_pieces<'s>(
    jumps: &[f64],
    a: f64,
    b: f64,
    stops: &'s [f64],
    closed: bool,
) -> Vec<(Piece, &'s [f64])> {
    let ps = pieces(jumps, a, b);
    let mut out = Vec::with_capacity(ps.len());
    let mut rest = stops;
    for (i, &piece) in ps.iter().enumerate() {
        let upto = ps.get(i + 1).map_or(b, |next| next.from);
        let last = i + 1 == ps.len();
        // A piece that is not integrated (two jumps an ulp apart) serves
        // nothing: its stops roll over to the next.
        let count = if piece.to > piece.from {
            rest.iter()
                .take_while(|&&s| s < upto || (last && closed && s <= upto))
                .count()
        } else {
            0
        };
        let (mine, others) = rest.split_at(count);
        // A stop in the ulp between the piece's end and the jump is read
        // at the piece's end.
        out.push((piece, mine));
        rest = others;
    }
    out
}

impl NonlinearSystem for ShootingSystem<'_> {
    fn size(&self) -> usize {
        self.eq.unknowns() + self.eq.dim() * (self.segments - 1)
    }

    /// κ(0) (and the other free initial values) in the units of the state
    /// component they set, node states in the state scales.
    fn unknown_scales(&self) -> Vec<f64> {
        let sens = self.eq.initial_sensitivity();
        let mut scales: Vec<f64> = (0..self.eq.unknowns())
            .map(|c| {
                (0..sens.nrows())
                    .find(|&r| sens[(r, c)] != 0.0)
                    .map_or(1.0, |r| self.scales[r])
            })
            .collect();
        for _ in 1..self.segments {
            scales.extend_from_slice(&self.scales);
        }
        scales
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        r: &mut DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), IntegrationError> {
        // Every entry of the staircase is written by each evaluation: the
        // last one's is reused.
        let mut a = self
            .work
            .staircase
            .take()
            .unwrap_or_else(|| self.staircase());
        let outcome = self.evaluate_staircase(x, r, &mut a);
        if outcome.is_ok() {
            a.write_dense(jac);
        }
        self.work.staircase = Some(a);
        outcome
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::equations::PlanarEquations;
    use crate::model::{Clamp, DeadLoads, LinearElastic, Rod};
    use nalgebra::Vector3;
    use std::sync::Arc;

    /// A planar cantilever under a tip force and a distributed load, whose
    /// right-hand side is a [`PlanarKernel`].
    fn loaded_planar() -> PlanarEquations {
        let energy = LinearElastic::uniform([10.0, 1.0, 10.0], [0.0; 3]).unwrap();
        let loads = DeadLoads {
            tip_force: Vector3::new(3.0, 0.0, 0.0),
            distributed_force: Vector3::new(0.5, 0.0, -0.2),
            ..Default::default()
        };
        let rod = Rod::new(1.0, Arc::new(energy), Clamp::paper(), loads, None).unwrap();
        PlanarEquations::new(rod)
    }

    /// The planar kernel's fixed-size segments against the generic path
    /// (the same system with the kernel taken away): the residual, the
    /// Jacobian and the integration work agree bit for bit, single and
    /// multiple shooting, loose and tight tolerances.
    #[test]
    fn the_planar_fast_path_is_the_generic_integration() {
        let eq = loaded_planar();
        assert!(eq.planar_kernel().is_some());
        for (segments, rtol) in [(1, 1e-4), (1, 1e-12), (3, 1e-8)] {
            let tol = Tolerances {
                rtol,
                atol: rtol,
                ..Tolerances::default()
            };
            let mut fast = ShootingSystem::new(&eq, segments, tol);
            let mut slow = ShootingSystem::new(&eq, segments, tol);
            slow.kernel = None;
            let x = fast.initial_unknowns(&[1.3]);
            let size = fast.size();
            let run = |sys: &mut ShootingSystem| {
                let (mut r, mut jac) = (DVector::zeros(size), DMatrix::zeros(size, size));
                sys.evaluate(&x, &mut r, &mut jac).unwrap();
                (r, jac, sys.stats)
            };
            let (a, b) = (run(&mut fast), run(&mut slow));
            assert_eq!(a, b, "{segments} segments, rtol {rtol}");
        }
    }

    /// The recorded sampling of the planar kernel on the fixed-size
    /// integrator against the generic path: the same samples, drift,
    /// record and work, bit for bit, on one and three segments.
    #[test]
    fn the_planar_recorded_sampling_is_the_generic_integration() {
        let eq = loaded_planar();
        let points: Vec<f64> = (0..=7).map(|i| f64::from(i) / 7.0).collect();
        for (segments, rtol) in [(1, 1e-4), (1, 1e-12), (3, 1e-8)] {
            let tol = Tolerances {
                rtol,
                atol: rtol,
                ..Tolerances::default()
            };
            let mut fast = ShootingSystem::new(&eq, segments, tol);
            let mut slow = ShootingSystem::new(&eq, segments, tol);
            slow.kernel = None;
            let x = fast.initial_unknowns(&[1.3]);
            let (a, b) = (
                fast.sample_recorded(&x, &points).unwrap(),
                slow.sample_recorded(&x, &points).unwrap(),
            );
            assert_eq!(a.0.len(), points.len());
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "{segments} segments");
            assert_eq!(fast.stats, slow.stats, "{segments} segments, rtol {rtol}");
        }
    }

    #[test]
    fn a_jump_ends_a_piece_an_ulp_below_and_is_applied_after_it() {
        let half = 0.5_f64;
        assert_eq!(
            pieces(&[half], 0.0, 1.0),
            vec![
                Piece {
                    from: 0.0,
                    to: half.next_down(),
                    jump: Some(half),
                },
                Piece {
                    from: half,
                    to: 1.0,
                    jump: None,
                },
            ]
        );
        // A jump on the segment's end: applied there (node states are
        // right limits); one on its start belongs to the segment before.
        assert_eq!(
            pieces(&[half], 0.0, half),
            vec![Piece {
                from: 0.0,
                to: half.next_down(),
                jump: Some(half),
            }]
        );
        assert_eq!(pieces(&[half], half, 1.0).len(), 1);
    }

    #[test]
    fn a_piece_that_is_not_integrated_serves_no_stop() {
        let close = 0.5_f64.next_up();
        let stops = [0.5, 0.75, 1.0];
        let served = served_pieces(&[close], 0.5, 1.0, &stops, true);
        assert_eq!(served.len(), 2);
        assert!(served[0].0.to <= served[0].0.from && served[0].1.is_empty());
        assert_eq!(served[1].1, &stops[..]);
    }
}
