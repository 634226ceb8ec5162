//! Dead loads: a tip force P, a tip couple C, a distributed force f per
//! unit reference length (self-weight ρAg) and point loads (F_k, C_k) at
//! interior points s_k, all fixed in space.

use nalgebra::Vector3;

/// A dead force F and a dead couple C applied at the interior point s of
/// the reference arclength (0 < s < L, both finite: checked by
/// [`super::Rod::new`]). The force makes the internal force n(s) jump
/// ([`DeadLoads::internal_force`]), the couple the internal moment
/// ([`DeadLoads::moment_jump`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLoad {
    /// Reference arclength of the point of application (m).
    pub s: f64,
    /// The force, global components (N).
    pub force: Vector3<f64>,
    /// The couple, global components (N·m).
    pub couple: Vector3<f64>,
}

impl PointLoad {
    /// A point force F at s, without a couple.
    pub fn force(s: f64, force: Vector3<f64>) -> PointLoad {
        PointLoad {
            s,
            force,
            couple: Vector3::zeros(),
        }
    }
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
    /// Forces and couples at interior points, in the order the problem gives them
    /// (`[[loads.point]]`); the same point may appear twice.
    pub point_loads: Vec<PointLoad>,
}

impl Default for DeadLoads {
    fn default() -> Self {
        DeadLoads {
            tip_force: Vector3::zeros(),
            tip_couple: Vector3::zeros(),
            distributed_force: Vector3::zeros(),
            point_loads: Vec::new(),
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
        for p in self.point_loads.iter().filter(|p| p.s > s) {
            n += p.force;
        }
        n
    }

    /// The jump of the internal moment m(s) (global components) at the
    /// point s: m(s⁺) − m(s⁻) = −Σ_{s_k = s} C_k. The moment exerted on
    /// [0, s) by (s, L] includes every couple beyond s (as M(L) = C at the
    /// tip), so crossing a couple in the direction of s drops it, as the
    /// internal force drops a point force. Zero where no point load sits
    /// at s.
    pub fn moment_jump(&self, s: f64) -> Vector3<f64> {
        -self
            .point_loads
            .iter()
            .filter(|p| p.s == s)
            .map(|p| p.couple)
            .sum::<Vector3<f64>>()
    }

    /// Whether some point load carries a non-zero couple (the moment then
    /// jumps inside the rod).
    pub fn has_point_couples(&self) -> bool {
        self.point_loads
            .iter()
            .any(|p| p.couple != Vector3::zeros())
    }

    /// The points s_k where n(s) or m(s) jumps, sorted and without repeats (a
    /// force of zero still counts, so that the discretization does not
    /// change as a continued force passes through zero).
    pub fn jumps(&self) -> Vec<f64> {
        let mut s: Vec<f64> = self.point_loads.iter().map(|p| p.s).collect();
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
            point_loads: self
                .point_loads
                .iter()
                .map(|p| PointLoad {
                    s: p.s,
                    force: p.force * factor,
                    couple: p.couple * factor,
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
            point_loads: vec![PointLoad::force(0.5, Vector3::new(1.0, 0.0, 0.0))],
            ..Default::default()
        };
        assert_eq!(loads.internal_force(0.25, 1.0).x, 1.0);
        assert_eq!(loads.internal_force(0.5, 1.0).x, 0.0, "right limit at s_k");
        assert_eq!(loads.internal_force(0.75, 1.0).x, 0.0);
        assert_eq!(loads.jumps(), vec![0.5]);
    }

    #[test]
    fn a_point_couple_drops_the_moment_where_it_acts() {
        let loads = DeadLoads {
            point_loads: vec![PointLoad {
                s: 0.5,
                force: Vector3::zeros(),
                couple: Vector3::new(0.0, 2.0, 0.0),
            }],
            ..Default::default()
        };
        assert_eq!(loads.moment_jump(0.5), Vector3::new(0.0, -2.0, 0.0));
        assert_eq!(loads.moment_jump(0.25), Vector3::zeros());
        assert!(loads.has_point_couples());
        let scaled = loads.scaled(0.5);
        assert_eq!(scaled.point_loads[0].couple.y, 1.0);
    }
}
