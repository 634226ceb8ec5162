//! The `[arm]` table: the longest-arm optimization of a problem file
//! (paper Sec. 3). The rod is non-dimensional: B̄1 = B1/B2 and B̄3 = B3/B2
//! come from `energy.stiffness`.

use serde::{Deserialize, Serialize};

use super::mesh::MeshKeys;
use super::problem::{invalid, ProblemError};
use crate::model::Rod;
use crate::study::arm::taper::Taper;
use crate::study::arm::{ArmProblem, ArmScene, ArmWeight, SearchOptions, SpatialArm};

/// `[arm]`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ArmSection {
    /// Reach direction (degrees above the horizontal).
    #[serde(default)]
    pub alpha: f64,
    /// M, the number of Taylor coefficients of φ(s̄).
    pub coefficients: usize,
    /// Bounds of c2..cM, M − 1 pairs.
    #[serde(deserialize_with = "super::strict::vec")]
    pub bounds: Vec<[f64; 2]>,
    /// Halton samples of the global stage.
    #[serde(default = "default_samples")]
    pub samples: usize,
    /// Nelder–Mead polishes.
    #[serde(default = "default_starts")]
    pub starts: usize,
    /// Iterations per polish.
    #[serde(default = "default_iterations")]
    pub iterations: u64,
    /// Finite elements of the second variation (default:
    /// [`crate::stability::StabilityOptions::default`], as in every table).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    /// Their Lagrange order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
    /// Also compute R̂0 of the intrinsically straight arm.
    #[serde(default = "default_true")]
    pub straight: bool,
    /// Actuator limit on |κ⁰| in units of √(F/B2) (of (q/B2)^{1/3} for the
    /// weight alone); absent: unlimited (paper Sec. 5, a constraint).
    #[serde(default)]
    pub max_curvature: Option<f64>,
    /// Halton samples of the reach map (the Fig. 5 data set); 0: none.
    #[serde(default)]
    pub map_samples: usize,
    /// Spatial loaded shapes (issue 20): κ̄2 = φ' from `bounds`, κ̄1 and
    /// κ̄3 from `bend_bounds` and `twist_bounds`, the roll about the chord
    /// from `roll_bounds`; γ_crit of the full 3-D second variation.
    #[serde(default)]
    pub spatial: bool,
    /// Bounds of the Taylor coefficients of κ̄1(s̄) (spatial; none: κ̄1 = 0).
    #[serde(default, deserialize_with = "super::strict::vec")]
    pub bend_bounds: Vec<[f64; 2]>,
    /// Bounds of the Taylor coefficients of κ̄3(s̄) (spatial; none: κ̄3 = 0).
    #[serde(default, deserialize_with = "super::strict::vec")]
    pub twist_bounds: Vec<[f64; 2]>,
    /// Bounds of the roll ψ (degrees) about the chord (spatial; absent: ψ = 0).
    #[serde(default)]
    pub roll_bounds: Option<[f64; 2]>,
    /// Directions α (degrees) at which `optimize` also compares the planar
    /// and spatial optima (spatial; empty: none).
    #[serde(default)]
    pub directions: Vec<f64>,
    /// A non-prismatic arm: the section profile optimized with the shape
    /// (`study::arm::taper`); absent: the prismatic arm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub taper: Option<TaperKeys>,
}

/// `[arm] taper = { knots = K, min_section = A_min }`: the section A(s̄),
/// piecewise linear through K uniform knots, of unit volume ∫A ds̄ = 1
/// (the prismatic arm's), A ≥ A_min, every stiffness B_i A².
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TaperKeys {
    /// K, the knots of the section (2 ≤ K ≤ elements + 1).
    pub knots: usize,
    /// A_min in units of the prismatic section, in (0, 1).
    pub min_section: f64,
}

fn default_samples() -> usize {
    400
}
fn default_starts() -> usize {
    4
}
fn default_iterations() -> u64 {
    400
}
fn default_true() -> bool {
    true
}

