//! The planar model: bending about d2 = d2(0) in the plane of d1(0), d3(0).
//!
//! With the turning angle φ measured from d3(0) towards d1(0) and the
//! coordinates x along d1(0), z along d3(0), the Kirchhoff equations
//! ([`super::KirchhoffEquations`]) with κ = κ2 e2 and d2 constant have
//! d3 = (sin φ, 0, cos φ), d1 = (cos φ, 0, −sin φ), and the d2 component of
//! the moment balance m' + d3 × n = 0 leaves (Antman, *Nonlinear Problems
//! of Elasticity*, 2nd ed., Ch. 4, the planar elastica):
//!
//!   x' = sin φ,  z' = cos φ,  φ' = κ2,  M2' = −N1,
//!
//! where N1 = n·d1 = n_x cos φ − n_z sin φ and M2 = ∂W/∂κ2 (0, κ2, 0), so
//! κ2' = (−N1 − ∂sM2)/H22. State y = (x, z, φ, κ2); one unknown κ2(0); one
//! tip condition M2(L) = C·d2.
//!
//! A hinged base ([`crate::model::Clamp::hinge`]) makes the angle φ(0) the
//! unknown instead of κ2(0), which then follows from M2(0) = 0.
//!
//! A support that holds the tip's position adds the in-plane reaction
//! (R_x, R_z) as two constant states with unknown initial values, and its
//! conditions replace the natural one: the position (or its component
//! across the sliding axis, with R·a = 0) and the tip angle φ(L) when the
//! rotation is held.

use nalgebra::{DMatrix, Vector3};

use super::moment_jump::bending_for_moment;
use super::{RodEquations, RodSample};
use crate::model::{Freedom, ResidualScales, Rod, RodTangent, TipSupport};
use crate::numerics::integrator::IntegrationError;

/// The 4-ODE planar equations of a rod.
#[derive(Debug, Clone)]
pub struct PlanarEquations {
    rod: Rod,
    /// The rod's residual units ([`Rod::residual_scales`], which samples
    /// the energy at 65 points), computed once: the tip residual and its
    /// Jacobian need them at every shooting evaluation.
    units: ResidualScales,
    /// The clamp's d1(0), d3(0): the in-plane axes x, z that every
    /// right-hand side evaluation projects the internal force on.
    axes: (Vector3<f64>, Vector3<f64>),
    /// H22 where it is one number: a trusted energy that is uniform (no
    /// explicit s, so ∂sM = 0 and ∂sH = 0) and quadratic (H independent of
    /// κ, so ∂H/∂κ = 0). The right-hand side then calls no energy method:
    /// four dynamic calls per evaluation of the linearized equations.
    constant_h22: Option<f64>,
    /// (n_x, n_z) of the tip force and of the distributed force on the
    /// axes, where no point force makes n(s) piecewise: n(s) = P + f (L − s)
    /// in the plane without forming the 3-vector at every evaluation.
    force_on_axes: Option<[f64; 4]>,
    /// The right-hand side as one small value where both of the above
    /// hold and the tip is free (no reaction states): [`PlanarKernel`].
    kernel: Option<PlanarKernel>,
}

/// The planar right-hand side of a rod whose H22 is one number (a trusted,
/// uniform, quadratic energy) and whose internal force is
/// n(s) = P + f (L − s) (no point forces), at a free tip: state
/// (x, z, φ, κ2) and
///
///   x' = sin φ,  z' = cos φ,  φ' = κ2,  κ2' = −N1/H22,
///   N1 = n_x cos φ − n_z sin φ,
///
/// with its linearization ∂κ2'/∂φ = (n_x sin φ + n_z cos φ)/H22,
/// ∂κ2'/∂κ2 = 0. One copyable value with no energy calls: what
/// [`PlanarEquations`] itself evaluates in this case, and what shooting's
/// fixed-size fast path (`numerics::integrator::FixedDop853`) inlines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarKernel {
    length: f64,
    /// 1/H22: a product instead of two divisions on every evaluation's
    /// critical path (within an ulp of the quotients).
    compliance: f64,
    /// (n_x, n_z) of the tip force P and of the distributed force f on
    /// the clamp's axes d1(0), d3(0).
    force: [f64; 4],
}

