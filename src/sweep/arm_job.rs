//! The longest arm at one grid point (paper Sec. 3–4.2), following up to
//! two families of local optima across the grid.
//!
//! Cold (the first point of a line): the global stage of
//! [`ArmProblem::optimize`] — Halton samples of the box, Nelder–Mead from
//! the best `starts` samples — plus, with two families, `starts` more
//! polishes from samples spread evenly over the ranking, so that a basin
//! other than the best one is entered. Family 0 is the best polished
//! design; family 1 the best one that is a distinct local optimum
//! ([`distinct_optima`]: another loaded shape, and a valley in between;
//! paper Sec. 4.2: "two local optimum values of C for each value of B̄1
//! and B̄3").
//!
//! Warm (the next points of the line): each family is polished from its
//! predecessor's optimum with a small simplex (1 % of the bounds), and
//! family 0 also from `warm_samples` Halton samples; family 1 is marked
//! `merged` when its polish lands on family 0's shape. Family 0 is the
//! better of the two at each point (they swap labels where they cross).

use super::{Job, Record};
use crate::io::Problem;
use crate::optimize::{ArmDesign, ArmProblem, ArmScene, SearchOptions};

/// Loaded shapes closer than this (root-mean-square difference of the
/// turning angle φ(s̄) over [0, 1], rad) are one local optimum: the reach
/// is flat along a ridge of nearly equal shapes whose tips differ.
pub const SAME_SHAPE: f64 = 0.1;

/// Simplex size of a warm polish (fraction of each bound's width).
const WARM_STEP: f64 = 0.01;

/// Simplex size of a cold polish (the search's own).
const COLD_STEP: f64 = 0.05;

/// The arm job: the optimization of the point's `[arm]` table.
#[derive(Debug, Clone, Copy)]
pub struct ArmJob {
    /// Families followed (1 or 2).
    pub families: usize,
    /// Halton samples added to a warm polish of family 0.
    pub warm_samples: usize,
    /// Nelder–Mead iterations of a warm polish.
    pub warm_iterations: u64,
}

/// Root-mean-square difference of the turning angles φ(s̄) = Σ c_i s̄^{i−1}
/// of two loaded shapes (c1..cM each) on 41 points of [0, 1].
pub fn shape_distance(a: &[f64], b: &[f64]) -> f64 {
    let phi = |c: &[f64], s: f64| c.iter().rev().fold(0.0, |acc, ci| acc * s + ci);
    let n = 41;
    let sum: f64 = (0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            (phi(a, s) - phi(b, s)).powi(2)
        })
        .sum();
    (sum / n as f64).sqrt()
}

/// Two designs are one local optimum unless their loaded shapes differ
/// (by more than [`SAME_SHAPE`]) *and* a valley separates them: the reach
/// dips below the lower of the two (by more than 0.1 %) somewhere on the
/// straight path between their coefficients. The reach is flat along a
/// ridge of different shapes, so a shape difference alone would count
/// unfinished polishes on the ridge as optima of their own.
pub fn distinct_optima(arm: &ArmProblem, scene: &ArmScene, a: &ArmDesign, b: &ArmDesign) -> bool {
    if shape_distance(&a.shape_coefficients, &b.shape_coefficients) <= SAME_SHAPE {
        return false;
    }
    let (ca, cb) = (&a.shape_coefficients[1..], &b.shape_coefficients[1..]);
    let floor = a.reach.min(b.reach) * (1.0 - 1e-3);
    [0.25, 0.5, 0.75].iter().any(|t| {
        let p: Vec<f64> = ca.iter().zip(cb).map(|(x, y)| x + t * (y - x)).collect();
        arm.design_in(scene, &p).is_none_or(|d| d.reach < floor)
    })
}

/// A family's outcome at a point.
struct Found {
    design: Option<ArmDesign>,
    status: &'static str,
    evaluations: usize,
}

