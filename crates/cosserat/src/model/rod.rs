//! The rod: length, stored energy, clamp at s = 0 and dead loads.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::{DeadLoads, StoredEnergy, TipSupport};

/// The support at s = 0: position and the directors d1(0), d2(0), d3(0);
/// a clamp, or a hinge about d2(0).
#[derive(Debug, Clone, PartialEq)]
pub struct Clamp {
    /// r(0) (m).
    pub position: Vector3<f64>,
    /// The director frame [d1 d2 d3] at s = 0, as columns (orthonormal,
    /// right-handed); for a hinge, the frame the turning angle is measured
    /// from.
    pub frame: Matrix3<f64>,
    /// A hinge about d2(0) instead of a clamp: the frame may turn about
    /// d2(0) (its angle is an unknown) and the moment about d2(0) vanishes
    /// there (planar scenes: the pinned end of a column).
    pub hinge: bool,
}

impl Clamp {
    /// A clamp from d1(0) and d3(0); d2 = d3 × d1 completes a right-handed
    /// frame. Orthonormality is the caller's to check (problem files do).
    pub fn new(position: Vector3<f64>, d1: Vector3<f64>, d3: Vector3<f64>) -> Self {
        let d2 = d3.cross(&d1);
        Clamp {
            position,
            frame: Matrix3::from_columns(&[d1, d2, d3]),
            hinge: false,
        }
    }

    /// The paper's clamp: origin, d1 = e1 (vertical, down), d3 = e3.
    pub fn paper() -> Self {
        Clamp::new(Vector3::zeros(), Vector3::x(), Vector3::z())
    }

    /// d_i(0), i = 0, 1, 2.
    pub fn director(&self, i: usize) -> Vector3<f64> {
        self.frame.column(i).into_owned()
    }

    /// The frame turned by `angle` (rad) about d2(0), d3 towards d1:
    /// R [d1 d2 d3] with R d3 = d3 cos θ + d1 sin θ (the clamp angle of the
    /// paper's Fig. 2; a negative angle turns back).
    pub fn turned_frame(&self, angle: f64) -> Matrix3<f64> {
        let axis = nalgebra::Unit::new_normalize(self.director(1));
        nalgebra::Rotation3::from_axis_angle(&axis, angle).matrix() * self.frame
    }
}

/// The units in which tip residuals are measured ([`Rod::residual_scales`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualScales {
    /// Moment about each body axis d_i (N·m).
    pub moment: Vector3<f64>,
    /// Force (N).
    pub force: f64,
    /// Length (m).
    pub length: f64,
}

/// A rod clamped at s = 0 under dead loads, free at s = L or held there by
/// a [`TipSupport`].
#[derive(Debug, Clone)]
pub struct Rod {
    /// Reference length L (m).
    pub length: f64,
    /// The stored energy density W(s, κ).
    pub energy: Arc<dyn StoredEnergy>,
    /// The clamp at s = 0.
    pub clamp: Clamp,
    /// Dead loads.
    pub loads: DeadLoads,
    /// The support at s = L; None for a free tip (a cantilever).
    pub support: Option<TipSupport>,
}

impl Rod {
    /// A characteristic moment (N·m) of the whole rod: the larger of the
    /// largest bending moment B/L that curves the rod by one radian and the
    /// moments of the loads. Only for order-of-magnitude checks; residuals
    /// are scaled per equation by [`Rod::residual_scales`].
    pub fn moment_scale(&self) -> f64 {
        let b = self.energy.stiffness(0.0, &Vector3::zeros());
        let stiff = b.diagonal().max() / self.length;
        stiff.max(self.loads.moment_scale(self.length))
    }

    /// The scale of each kind of tip residual, one per equation so that no
    /// stiffness ratio can hide an unmet condition: the body moment about
    /// d_i is measured in H_ii(L)/L (an error of one unit is a curvature
    /// error of 1/L in that component), or in the loads' moment or the
    /// intrinsic moment |M_i(s, κ = 0)| of that component where those are
    /// larger (the integrated curvature is only as accurate as the
    /// integrator's relative tolerance times its size, and so is a moment
    /// residual measured in anything smaller); forces in the smallest of
    /// these over L or the loads' force; positions in L; angles are already
    /// dimensionless.
    pub fn residual_scales(&self) -> ResidualScales {
        let l = self.length;
        let h = self.energy.stiffness(l, &Vector3::zeros()).diagonal();
        let loads = self.loads.moment_scale(l);
        let largest = h.max();
        let intrinsic = self.intrinsic_moment();
        let moment = Vector3::from_fn(|i, _| {
            let bend = if h[i] > 0.0 { h[i] } else { largest };
            (bend / l)
                .max(loads)
                .max(intrinsic[i])
                .max(f64::MIN_POSITIVE)
        });
        let load_force = self.loads.tip_force.norm() + self.loads.distributed_force.norm() * l;
        ResidualScales {
            moment,
            force: (moment.min() / l).max(load_force),
            length: l,
        }
    }

    /// max over s of |M_i(s, κ = 0)|: the moment an intrinsically curved rod
    /// carries when straightened (B_i |κ⁰_i| for the linear energy), on 65
    /// points along the rod.
    fn intrinsic_moment(&self) -> Vector3<f64> {
        (0..=64)
            .map(|j| {
                let s = self.length * f64::from(j) / 64.0;
                self.energy.moment(s, &Vector3::zeros()).abs()
            })
            .fold(Vector3::zeros(), |a, m| a.sup(&m))
    }

    /// The same rod under loads scaled by `factor`.
    pub fn with_load_factor(&self, factor: f64) -> Rod {
        Rod {
            loads: self.loads.scaled(factor),
            ..self.clone()
        }
    }
}