impl PlanarKernel {
    /// The state's rates dy (4 components) at (s, y), and the pieces the
    /// linearization needs: (sin φ, cos φ, ∂κ2'/∂φ).
    #[inline]
    fn state_rates(&self, s: f64, y: &[f64], dy: &mut [f64]) -> (f64, f64, f64) {
        let [px, pz, fx, fz] = self.force;
        let arm = self.length - s;
        let (nx, nz) = (px + fx * arm, pz + fz * arm);
        let (sin, cos) = y[2].sin_cos();
        let n1 = nx * cos - nz * sin;
        let dn1 = -nx * sin - nz * cos;
        dy[0] = sin;
        dy[1] = cos;
        dy[2] = y[3];
        dy[3] = -n1 * self.compliance;
        (sin, cos, -dn1 * self.compliance)
    }

    /// f(s, y) and ∂f/∂y applied to `cols` tangent vectors in `phi`
    /// (4 × cols, column-major), as [`RodEquations::rhs_linearized`].
    #[inline]
    pub fn rates(
        &self,
        s: f64,
        y: &[f64],
        cols: usize,
        phi: &[f64],
        dy: &mut [f64],
        dphi: &mut [f64],
    ) {
        let (sin, cos, d_phi) = self.state_rates(s, y, dy);
        for (v, out) in phi.chunks_exact(4).zip(dphi.chunks_exact_mut(4)).take(cols) {
            out[0] = cos * v[2];
            out[1] = -sin * v[2];
            out[2] = v[3];
            out[3] = d_phi * v[2];
        }
    }

    /// The state and one sensitivity column as one 8-vector
    /// (x, z, φ, κ2, δx, δz, δφ, δκ2): [`PlanarKernel::rates`] with
    /// `cols` = 1 on arrays, for the fixed-size integrator.
    #[inline]
    pub fn rates_with_column(&self, s: f64, y: &[f64; 8], d: &mut [f64; 8]) {
        let (state, column) = y.split_at(4);
        let (dy, dphi) = d.split_at_mut(4);
        self.rates(s, state, 1, column, dy, dphi);
    }

    /// The state's rates alone on a 4-array (x, z, φ, κ2): what
    /// [`RodEquations::rhs`] of the planar equations computes with this
    /// kernel, for the fixed-size sampling integration.
    #[inline]
    pub fn state_rates_fixed(&self, s: f64, y: &[f64; 4], d: &mut [f64; 4]) {
        self.state_rates(s, y, d);
    }
}

impl PlanarEquations {
    /// The planar equations of a rod whose scene is planar (see
    /// [`crate::model::ModelChoice`]).
    pub fn new(rod: Rod) -> Self {
        let units = rod.residual_scales();
        let axes = (rod.clamp().director(0), rod.clamp().director(2));
        let e = rod.energy();
        let constant_h22 = (e.derivatives_trusted() && e.is_uniform() && e.is_quadratic())
            .then(|| e.stiffness(0.0, &Vector3::zeros())[(1, 1)]);
        let loads = rod.loads();
        let force_on_axes = loads.point_loads.is_empty().then(|| {
            let (p, f) = (loads.tip_force, loads.distributed_force);
            [
                p.dot(&axes.0),
                p.dot(&axes.1),
                f.dot(&axes.0),
                f.dot(&axes.1),
            ]
        });
        let free_tip = !rod.support().as_ref().is_some_and(|s| s.holds_position());
        let kernel = match (constant_h22, force_on_axes, free_tip) {
            (Some(h22), Some(force), true) => Some(PlanarKernel {
                length: rod.length(),
                compliance: 1.0 / h22,
                force,
            }),
            _ => None,
        };
        PlanarEquations {
            rod,
            units,
            axes,
            constant_h22,
            force_on_axes,
            kernel,
        }
    }

    fn kappa(k2: f64) -> Vector3<f64> {
        Vector3::new(0.0, k2, 0.0)
    }

