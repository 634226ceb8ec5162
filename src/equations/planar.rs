//! The planar model: bending about d2 = d2(0) in the plane of d1(0), d3(0).
//!
//! With the turning angle φ measured from d3(0) towards d1(0) and the
//! coordinates x along d1(0), z along d3(0) (DESIGN.md "Planar reduction"):
//!
//!   x' = sin φ,  z' = cos φ,  φ' = κ2,  M2' = −N1,
//!
//! where N1 = n·d1 = n_x cos φ − n_z sin φ and M2 = ∂W/∂κ2 (0, κ2, 0), so
//! κ2' = (−N1 − ∂sM2)/H22. State y = (x, z, φ, κ2); one unknown κ2(0); one
//! tip condition M2(L) = C·d2.

use nalgebra::{DMatrix, Vector3};

use super::{RodEquations, RodSample};
use crate::model::Rod;

/// The 4-ODE planar equations of a rod.
#[derive(Debug, Clone)]
pub struct PlanarEquations {
    rod: Rod,
}

impl PlanarEquations {
    /// The planar equations of a rod whose scene is planar (see
    /// [`crate::model::ModelChoice`]).
    pub fn new(rod: Rod) -> Self {
        PlanarEquations { rod }
    }

    fn kappa(k2: f64) -> Vector3<f64> {
        Vector3::new(0.0, k2, 0.0)
    }

    /// (n_x, n_z): the internal force in the clamp frame's plane.
    fn force_in_plane(&self, s: f64) -> (f64, f64) {
        let n = self.rod.loads.internal_force(s, self.rod.length);
        (
            n.dot(&self.rod.clamp.director(0)),
            n.dot(&self.rod.clamp.director(2)),
        )
    }

    /// (κ2', ∂κ2'/∂φ, ∂κ2'/∂κ2) at (s, φ, κ2).
    fn curvature_rate(&self, s: f64, phi: f64, k2: f64) -> (f64, f64, f64) {
        let e = &self.rod.energy;
        let kappa = Self::kappa(k2);
        let (nx, nz) = self.force_in_plane(s);
        let (sin, cos) = phi.sin_cos();
        let n1 = nx * cos - nz * sin;
        let h22 = e.stiffness(s, &kappa)[(1, 1)];
        let rate = (-n1 - e.moment_rate(s, &kappa)[1]) / h22;
        let dn1 = -nx * sin - nz * cos;
        let t22 = e.stiffness_derivative(s, &kappa, &Self::kappa(rate))[(1, 1)];
        let hs22 = e.stiffness_rate(s, &kappa)[(1, 1)];
        (rate, -dn1 / h22, -(hs22 + t22) / h22)
    }
}

impl RodEquations for PlanarEquations {
    fn dim(&self) -> usize {
        4
    }

    fn unknowns(&self) -> usize {
        1
    }

    fn length(&self) -> f64 {
        self.rod.length
    }

    fn initial_state(&self, u: &[f64], y0: &mut [f64]) {
        y0.copy_from_slice(&[0.0, 0.0, 0.0, u[0]]);
    }

    fn initial_sensitivity(&self) -> DMatrix<f64> {
        DMatrix::from_column_slice(4, 1, &[0.0, 0.0, 0.0, 1.0])
    }

    fn rhs(&self, s: f64, y: &[f64], dy: &mut [f64]) {
        let (sin, cos) = y[2].sin_cos();
        dy[0] = sin;
        dy[1] = cos;
        dy[2] = y[3];
        dy[3] = self.curvature_rate(s, y[2], y[3]).0;
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
        let (sin, cos) = y[2].sin_cos();
        let (rate, d_phi, d_k2) = self.curvature_rate(s, y[2], y[3]);
        dy.copy_from_slice(&[sin, cos, y[3], rate]);
        for c in 0..cols {
            let v = &phi[4 * c..4 * c + 4];
            let out = &mut dphi[4 * c..4 * c + 4];
            out[0] = cos * v[2];
            out[1] = -sin * v[2];
            out[2] = v[3];
            out[3] = d_phi * v[2] + d_k2 * v[3];
        }
    }

    fn tip_residual(&self, y: &[f64], r: &mut [f64]) {
        let m2 = self.rod.energy.moment(self.rod.length, &Self::kappa(y[3]))[1];
        r[0] = m2 - self.rod.loads.tip_couple.dot(&self.rod.clamp.director(1));
    }

    fn tip_residual_jacobian(&self, y: &[f64]) -> DMatrix<f64> {
        let h22 = self
            .rod
            .energy
            .stiffness(self.rod.length, &Self::kappa(y[3]))[(1, 1)];
        DMatrix::from_row_slice(1, 4, &[0.0, 0.0, 0.0, h22])
    }

    fn project(&self, _: &mut [f64]) {}

    /// M2(0) balancing the loads on the straight rod: C·d2 plus the moment
    /// about d2 of P at the tip and f along the rod, then κ2 from M2 by
    /// Newton on ∂W/∂κ2 = M2.
    fn initial_guess(&self) -> Vec<f64> {
        let m = straight_rod_clamp_moment(&self.rod);
        let m2 = m.dot(&self.rod.clamp.director(1));
        let e = &self.rod.energy;
        let mut k2 = 0.0;
        for _ in 0..50 {
            let kappa = Self::kappa(k2);
            let step = (e.moment(0.0, &kappa)[1] - m2) / e.stiffness(0.0, &kappa)[(1, 1)];
            k2 -= step;
            if step.abs() <= 1e-14 * k2.abs().max(1.0) {
                break;
            }
        }
        vec![k2]
    }

    fn unknowns_of(&self, y0: &[f64]) -> Vec<f64> {
        vec![y0[3]]
    }

    fn sample(&self, s: f64, y: &[f64]) -> RodSample {
        let c = &self.rod.clamp;
        let (ex, ey, ez) = (c.director(0), c.director(1), c.director(2));
        let (sin, cos) = y[2].sin_cos();
        let kappa = Self::kappa(y[3]);
        RodSample {
            s,
            position: c.position + ex * y[0] + ez * y[1],
            directors: [ex * cos - ez * sin, ey, ex * sin + ez * cos],
            curvature: kappa,
            moment: self.rod.energy.moment(s, &kappa),
            force: self.rod.loads.internal_force(s, self.rod.length),
        }
    }

    fn straight_state(&self, s: f64) -> Vec<f64> {
        vec![0.0, s, 0.0, 0.0]
    }

    fn moment_scale(&self) -> f64 {
        self.rod.moment_scale()
    }

    fn state_scales(&self) -> Vec<f64> {
        let l = self.rod.length;
        vec![l, l, 1.0, 1.0 / l]
    }
}

/// The moment at the clamp, m(0) = C + (r(L) − r(0)) × P + ∫ (r − r(0)) × f,
/// on the straight rod r(s) = r(0) + s d3(0) (global components).
pub(crate) fn straight_rod_clamp_moment(rod: &Rod) -> Vector3<f64> {
    let t = rod.clamp.director(2);
    let l = rod.length;
    let loads = &rod.loads;
    loads.tip_couple
        + (t * l).cross(&loads.tip_force)
        + (t * (0.5 * l * l)).cross(&loads.distributed_force)
}
