//! Per-point measures of a branch, named by the user: any component of
//! the position, tangent, internal force, internal moment or curvature at
//! any point s = σL of the rod (σ ∈ [0, 1]; the force and moment at σ = 0
//! are the clamp's reaction, at σ = 1 a support's), the planar turning
//! angle φ(L) − φ(0) unfolded through any number of turns, the stored
//! energy and the total potential energy. Each is computed from the point's own equilibrium (one
//! integration for all the measures of a point), stored with the point and
//! written to the diagram, so that `cosserat plot --measure NAME` draws it.
//!
//! Grammar: `position[i]@σ`, `tangent[i]@σ`, `force[i]@σ`, `moment[i]@σ`
//! (global components, i = 0, 1, 2), `curvature[i]@σ` (body components),
//! `turning` (∫₀ᴸ κ2 ds, planar scenes), `stored_energy` (∫₀ᴸ W(s, κ) ds,
//! unshearable rods), `total_potential_energy` (the stored energy minus
//! the work of the dead loads,
//! Π = ∫₀ᴸ W(s, κ) ds − P·r(L) − ∫₀ᴸ f·r(s) ds, unshearable rods; the
//! potential of the dead loads as [`crate::stability`] defines it,
//! −∫ n·r' ds with n = P + ∫ₛᴸ f, integrated by parts with r measured from
//! the global origin; a dead tip couple is only accepted where the tip's
//! rotation is held, where it does no work and is left out). Along a
//! branch in a load factor λ (P = λP₀, f = λf₀) the envelope theorem gives
//! dΠ/dλ = −P₀·r(L) − ∫ f₀·r ds. The integrals use 3-point Gauss–Legendre on 64 equal
//! intervals (exact for the polynomial part, sixth order on a smooth
//! integrand).

use crate::equations::RodSample;
use crate::model::DeadLoads;
use crate::numerics::quadrature::gauss_legendre;

/// A quantity sampled at one point of the rod.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// r(s), global.
    Position,
    /// d3(s), global.
    Tangent,
    /// n(s), global.
    Force,
    /// m(s), global.
    Moment,
    /// κ(s), body components.
    Curvature,
}

impl Quantity {
    fn name(self) -> &'static str {
        match self {
            Quantity::Position => "position",
            Quantity::Tangent => "tangent",
            Quantity::Force => "force",
            Quantity::Moment => "moment",
            Quantity::Curvature => "curvature",
        }
    }

    fn value(self, sample: &RodSample, i: usize) -> f64 {
        match self {
            Quantity::Position => sample.position[i],
            Quantity::Tangent => sample.directors[2][i],
            Quantity::Force => sample.force[i],
            Quantity::Moment => sample.moment[i],
            Quantity::Curvature => sample.curvature[i],
        }
    }
}

/// One named measure of a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measure {
    /// Component `component` of `quantity` at s = `fraction`·L.
    At {
        /// What is sampled.
        quantity: Quantity,
        /// The component, 0 to 2.
        component: usize,
        /// s/L in [0, 1].
        fraction: f64,
    },
    /// φ(L) − φ(0) = ∫₀ᴸ κ2 ds of a planar rod, unfolded.
    Turning,
    /// ∫₀ᴸ W(s, κ) ds.
    StoredEnergy,
    /// ∫₀ᴸ W(s, κ) ds − P·r(L) − ∫₀ᴸ f·r ds: the stored energy minus the
    /// work of the dead loads (module doc).
    TotalPotentialEnergy,
}

/// Intervals of the quadrature of the integral measures.
const QUADRATURE_INTERVALS: usize = 64;

impl Measure {
    /// The measure named `name` (grammar in the module doc), or why not.
    pub fn parse(name: &str) -> Result<Measure, String> {
        let name = name.trim();
        match name {
            "turning" => return Ok(Measure::Turning),
            "stored_energy" => return Ok(Measure::StoredEnergy),
            "total_potential_energy" => return Ok(Measure::TotalPotentialEnergy),
            _ => {}
        }
        let bad = || {
            format!(
                "`{name}` is not a measure: expected QUANTITY[i]@σ (QUANTITY one of position, \
                 tangent, force, moment, curvature; i = 0, 1, 2; σ = s/L in [0, 1]), turning, \
                 stored_energy or total_potential_energy"
            )
        };
        let (head, at) = name.split_once('@').ok_or_else(bad)?;
        let (quantity, index) = head.split_once('[').ok_or_else(bad)?;
        let component: usize = index
            .strip_suffix(']')
            .and_then(|i| i.trim().parse().ok())
            .filter(|i| *i < 3)
            .ok_or_else(bad)?;
        let fraction: f64 = at
            .trim()
            .parse()
            .ok()
            .filter(|f: &f64| (0.0..=1.0).contains(f))
            .ok_or_else(bad)?;
        let quantity = [
            Quantity::Position,
            Quantity::Tangent,
            Quantity::Force,
            Quantity::Moment,
            Quantity::Curvature,
        ]
        .into_iter()
        .find(|q| q.name() == quantity.trim())
        .ok_or_else(bad)?;
        Ok(Measure::At {
            quantity,
            component,
            fraction,
        })
    }