/// Both loads point down (e1) or are absent, with no tip couple.
fn downward(rod: &Rod) -> Result<(f64, f64), ProblemError> {
    let l = &rod.loads();
    let down = |v: &nalgebra::Vector3<f64>| v[1] == 0.0 && v[2] == 0.0 && v[0] >= 0.0;
    if !l.point_loads.is_empty() {
        return Err(invalid(
            "loads.point",
            "the arm takes a tip force and its weight only, no [[loads.point]]",
        ));
    }
    if !(down(&l.tip_force) && down(&l.distributed_force) && l.tip_couple.norm() == 0.0) {
        return Err(invalid(
            "loads",
            "the arm takes a downward tip force [F, 0, 0] and/or its weight as a downward \
             distributed_force [q, 0, 0], no couple",
        ));
    }
    Ok((l.tip_force[0], l.distributed_force[0]))
}

/// The smallest |cos α| of a downward reach direction (sin α < 0) that a
/// mesh of `elements` resolves: [`reach_direction`].
pub fn min_downward_cosine(elements: usize) -> f64 {
    8.0 / elements as f64
}

/// Checks the reach direction α (degrees above the horizontal, the tip's
/// elevation seen from the clamp).
///
/// Every α in [−180°, 180°] names a direction: α in [−90°, 90°] reaches
/// to the side the clamp's tangent points to, α beyond ±90° to the other
/// side (the mirror image of 180° − α, resp. −180° − α, with the clamp
/// angle free). The reach is finite everywhere but straight down: at
/// α = −90° the arm hangs, in tension, stable under any load, so its
/// reach is unbounded (the search reported R* ≈ 1e10, a number of the
/// mesh). Near it the reach is finite but grows like 1/|cos α|: measured
/// R* |cos α| = 3.97, 3.42, 2.48, 1.51 at α = −60°, −80°, −88°, −89.9°
/// (B̄1 = 4, B̄3 = 1.27, M = 3), so R* ≤ 4/|cos α| in units of √(B2/F).
/// The critical load γ ≥ R*² of such an arm bends it in a boundary layer
/// of length 1/√γ (in units of L), which the mesh resolves only when it
/// spans two elements: 4/|cos α| ≤ elements/2, i.e.
/// |cos α| ≥ 8/elements. Downward directions closer to vertical are
/// refused: α ≥ −85.4° (and ≤ −94.6°) for 100 elements.
pub fn reach_direction(alpha: f64, elements: usize) -> Result<f64, ProblemError> {
    if !alpha.is_finite() || alpha.abs() > 180.0 {
        return Err(invalid(
            "arm.alpha",
            format!(
                "{alpha} is outside [−180, 180] degrees (the tip's elevation above the \
                 horizontal; beyond ±90° the arm reaches to the other side)"
            ),
        ));
    }
    let (sin, cos) = alpha.to_radians().sin_cos();
    let min = min_downward_cosine(elements);
    if sin < 0.0 && cos.abs() < min {
        let limit = 90.0 - min.asin().to_degrees();
        return Err(invalid(
            "arm.alpha",
            format!(
                "{alpha}° is within {:.1}° of straight down: an arm hanging straight down is \
                 stable under any load, so its reach is unbounded, and near it the reach grows \
                 like 4/|cos α| (in units of √(B2/F)), beyond what arm.elements = {elements} \
                 resolves (|cos α| ≥ 8/elements). Use α ≥ −{limit:.1}° (or ≤ −{:.1}°), or \
                 raise arm.elements",
                90.0 - limit,
                180.0 - limit,
            ),
        ));
    }
    Ok(alpha)
}