impl ArmJob {
    /// The cold search: family 0 and, if asked, the best distinct optimum.
    fn cold(&self, arm: &ArmProblem, scene: &ArmScene, search: &SearchOptions) -> Vec<Found> {
        let mut sampled: Vec<(f64, Vec<f64>)> = (1..=search.samples)
            .filter_map(|i| {
                let p = arm.halton_point(i);
                arm.design_in(scene, &p).map(|d| (d.reach, p))
            })
            .collect();
        sampled.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut evaluations = search.samples;
        let mut starts: Vec<&Vec<f64>> = sampled.iter().take(search.starts).map(|s| &s.1).collect();
        if self.families > 1 && sampled.len() > search.starts {
            let stride = (sampled.len() / search.starts.max(1)).max(1);
            starts.extend(sampled.iter().step_by(stride).map(|s| &s.1));
        }
        let mut polished: Vec<ArmDesign> = vec![];
        for start in starts {
            let (d, used) = arm.polish_with_step(scene, start, search.iterations, COLD_STEP);
            evaluations += used;
            polished.extend(d);
        }
        polished.sort_by(|a, b| b.reach.total_cmp(&a.reach));
        let best = polished.first().cloned();
        let second = best.as_ref().and_then(|b| {
            polished
                .iter()
                .find(|d| distinct_optima(arm, scene, d, b))
                .cloned()
        });
        let found = |design: Option<ArmDesign>, missing: &'static str| Found {
            status: if design.is_some() { "optimum" } else { missing },
            design,
            evaluations,
        };
        let mut out = vec![found(best, "no_critical_load")];
        if self.families > 1 {
            out.push(found(second, "not_found"));
        }
        out
    }

    /// A warm polish from the predecessor's optimum of family `f`.
    fn warm(&self, arm: &ArmProblem, scene: &ArmScene, previous: &Record, f: usize) -> Found {
        let coefficients = previous
            .numbers
            .get(&format!("family_{f}/shape_coefficients"));
        let start: Option<Vec<f64>> = coefficients
            .filter(|c| c.len() == arm.coefficients() && c.iter().all(|v| v.is_finite()))
            .map(|c| c[1..].to_vec());
        let Some(start) = start else {
            return Found {
                design: None,
                status: "not_found",
                evaluations: 0,
            };
        };
        let (mut design, mut evaluations) =
            arm.polish_with_step(scene, &start, self.warm_iterations, WARM_STEP);
        if f == 0 && self.warm_samples > 0 {
            let best_sample = (1..=self.warm_samples)
                .filter_map(|i| {
                    let p = arm.halton_point(i);
                    arm.design_in(scene, &p).map(|d| (d.reach, p))
                })
                .max_by(|a, b| a.0.total_cmp(&b.0));
            evaluations += self.warm_samples;
            if let Some((_, p)) = best_sample {
                let (d, used) = arm.polish_with_step(scene, &p, self.warm_iterations, COLD_STEP);
                evaluations += used;
                if d.as_ref().map(|d| d.reach) > design.as_ref().map(|d| d.reach) {
                    design = d;
                }
            }
        }
        Found {
            status: if design.is_some() {
                "optimum"
            } else {
                "no_critical_load"
            },
            design,
            evaluations,
        }
    }

    /// Records family `f`'s outcome.
    fn write(
        &self,
        arm: &ArmProblem,
        scene: &ArmScene,
        record: &mut Record,
        f: usize,
        found: Found,
    ) {
        let m = arm.coefficients();
        let key = |name: &str| format!("family_{f}/{name}");
        let nan = vec![f64::NAN; m];
        let optimum = found
            .design
            .and_then(|d| arm.complete(scene, d, found.evaluations));
        let (reach, gamma, c, b) = match &optimum {
            Some(o) => (
                o.design.reach,
                o.design.gamma,
                o.design.shape_coefficients.clone(),
                o.curvature_coefficients.clone(),
            ),
            None => (f64::NAN, f64::NAN, nan.clone(), nan),
        };
        record.set(&key("reach"), vec![reach]);
        record.set(&key("gamma_crit"), vec![gamma]);
        record.set(&key("shape_coefficients"), c);
        record.set(&key("curvature_coefficients"), b);
        record.set(&key("evaluations"), vec![found.evaluations as f64]);
        record.label(&key("status"), found.status);
    }
}

impl Job for ArmJob {
    fn kind(&self) -> &'static str {
        "arm"
    }

    fn run(&self, index: usize, problem: &Problem, previous: Option<&Record>) -> Record {
        let mut record = Record::new(index);
        let Some((arm, search, straight)) = &problem.arm else {
            record.label("error", "the problem has no [arm] table");
            return record;
        };
        // The arm's loads and actuator limit (the paper's tip load unless
        // the file says otherwise).
        let scene = problem.arm_scene.map(|(s, _)| s).unwrap_or_default();
        let mut found = match previous {
            None => self.cold(arm, &scene, search),
            Some(p) => (0..self.families)
                .map(|f| self.warm(arm, &scene, p, f))
                .collect(),
        };
        if let [first, second] = &mut found[..] {
            if let (Some(a), Some(b)) = (&first.design, &second.design) {
                if !distinct_optima(arm, &scene, a, b) {
                    second.status = "merged";
                } else if b.reach > a.reach {
                    // Family 0 is the better optimum at every point (the
                    // paper's panel a, "the global optimum"); the two
                    // continued optima swap labels where they cross.
                    std::mem::swap(first, second);
                }
            }
        }
        for (f, outcome) in found.into_iter().enumerate() {
            self.write(arm, &scene, &mut record, f, outcome);
        }
        if *straight {
            write_straight(arm, &mut record);
        }
        record
    }
}

/// R0 of the intrinsically straight arm at the point's direction α
/// ([`ArmProblem::straight`]: the level family followed in the load, the
/// farthest stable equilibrium).
fn write_straight(arm: &ArmProblem, record: &mut Record) {
    let s = arm.straight();
    let v = |f: fn(&crate::optimize::StraightArm) -> f64| s.as_ref().map_or(f64::NAN, f);
    record.set("straight/reach", vec![v(|s| s.reach)]);
    record.set("straight/gamma_crit", vec![v(|s| s.gamma)]);
    record.set("straight/clamp_angle", vec![v(|s| s.clamp_angle)]);
    record.label(
        "straight/status",
        if s.is_some() { "found" } else { "not_found" },
    );
}