    /// Whether the support holds the tip's position (reaction states).
    fn reacts(&self) -> bool {
        self.rod
            .support()
            .as_ref()
            .is_some_and(|s| s.holds_position())
    }

    /// (n_x, n_z): the internal force in the clamp frame's plane, with the
    /// reaction of a held tip.
    fn force_in_plane(&self, s: f64, y: &[f64]) -> (f64, f64) {
        let (nx, nz) = if let Some([px, pz, fx, fz]) = &self.force_on_axes {
            let arm = self.rod.length() - s;
            (px + fx * arm, pz + fz * arm)
        } else {
            let n = self.rod.loads().internal_force(s, self.rod.length());
            (n.dot(&self.axes.0), n.dot(&self.axes.1))
        };
        if y.len() > 4 {
            (nx + y[4], nz + y[5])
        } else {
            (nx, nz)
        }
    }

    /// κ2' at (s, y) with the pieces its linearization and p-derivative
    /// share; ∂κ2'/∂(R_x, R_z) = (−cos φ, sin φ)/H22.
    fn curvature_rate(&self, s: f64, y: &[f64]) -> Curving {
        let (nx, nz) = self.force_in_plane(s, y);
        let (sin, cos) = y[2].sin_cos();
        let n1 = nx * cos - nz * sin;
        let (rate, h22) = if let Some(h22) = self.constant_h22 {
            (-n1 / h22, h22)
        } else {
            let e = &self.rod.energy();
            let kappa = Self::kappa(y[3]);
            let h22 = e.stiffness(s, &kappa)[(1, 1)];
            ((-n1 - e.moment_rate(s, &kappa)[1]) / h22, h22)
        };
        Curving {
            rate,
            sin,
            cos,
            h22,
            nx,
            nz,
        }
    }

    /// (∂κ2'/∂φ, ∂κ2'/∂κ2) at (s, y) given its [`Curving`].
    fn curvature_rate_slopes(&self, s: f64, y: &[f64], c: &Curving) -> (f64, f64) {
        let dn1 = -c.nx * c.sin - c.nz * c.cos;
        if self.constant_h22.is_some() {
            return (-dn1 / c.h22, 0.0);
        }
        let e = &self.rod.energy();
        let kappa = Self::kappa(y[3]);
        let t22 = e.stiffness_derivative(s, &kappa, &Self::kappa(c.rate))[(1, 1)];
        let hs22 = e.stiffness_rate(s, &kappa)[(1, 1)];
        (-dn1 / c.h22, -(hs22 + t22) / c.h22)
    }
}

/// κ2' and what it was computed from: sin φ, cos φ, H22 and the in-plane
/// force (n_x, n_z).
struct Curving {
    rate: f64,
    sin: f64,
    cos: f64,
    h22: f64,
    nx: f64,
    nz: f64,
}

impl PlanarEquations {
    /// κ2(0) at a hinged base: the root of ∂W/∂κ2(0, κ2) = 0 (κ⁰2(0) for
    /// the linear energy), by Newton from κ2 = 0.
    fn hinge_curvature(&self) -> f64 {
        let e = &self.rod.energy();
        crate::numerics::scalar::newton(0.0, 50, 1e-15, |k2| {
            let kappa = Self::kappa(k2);
            e.moment(0.0, &kappa)[1] / e.stiffness(0.0, &kappa)[(1, 1)]
        })
    }