    /// The canonical name (what the diagram file and `plot` call it).
    pub fn name(&self) -> String {
        match self {
            Measure::At {
                quantity,
                component,
                fraction,
            } => format!("{}[{component}]@{fraction}", quantity.name()),
            Measure::Turning => "turning".into(),
            Measure::StoredEnergy => "stored_energy".into(),
            Measure::TotalPotentialEnergy => "total_potential_energy".into(),
        }
    }

    fn integral(&self) -> bool {
        matches!(
            self,
            Measure::Turning | Measure::StoredEnergy | Measure::TotalPotentialEnergy
        )
    }
}

/// The points s (sorted, on a rod of `length`) at which `measures` need
/// the solution, and the quadrature weights of the integral ones.
pub(super) struct Plan {
    /// Sorted sample points.
    pub(super) points: Vec<f64>,
    /// Where each point measure's s lies in `points`.
    at: Vec<Option<usize>>,
    /// Quadrature nodes' indices in `points` and weights.
    quadrature: Vec<(usize, f64)>,
    /// The tip's index in `points` when a measure needs r(L).
    tip: Option<usize>,
}

impl Plan {
    pub(super) fn new(measures: &[Measure], length: f64) -> Plan {
        let mut points: Vec<f64> = measures
            .iter()
            .filter_map(|m| match m {
                Measure::At { fraction, .. } => Some(fraction * length),
                _ => None,
            })
            .collect();
        let mut nodes = vec![];
        if measures.iter().any(Measure::integral) {
            let h = length / QUADRATURE_INTERVALS as f64;
            for k in 0..QUADRATURE_INTERVALS {
                let a = h * k as f64;
                let (x, w) = gauss_legendre(3, a, a + h).expect("3 Gauss points are tabulated");
                nodes.extend(x.into_iter().zip(w));
            }
            points.extend(nodes.iter().map(|(x, _)| *x));
        }
        let needs_tip = measures.contains(&Measure::TotalPotentialEnergy);
        if needs_tip {
            points.push(length);
        }
        points.sort_by(f64::total_cmp);
        points.dedup();
        let index = |s: f64| points.partition_point(|p| *p < s);
        let at = measures
            .iter()
            .map(|m| match m {
                Measure::At { fraction, .. } => Some(index(fraction * length)),
                _ => None,
            })
            .collect();
        let quadrature = nodes.iter().map(|(x, w)| (index(*x), *w)).collect();
        let tip = needs_tip.then(|| index(length));
        Plan {
            points,
            at,
            quadrature,
            tip,
        }
    }

    /// The measures' values from the samples at `self.points`; `density`
    /// is W(s, κ), `loads` the rod's dead loads.
    pub(super) fn values(
        &self,
        measures: &[Measure],
        samples: &[RodSample],
        density: &dyn Fn(f64, &nalgebra::Vector3<f64>) -> f64,
        loads: &DeadLoads,
    ) -> Vec<f64> {
        let integral = |f: &dyn Fn(&RodSample) -> f64| -> f64 {
            self.quadrature
                .iter()
                .map(|(i, w)| w * f(&samples[*i]))
                .sum()
        };
        measures
            .iter()
            .zip(&self.at)
            .map(|(m, at)| match (m, at) {
                (
                    Measure::At {
                        quantity,
                        component,
                        ..
                    },
                    Some(i),
                ) => quantity.value(&samples[*i], *component),
                (Measure::Turning, _) => integral(&|r| r.curvature[1]),
                (Measure::StoredEnergy, _) => integral(&|r| density(r.s, &r.curvature)),
                (Measure::TotalPotentialEnergy, _) => {
                    let tip = &samples[self.tip.expect("the plan samples the tip")];
                    integral(&|r| {
                        density(r.s, &r.curvature) - loads.distributed_force.dot(&r.position)
                    }) - loads.tip_force.dot(&tip.position)
                }
                (Measure::At { .. }, None) => unreachable!("point measures have a sample"),
            })
            .collect()
    }
}

impl super::Run<'_> {
    /// The run's measures at (x, p): none without measures (no work), else
    /// one integration through every needed point.
    pub(super) fn measures(&self, x: &[f64], p: f64) -> Result<Vec<f64>, super::PointError> {
        let measures = &self.opts.measures;
        if measures.is_empty() {
            return Ok(vec![]);
        }
        let rod = self.family.rod_at(p)?;
        let plan = Plan::new(measures, rod.length());
        let samples = self.family.samples(x, p, &plan.points)?;
        let energy = rod.energy();
        Ok(plan.values(
            measures,
            &samples,
            &|s, k| energy.density(s, k),
            rod.loads(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for name in [
            "force[2]@0",
            "position[0]@0.5",
            "curvature[1]@1",
            "turning",
            "stored_energy",
            "total_potential_energy",
        ] {
            assert_eq!(Measure::parse(name).unwrap().name(), name);
        }
        for bad in [
            "force[3]@0",
            "force[2]@1.5",
            "force@0",
            "speed[0]@0",
            "energy",
        ] {
            assert!(Measure::parse(bad).is_err(), "{bad}");
        }
    }

    /// The quadrature integrates a cubic exactly: ∫₀² s³ ds = 4.
    #[test]
    fn quadrature_weights_sum_to_the_integral() {
        let plan = Plan::new(&[Measure::Turning], 2.0);
        let total: f64 = plan
            .quadrature
            .iter()
            .map(|(i, w)| w * plan.points[*i].powi(3))
            .sum();
        assert!((total - 4.0).abs() < 1e-13, "{total}");
    }
}
