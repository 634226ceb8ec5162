//! Dead loads: a tip force P, a tip couple C, a distributed force f per
//! unit reference length (self-weight ρAg) and point forces F_k at interior
//! points s_k, all fixed in space.

use nalgebra::Vector3;

/// A dead force F applied at the interior point s of the reference
/// arclength (0 < s < L, checked by [`super::Rod::new`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointForce {
    /// Reference arclength of the point of application (m).
    pub s: f64,
    /// The force, global components (N).
    pub force: Vector3<f64>,
}

/// Dead loads in global components.
#[derive(Debug, Clone, PartialEq)]
pub struct DeadLoads {
    /// Force on the tip (N).
    pub tip_force: Vector3<f64>,
    /// Couple on the tip (N·m).
    pub tip_couple: Vector3<f64>,
    /// Force per unit reference length, uniform along the rod (N/m).
    pub distributed_force: Vector3<f64>,
    /// Forces at interior points, in the order the problem gives them
    /// (`[[loads.point]]`); the same point may appear twice.
    pub point_forces: Vec<PointForce>,
}

impl Default for DeadLoads {
    fn default() -> Self {
        DeadLoads {
            tip_force: Vector3::zeros(),
            tip_couple: Vector3::zeros(),
            distributed_force: Vector3::zeros(),
            point_forces: Vec::new(),
        }
    }
}

impl DeadLoads {
    /// The internal force n(s) = P + ∫_s^L f + Σ_{s_k > s} F_k, exerted on
    /// the part [0, s) by the part (s, L]: the force balance n' + f = 0
    /// integrated from n(L) = P, with the jump n(s_k⁻) − n(s_k⁺) = F_k at
    /// each point force. Dead loads keep their direction as the rod
    /// deforms, so n(s) is known before the shape is. At s = s_k it is the
    /// right limit n(s_k⁺): a solver integrates up to the float below s_k
    /// and restarts at s_k ([`DeadLoads::jumps`]).
    pub fn internal_force(&self, s: f64, length: f64) -> Vector3<f64> {
        let mut n = self.tip_force + self.distributed_force * (length - s);
        for p in self.point_forces.iter().filter(|p| p.s > s) {
            n += p.force;
        }
        n
    }

    /// The points s_k where n(s) jumps, sorted and without repeats (a
    /// force of zero still counts, so that the discretization does not
    /// change as a continued force passes through zero).
    pub fn jumps(&self) -> Vec<f64> {
        let mut s: Vec<f64> = self.point_forces.iter().map(|p| p.s).collect();
        s.sort_by(f64::total_cmp);
        s.dedup();
        s
    }

    /// The same loads multiplied by a factor (load ramps, continuation);
    /// the points of application stay.
    #[must_use]
    pub fn scaled(&self, factor: f64) -> DeadLoads {
        DeadLoads {
            tip_force: self.tip_force * factor,
            tip_couple: self.tip_couple * factor,
            distributed_force: self.distributed_force * factor,
            point_forces: self
                .point_forces
                .iter()
                .map(|p| PointForce {
                    s: p.s,
                    force: p.force * factor,
                })
                .collect(),
        }
    }

    /// A moment scale of the tip and distributed loads on a rod of the
    /// given length (N·m). Point forces are left out: the scale is only the
    /// unit of a residual (the bending scale B/L bounds it below), and its
    /// p-derivative ([`super::RodTangent::residual_scales_rate`]) stays that
    /// of these three loads.
    pub fn moment_scale(&self, length: f64) -> f64 {
        (self.tip_force.norm() * length)
            .max(self.tip_couple.norm())
            .max(self.distributed_force.norm() * length * length)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_force_jumps_the_internal_force_at_its_point() {
        let loads = DeadLoads {
            point_forces: vec![PointForce {
                s: 0.5,
                force: Vector3::new(1.0, 0.0, 0.0),
            }],
            ..Default::default()
        };
        assert_eq!(loads.internal_force(0.25, 1.0).x, 1.0);
        assert_eq!(loads.internal_force(0.5, 1.0).x, 0.0, "right limit at s_k");
        assert_eq!(loads.internal_force(0.75, 1.0).x, 0.0);
        assert_eq!(loads.jumps(), vec![0.5]);
    }
}