    /// The residuals (3) and Jacobian (3 × dim) of a supported tip, each
    /// dimensionless in its own unit ([`crate::model::Rod::residual_scales`]:
    /// positions over L, angles as they are, the axial force over the force
    /// scale, the moment about d2 over B2/L). The support
    /// is planar (see [`crate::model::ModelChoice`]): targets in the plane,
    /// axes in the plane or, for rotation, along d2 (then free in-plane).
    fn supported_tip(&self, support: &TipSupport, y: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
        let n = self.dim();
        let l = self.rod.length();
        let scales = self.units;
        let c = &self.rod.clamp();
        let (ex, ez) = self.axes;
        let target = support.position - c.position;
        let (px, pz) = (target.dot(&ex), target.dot(&ez));
        let mut r = Vec::with_capacity(3);
        let mut g = DMatrix::zeros(3, n);
        match support.translation {
            Freedom::Free => {}
            Freedom::Fixed => {
                r.push((y[0] - px) / l);
                g[(0, 0)] = 1.0 / l;
                r.push((y[1] - pz) / l);
                g[(1, 1)] = 1.0 / l;
            }
            Freedom::Axial(a) => {
                let (ax, az) = (a.dot(&ex), a.dot(&ez));
                r.push((-(y[0] - px) * az + (y[1] - pz) * ax) / l);
                g[(0, 0)] = -az / l;
                g[(0, 1)] = ax / l;
                let f = scales.force;
                r.push((y[4] * ax + y[5] * az) / f);
                g[(1, 4)] = ax / f;
                g[(1, 5)] = az / f;
            }
        }
        let row = r.len();
        match support.rotation {
            Freedom::Fixed => {
                let d3 = support.frame.column(2);
                // The held angle on the 2π-branch nearest φ(L): a frame
                // fixes the angle only modulo 2π, and atan2's cut at ±π
                // made the residual jump by 2π there — continued in
                // `support.turn.angle` the rod bent by its end unwound
                // from φ(L) = 2.79 to 0.005 in one step at θ = 6.29.
                let target = d3.dot(&ex).atan2(d3.dot(&ez));
                let turns = ((y[2] - target) / std::f64::consts::TAU).round();
                r.push(y[2] - target - std::f64::consts::TAU * turns);
                g[(row, 2)] = 1.0;
            }
            Freedom::Free | Freedom::Axial(_) => {
                let kappa = Self::kappa(y[3]);
                let e = &self.rod.energy();
                let m = scales.moment[1];
                r.push(
                    (e.moment(l, &kappa)[1] - self.rod.loads().tip_couple.dot(&c.director(1))) / m,
                );
                g[(row, 3)] = e.stiffness(l, &kappa)[(1, 1)] / m;
            }
        }
        g = g.rows(0, r.len()).into_owned();
        (r, g)
    }
}

impl PlanarEquations {
    /// ∂/∂p of [`PlanarEquations::supported_tip`]'s residuals at a fixed
    /// tip state, row by row: the in-plane coordinates (p_x, p_z) of the
    /// held position and (a_x, a_z) of a sliding axis move with the
    /// support's shift δX and the clamp's spin ω (δe_x = ω × e_x), the held
    /// angle atan2(u, v) of d̂3 (spinning with the support, δd̂3 = Ω × d̂3)
    /// by (v δu − u δv)/(u² + v²), the moment row as at a
    /// free tip; every row's unit by its rate (value = q/u: δq/u −
    /// value δu/u).
    fn supported_tip_rates(&self, support: &TipSupport, y: &[f64], t: &RodTangent) -> Vec<f64> {
        let l = self.rod.length();
        let (scales, rates) = (self.units, t.residual_scales_rate(&self.rod));
        let c = self.rod.clamp();
        let w = t.clamp_spin();
        let (ex, ez) = (c.director(0), c.director(2));
        let (dex, dez) = (w.cross(&ex), w.cross(&ez));
        let target = support.position - c.position;
        let dtarget = t.support_shift();
        let (px, pz) = (target.dot(&ex), target.dot(&ez));
        let (dpx, dpz) = (
            dtarget.dot(&ex) + target.dot(&dex),
            dtarget.dot(&ez) + target.dot(&dez),
        );
        let ratio = |value: f64, dq: f64, u: f64, du: f64| dq / u - value * du / u;
        let dl = t.length();
        let mut out = Vec::with_capacity(3);
        match support.translation {
            Freedom::Free => {}
            Freedom::Fixed => {
                out.push(ratio((y[0] - px) / l, -dpx, l, dl));
                out.push(ratio((y[1] - pz) / l, -dpz, l, dl));
            }
            Freedom::Axial(a) => {
                let (ax, az) = (a.dot(&ex), a.dot(&ez));
                let (dax, daz) = (a.dot(&dex), a.dot(&dez));
                let value = (-(y[0] - px) * az + (y[1] - pz) * ax) / l;
                let dq = dpx * az - (y[0] - px) * daz - dpz * ax + (y[1] - pz) * dax;
                out.push(ratio(value, dq, l, dl));
                let f = scales.force;
                let value = (y[4] * ax + y[5] * az) / f;
                out.push(ratio(value, y[4] * dax + y[5] * daz, f, rates.force));
            }
        }
        match support.rotation {
            Freedom::Fixed => {
                let d3 = support.frame.column(2).into_owned();
                let dd3 = t.support_spin().cross(&d3);
                let (u, v) = (d3.dot(&ex), d3.dot(&ez));
                let (du, dv) = (d3.dot(&dex) + dd3.dot(&ex), d3.dot(&dez) + dd3.dot(&ez));
                out.push(-(v * du - u * dv) / (u * u + v * v));
            }
            Freedom::Free | Freedom::Axial(_) => {
                let mut g = [0.0];
                self.free_tip_rate(y, t, &mut g);
                out.push(g[0]);
            }
        }
        out
    }