impl ArmSection {
    /// The section's design space of a tapered arm (`arm.taper`), checked
    /// against the scene and mesh: None for a prismatic arm. A tapered arm
    /// is weightless under a tip load, without actuator limit or reach
    /// map, on elements of order ≥ 2 with at least one element per knot
    /// interval: a section resolved as finely as linear elements lets the
    /// optimizer exploit the discretization (Keller's strongest column came
    /// out 1.76 times the uniform one on linear elements with a knot at
    /// every node, against the exact 4/3).
    pub fn taper(&self, rod: &Rod, arm: &ArmProblem) -> Result<Option<Taper>, ProblemError> {
        let Some(keys) = self.taper else {
            return Ok(None);
        };
        let taper = Taper::new(keys.knots, keys.min_section)
            .map_err(|e| invalid("arm.taper", e.to_string()))?;
        if self.scene(rod)?.weight != ArmWeight::Weightless || self.max_curvature.is_some() {
            return Err(invalid(
                "arm.taper",
                "a tapered arm takes a tip load alone (no weight, no arm.max_curvature)",
            ));
        }
        if self.map_samples > 0 {
            return Err(invalid(
                "arm.map_samples",
                "a tapered arm has no reach map; use 0",
            ));
        }
        let mesh = &arm.stability;
        if mesh.order() < 2 {
            return Err(invalid(
                "arm.order",
                "a tapered arm needs elements of order 2 or 3 (linear elements let the section \
                 optimizer exploit the discretization)",
            ));
        }
        if keys.knots > mesh.elements() + 1 {
            return Err(invalid(
                "arm.taper.knots",
                format!(
                    "{} knots need at least {} elements (one per knot interval), got {}",
                    keys.knots,
                    keys.knots - 1,
                    mesh.elements()
                ),
            ));
        }
        Ok(Some(taper))
    }

    /// The arm's loads (from `[loads]`: a tip force, the weight as a
    /// distributed force, or both in the ratio w = qL/F) and actuator limit.
    pub fn scene(&self, rod: &Rod) -> Result<ArmScene, ProblemError> {
        let (tip, weight) = downward(rod)?;
        let ratio = weight * rod.length() / tip;
        let weight = match (tip > 0.0, weight > 0.0) {
            (true, false) => ArmWeight::Weightless,
            (true, true) if ratio.is_finite() => ArmWeight::WithTipLoad(ratio),
            (false, true) => ArmWeight::Alone,
            _ => {
                return Err(invalid(
                    "loads",
                    "the arm needs a finite downward tip force or distributed force",
                ))
            }
        };
        if let Some(k) = self.max_curvature {
            if !(k.is_finite() && k > 0.0) {
                return Err(invalid(
                    "arm.max_curvature",
                    format!("must be finite and positive, got {k}"),
                ));
            }
        }
        Ok(ArmScene {
            weight,
            max_curvature: self.max_curvature,
        })
    }

