//! Dead loads: a tip force P, a tip couple C and a distributed force f per
//! unit reference length (self-weight ρAg), all fixed in space.

use nalgebra::Vector3;

/// Dead loads in global components.
#[derive(Debug, Clone, PartialEq)]
pub struct DeadLoads {
    /// Force on the tip (N).
    pub tip_force: Vector3<f64>,
    /// Couple on the tip (N·m).
    pub tip_couple: Vector3<f64>,
    /// Force per unit reference length, uniform along the rod (N/m).
    pub distributed_force: Vector3<f64>,
}

impl Default for DeadLoads {
    fn default() -> Self {
        DeadLoads {
            tip_force: Vector3::zeros(),
            tip_couple: Vector3::zeros(),
            distributed_force: Vector3::zeros(),
        }
    }
}

impl DeadLoads {
    /// The internal force n(s) = P + ∫_s^L f, exerted on the part [0, s) by
    /// the part (s, L]: the force balance n' + f = 0 integrated from
    /// n(L) = P. Dead loads keep their direction as the rod deforms, so
    /// n(s) is known before the shape is.
    pub fn internal_force(&self, s: f64, length: f64) -> Vector3<f64> {
        self.tip_force + self.distributed_force * (length - s)
    }

    /// The same loads multiplied by a factor (load ramps, continuation).
    #[must_use]
    pub fn scaled(&self, factor: f64) -> DeadLoads {
        DeadLoads {
            tip_force: self.tip_force * factor,
            tip_couple: self.tip_couple * factor,
            distributed_force: self.distributed_force * factor,
        }
    }

    /// A moment scale of the loads on a rod of the given length (N·m).
    pub fn moment_scale(&self, length: f64) -> f64 {
        (self.tip_force.norm() * length)
            .max(self.tip_couple.norm())
            .max(self.distributed_force.norm() * length * length)
    }
}