    /// g = (M2(L) − C·d2)/M_s: δg = (δM2 − δC·d2 − C·(ω × d2))/M_s −
    /// g δM_s/M_s.
    fn free_tip_rate(&self, y: &[f64], t: &RodTangent, out: &mut [f64]) {
        let l = self.rod.length();
        let kappa = Self::kappa(y[3]);
        let e = self.rod.energy();
        let d2 = self.rod.clamp().director(1);
        let c = &self.rod.loads().tip_couple;
        let unit = self.units.moment[1];
        let dunit = t.residual_scales_rate(&self.rod).moment[1];
        let g = (e.moment(l, &kappa)[1] - c.dot(&d2)) / unit;
        let dm = t.energy_rate(e.as_ref(), l, &kappa).moment[1];
        let dc = t.loads().tip_couple.dot(&d2) + c.dot(&t.clamp_spin().cross(&d2));
        out[0] = (dm - dc) / unit - g * dunit / unit;
    }
}

impl RodEquations for PlanarEquations {
    fn dim(&self) -> usize {
        if self.reacts() {
            6
        } else {
            4
        }
    }

    fn unknowns(&self) -> usize {
        self.dim() - 3
    }

    fn length(&self) -> f64 {
        self.rod.length()
    }

    fn jumps(&self) -> Vec<f64> {
        self.rod.breaks()
    }

    fn state_jumps(&self) -> bool {
        self.rod.loads().has_point_couples()
    }

    /// A point couple C along d2 drops M2 by C·d2 (d2 is constant in the
    /// plane, so the jump does not depend on the state): κ2⁺ from
    /// ∂W/∂κ2(s, κ2⁺) = M2⁻ − C·d2, and dκ2⁺ = (H22⁻/H22⁺) dκ2⁻.
    fn jump(
        &self,
        s: f64,
        y: &mut [f64],
        cols: usize,
        phi: &mut [f64],
    ) -> Result<(), IntegrationError> {
        let drop = self
            .rod
            .loads()
            .moment_jump(s)
            .dot(&self.rod.clamp().director(1));
        if drop == 0.0 {
            return Ok(());
        }
        let n = self.dim();
        let (k2, ratio) = if let Some(h22) = self.constant_h22 {
            (y[3] + drop / h22, 1.0)
        } else {
            let e = self.rod.energy();
            let before = Self::kappa(y[3]);
            let left = s.next_down();
            let target = e.moment(left, &before)[1] + drop;
            let (k2, h_after) = bending_for_moment(e.as_ref(), s, y[3], target)
                .map_err(|reason| IntegrationError::JumpWithoutValue { s, reason })?;
            (k2, e.stiffness(left, &before)[(1, 1)] / h_after)
        };
        y[3] = k2;
        for c in 0..cols {
            phi[n * c + 3] *= ratio;
        }
        Ok(())
    }