    /// The arm problem of `rod` (constant stiffness) and the search options.
    pub fn build(&self, rod: &Rod) -> Result<(ArmProblem, SearchOptions, bool), ProblemError> {
        let h = rod.energy().stiffness(0.0, &nalgebra::Vector3::zeros());
        let constant = rod.energy().is_quadratic()
            && [0.5, 1.0].iter().all(|s| {
                rod.energy()
                    .stiffness(s * rod.length(), &nalgebra::Vector3::zeros())
                    == h
            });
        if !constant {
            return Err(invalid(
                "energy",
                "the arm needs the linear energy with constant stiffness",
            ));
        }
        if self.coefficients < 1 || self.bounds.len() + 1 != self.coefficients {
            return Err(invalid(
                "arm.bounds",
                format!(
                    "needs coefficients − 1 = {} pairs, got {}",
                    self.coefficients.saturating_sub(1),
                    self.bounds.len()
                ),
            ));
        }
        for (i, [lo, hi]) in self.bounds.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(invalid(
                    format!("arm.bounds[{i}]"),
                    format!("need finite lo < hi, got [{lo}, {hi}]"),
                ));
            }
        }
        // The arm's critical load is the lowest eigenvalue of the pencil.
        let stability = MeshKeys {
            table: "arm",
            elements: self.elements,
            order: self.order,
            eigenvalues: Some(1),
            min_elements: 2,
        }
        .build()?;
        if self.samples < 1 {
            return Err(invalid(
                "arm.samples",
                "must be at least 1 (the Halton samples of the global stage; e.g. 400)",
            ));
        }
        if self.starts < 1 || self.iterations < 1 {
            // starts = 0 skipped every polish and reported the best raw
            // sample as the optimum.
            return Err(invalid(
                if self.starts < 1 {
                    "arm.starts"
                } else {
                    "arm.iterations"
                },
                "must be at least 1 (Nelder–Mead polishes and their iterations; e.g. 4 and 400)",
            ));
        }
        reach_direction(self.alpha, stability.elements())?;
        let b2 = h[(1, 1)];
        Ok((
            ArmProblem {
                b1: h[(0, 0)] / b2,
                b3: h[(2, 2)] / b2,
                alpha: self.alpha.to_radians(),
                bounds: self.bounds.iter().map(|[a, b]| (*a, *b)).collect(),
                stability,
            },
            SearchOptions {
                samples: self.samples,
                starts: self.starts,
                iterations: self.iterations,
            },
            self.straight,
        ))
    }

    /// The spatial arm of `[arm] spatial = true` (None without it), built
    /// on the planar problem `planar`. The spatial keys without
    /// `spatial = true`, and the planar-only keys with it (the actuator
    /// limit, the reach map), are refused by name.
    pub fn spatial_arm(
        &self,
        planar: &ArmProblem,
        scene: &ArmScene,
    ) -> Result<Option<SpatialArm>, ProblemError> {
        if !self.spatial {
            let given = [
                ("arm.bend_bounds", !self.bend_bounds.is_empty()),
                ("arm.twist_bounds", !self.twist_bounds.is_empty()),
                ("arm.roll_bounds", self.roll_bounds.is_some()),
                ("arm.directions", !self.directions.is_empty()),
            ];
            if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
                return Err(invalid(
                    *key,
                    "is a key of spatial arms: set arm.spatial = true",
                ));
            }
            return Ok(None);
        }
        if scene.max_curvature.is_some() {
            return Err(invalid(
                "arm.max_curvature",
                "the actuator limit is implemented for planar arms only (remove it or \
                 arm.spatial)",
            ));
        }
        if self.map_samples > 0 {
            return Err(invalid(
                "arm.map_samples",
                "the reach map is of planar arms (c2, c3); use 0 with arm.spatial",
            ));
        }
        let pairs = |key: &str, b: &[[f64; 2]]| -> Result<Vec<(f64, f64)>, ProblemError> {
            b.iter()
                .enumerate()
                .map(|(i, [lo, hi])| {
                    if lo.is_finite() && hi.is_finite() && lo < hi {
                        Ok((*lo, *hi))
                    } else {
                        Err(invalid(
                            format!("{key}[{i}]"),
                            format!("need finite lo < hi, got [{lo}, {hi}]"),
                        ))
                    }
                })
                .collect()
        };
        let roll = match self.roll_bounds {
            Some(b) => Some(pairs("arm.roll_bounds", &[b])?[0]),
            None => None,
        };
        if let Some((lo, hi)) = roll {
            if lo < -360.0 || hi > 360.0 {
                return Err(invalid(
                    "arm.roll_bounds",
                    format!("the roll is an angle in degrees within [−360, 360], got [{lo}, {hi}]"),
                ));
            }
        }
        let directions = self
            .directions
            .iter()
            .enumerate()
            .map(|(i, a)| {
                reach_direction(*a, planar.stability.elements())
                    .map(f64::to_radians)
                    .map_err(|e| invalid(format!("arm.directions[{i}]"), e.to_string()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Some(SpatialArm {
            directions,
            planar: planar.clone(),
            bend_bounds: pairs("arm.bend_bounds", &self.bend_bounds)?,
            twist_bounds: pairs("arm.twist_bounds", &self.twist_bounds)?,
            roll_bounds: roll.map(|(a, b)| (a.to_radians(), b.to_radians())),
        }))
    }
}