    fn initial_state(&self, u: &[f64], y0: &mut [f64]) {
        y0[..3].fill(0.0);
        y0[3..].copy_from_slice(u);
        if self.rod.clamp().hinge {
            y0[2] = u[0];
            y0[3] = self.hinge_curvature();
        }
    }

    fn initial_sensitivity(&self) -> DMatrix<f64> {
        let n = self.dim();
        let first = if self.rod.clamp().hinge { 2 } else { 3 };
        DMatrix::from_fn(n, n - 3, |i, j| {
            let row = if j == 0 { first } else { j + 3 };
            if i == row {
                1.0
            } else {
                0.0
            }
        })
    }

    fn rhs(&self, s: f64, y: &[f64], dy: &mut [f64]) {
        if let Some(kernel) = &self.kernel {
            kernel.state_rates(s, y, dy);
            return;
        }
        let c = self.curvature_rate(s, y);
        dy[0] = c.sin;
        dy[1] = c.cos;
        dy[2] = y[3];
        dy[3] = c.rate;
        dy[4..].fill(0.0);
    }

    fn rhs_linearized(
        &self,
        s: f64,
        y: &[f64],
        cols: usize,
        phi: &[f64],
        dy: &mut [f64],
        dphi: &mut [f64],
    ) {
        if let Some(kernel) = &self.kernel {
            kernel.rates(s, y, cols, phi, dy, dphi);
            return;
        }
        let c = self.curvature_rate(s, y);
        let (d_phi, d_k2) = self.curvature_rate_slopes(s, y, &c);
        let (sin, cos, h22) = (c.sin, c.cos, c.h22);
        dy[..4].copy_from_slice(&[sin, cos, y[3], c.rate]);
        dy[4..].fill(0.0);
        let n = self.dim();
        for c in 0..cols {
            let v = &phi[n * c..n * (c + 1)];
            let out = &mut dphi[n * c..n * (c + 1)];
            out[0] = cos * v[2];
            out[1] = -sin * v[2];
            out[2] = v[3];
            out[3] = d_phi * v[2] + d_k2 * v[3];
            if n > 4 {
                out[3] += (-cos * v[4] + sin * v[5]) / h22;
                out[4..].fill(0.0);
            }
        }
    }

    fn tip_residual(&self, y: &[f64], r: &mut [f64]) {
        if let Some(support) = &self.rod.support() {
            r.copy_from_slice(&self.supported_tip(support, y).0);
            return;
        }
        let m2 = self
            .rod
            .energy()
            .moment(self.rod.length(), &Self::kappa(y[3]))[1];
        let unit = self.units.moment[1];
        r[0] = (m2
            - self
                .rod
                .loads()
                .tip_couple
                .dot(&self.rod.clamp().director(1)))
            / unit;
    }

    fn tip_residual_jacobian(&self, y: &[f64]) -> DMatrix<f64> {
        if let Some(support) = &self.rod.support() {
            return self.supported_tip(support, y).1;
        }
        let h22 = self
            .rod
            .energy()
            .stiffness(self.rod.length(), &Self::kappa(y[3]))[(1, 1)];
        let unit = self.units.moment[1];
        DMatrix::from_row_slice(1, 4, &[0.0, 0.0, 0.0, h22 / unit])
    }

    fn project(&self, _: &mut [f64]) {}

    fn planar_kernel(&self) -> Option<PlanarKernel> {
        self.kernel
    }

    /// M2(0) balancing the loads on the straight rod: C·d2 plus the moment
    /// about d2 of P at the tip and f along the rod, then κ2 from M2 by
    /// Newton on ∂W/∂κ2 = M2.
    fn initial_guess(&self) -> Vec<f64> {
        let m = straight_rod_clamp_moment(&self.rod);
        let m2 = m.dot(&self.rod.clamp().director(1));
        let e = &self.rod.energy();
        let k2 = crate::numerics::scalar::newton(0.0, 50, 1e-14, |k2| {
            let kappa = Self::kappa(k2);
            (e.moment(0.0, &kappa)[1] - m2) / e.stiffness(0.0, &kappa)[(1, 1)]
        });
        let mut u = vec![if self.rod.clamp().hinge { 0.0 } else { k2 }];
        u.resize(self.unknowns(), 0.0);
        u
    }

    /// (R_x, R_z) = (R·d1(0), R·d3(0)), the unknowns after the first.
    fn set_reaction(&self, u: &mut [f64], r: &Vector3<f64>) -> bool {
        if !self.reacts() {
            return false;
        }
        let c = self.rod.clamp();
        u[1] = r.dot(&c.director(0));
        u[2] = r.dot(&c.director(2));
        true
    }

    fn unknowns_of(&self, y0: &[f64]) -> Vec<f64> {
        let mut u = y0[3..].to_vec();
        if self.rod.clamp().hinge {
            u[0] = y0[2];
        }
        u
    }

    fn sample(&self, s: f64, y: &[f64]) -> RodSample {
        let c = &self.rod.clamp();
        let (ex, ey, ez) = (c.director(0), c.director(1), c.director(2));
        let (sin, cos) = y[2].sin_cos();
        let kappa = Self::kappa(y[3]);
        RodSample {
            s,
            position: c.position + ex * y[0] + ez * y[1],
            directors: [ex * cos - ez * sin, ey, ex * sin + ez * cos],
            curvature: kappa,
            moment: self.rod.energy().moment(s, &kappa),
            force: self.rod.loads().internal_force(s, self.rod.length())
                + if y.len() > 4 {
                    ex * y[4] + ez * y[5]
                } else {
                    Vector3::zeros()
                },
        }
    }

    fn curvature(&self, _s: f64, y: &[f64]) -> Vector3<f64> {
        Self::kappa(y[3])
    }

    fn straight_state(&self, s: f64) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        y[1] = s;
        y
    }

    fn state_scales(&self) -> Vec<f64> {
        let l = self.rod.length();
        let mut scales = vec![l, l, 1.0, 1.0 / l];
        scales.resize(self.dim(), self.units.force);
        scales
    }

    /// The position (x, z): f reads only the angle, the curvature and the
    /// reaction.
    fn quadrature_components(&self) -> std::ops::Range<usize> {
        0..2
    }

    /// A tangent whose energy rates are exact for this rod.
    fn differentiates(&self, t: &RodTangent) -> bool {
        t.fits(&self.rod)
    }

    /// (L'/L) f, plus κ2' = (−N1 − ∂sM2)/H22 moved at fixed (φ, κ2):
    /// δκ2' = (−δN1 − δ∂sM2 − δH22 κ2')/H22 with δN1 = δn_x cos φ −
    /// δn_z sin φ, δn_x = δn·d1(0) + n·(ω × d1(0)) (likewise z).
    fn rhs_parameter(&self, s: f64, y: &[f64], f: &[f64], t: &RodTangent, out: &mut [f64]) {
        let stretch = t.length() / self.rod.length();
        for (o, v) in out.iter_mut().zip(f) {
            *o = v * stretch;
        }
        let c = self.rod.clamp();
        let (ex, ez) = (c.director(0), c.director(2));
        let (n, dn) = (
            self.rod.loads().internal_force(s, self.rod.length()),
            t.internal_force_rate(&self.rod, s),
        );
        let w = t.clamp_spin();
        let dnx = dn.dot(&ex) + n.dot(&w.cross(&ex));
        let dnz = dn.dot(&ez) + n.dot(&w.cross(&ez));
        let (sin, cos, rate) = (f[0], f[1], f[3]);
        let kappa = Self::kappa(y[3]);
        let e = self.rod.energy();
        let de = t.energy_rate(e.as_ref(), s, &kappa);
        let h22 = e.stiffness(s, &kappa)[(1, 1)];
        out[3] +=
            (-(dnx * cos - dnz * sin) - de.moment_rate[1] - de.stiffness[(1, 1)] * rate) / h22;
    }

    /// Zero but at a hinged base, where κ2(0) solves M2(0, κ2) = 0:
    /// δκ2(0) = −δM2/H22.
    fn initial_state_parameter(&self, u: &[f64], t: &RodTangent, out: &mut [f64]) {
        out.fill(0.0);
        if self.rod.clamp().hinge {
            let mut y0 = vec![0.0; self.dim()];
            self.initial_state(u, &mut y0);
            let kappa = Self::kappa(y0[3]);
            let e = self.rod.energy();
            let dm = t.energy_rate(e.as_ref(), 0.0, &kappa).moment[1];
            out[3] = -dm / e.stiffness(0.0, &kappa)[(1, 1)];
        }
    }

    /// The free tip's rate (`free_tip_rate`), a support's row by row
    /// (`supported_tip_rates`).
    fn tip_residual_parameter(&self, y: &[f64], t: &RodTangent, out: &mut [f64]) {
        match self.rod.support() {
            Some(support) => out.copy_from_slice(&self.supported_tip_rates(support, y, t)),
            None => self.free_tip_rate(y, t, out),
        }
    }

    fn state_scales_parameter(&self, t: &RodTangent) -> Vec<f64> {
        let (l, dl) = (self.rod.length(), t.length());
        let mut rates = vec![dl, dl, 0.0, -dl / (l * l)];
        rates.resize(self.dim(), t.residual_scales_rate(&self.rod).force);
        rates
    }
}

/// The moment at the clamp, m(0) = C + Σ C_k + (r(L) − r(0)) × P +
/// ∫ (r − r(0)) × f, on the straight rod r(s) = r(0) + s d3(0) (global
/// components): every couple beyond s = 0 acts on the clamp undiminished.
/// The point forces' arms are left out (a guess only; Newton and the ramp
/// take it from there).
pub(crate) fn straight_rod_clamp_moment(rod: &Rod) -> Vector3<f64> {
    let t = rod.clamp().director(2);
    let l = rod.length();
    let loads = &rod.loads();
    let point_couples: Vector3<f64> = loads.point_loads.iter().map(|p| p.couple).sum();
    loads.tip_couple
        + point_couples
        + (t * l).cross(&loads.tip_force)
        + (t * (0.5 * l * l)).cross(&loads.distributed_force)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::Vector3;

    use super::*;
    use crate::model::{Clamp, DeadLoads, LinearElastic};

    /// The kernel (constant H22, no energy calls) against the general path
    /// of the same rod (H22, ∂sM and ∂H/∂κ asked of the energy at every
    /// evaluation, n(s) formed as a 3-vector): f and ∂f/∂y · φ agree to
    /// round-off at states across the turn.
    #[test]
    fn the_kernel_is_the_general_right_hand_side() {
        let energy = LinearElastic::uniform([10.0, 2.5, 10.0], [0.0; 3]).unwrap();
        let loads = DeadLoads {
            tip_force: Vector3::new(3.0, 0.0, 1.0),
            distributed_force: Vector3::new(0.5, 0.0, -0.2),
            ..Default::default()
        };
        let rod = Rod::new(1.5, Arc::new(energy), Clamp::paper(), loads, None).unwrap();
        let fast = PlanarEquations::new(rod);
        assert!(fast.planar_kernel().is_some());
        let general = PlanarEquations {
            constant_h22: None,
            force_on_axes: None,
            kernel: None,
            ..fast.clone()
        };
        let phi = [0.3, -0.7, 1.1, -2.0, 0.0, 0.5, -0.4, 0.9];
        for (s, angle) in [(0.0, 0.0), (0.4, 1.2), (1.1, -2.9), (1.5, 4.0)] {
            let y = [0.2, 0.9, angle, -1.7];
            let mut out = [[0.0; 12]; 2];
            for (eq, o) in [&fast, &general].into_iter().zip(&mut out) {
                let (dy, dphi) = o.split_at_mut(4);
                eq.rhs_linearized(s, &y, 2, &phi, dy, dphi);
                let mut alone = [0.0; 4];
                eq.rhs(s, &y, &mut alone);
                assert_eq!(alone, dy[..4], "rhs and rhs_linearized at s = {s}");
            }
            for (a, b) in out[0].iter().zip(&out[1]) {
                assert!(
                    (a - b).abs() <= 1e-15 * b.abs().max(1.0),
                    "s = {s}: {a} against {b}"
                );
            }
        }
    }
}
