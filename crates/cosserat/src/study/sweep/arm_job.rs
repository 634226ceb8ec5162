//! The longest arm at one grid point (paper Sec. 3–4.2), following up to
//! two families of local optima across the grid.
//!
//! Cold (the first point of a line): the global stage of
//! [`ArmProblem::optimize`] — Sobol' samples of the box, the exact-gradient
//! polish (projected BFGS) from the best `starts` samples — plus, with two
//! families, `starts` more polishes from samples spread evenly over the
//! ranking, so that a basin other than the best one is entered. Family 0
//! is the best polished design; family 1 the best one that is a distinct
//! local optimum ([`distinct_optima`]: another loaded shape, and a valley
//! in between; paper Sec. 4.2: "two local optimum values of C for each
//! value of B̄1 and B̄3").
//!
//! Warm (the next points of the line): each family is polished from its
//! predecessor's optimum, on the predecessor's discretization (where its
//! optimum needed a finer one, the neighbour starts there instead of
//! searching the whole box again on it), and family 0 also from
//! `warm_samples` Sobol' samples; family 1 is marked `merged` when its
//! polish lands on family 0's shape. Family 0 is the better of the two at
//! each point (they swap labels where they cross).
//!
//! A family absent at the predecessor (`not_found`: the cold search's
//! spread polishes all ended on family 0) is carried as absent (`start` =
//! `carried`) instead of searched for cold again at every point. The
//! argument: a nondegenerate local maximum persists under a small change
//! of (B̄1, B̄3) (implicit function theorem on its KKT conditions), so a
//! second optimum appears along a line only in a fold, born together with
//! a saddle; the cold search at the line's first point is where the
//! second family is looked for, and a line keeps the families its first
//! point found (as it did for the wide box's map, README "Sweeps"). A
//! family that failed at the predecessor (no critical load, an evaluation
//! failure) is still searched cold (`cold_after_failure`).

use super::{Job, Record};
use crate::stability::StabilityOptions;
use crate::study::arm::{
    ArmDesign, ArmOptimum, ArmProblem, ArmScene, ReachLimit, SearchOptions, Verdict,
    REACH_TOLERANCE,
};
use crate::study::Problem;

/// Loaded shapes closer than this (root-mean-square difference of the
/// turning angle φ(s̄) over [0, 1], rad) are one local optimum: the reach
/// is flat along a ridge of nearly equal shapes whose tips differ.
pub const SAME_SHAPE: f64 = 0.1;

/// The arm job: the optimization of the point's `[arm]` table.
#[derive(Debug, Clone, Copy)]
pub struct ArmJob {
    /// Families followed (1 or 2).
    pub families: usize,
    /// Sobol' samples added to a warm polish of family 0.
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
            let s = f64::from(i) / f64::from(n - 1);
            (phi(a, s) - phi(b, s)).powi(2)
        })
        .sum();
    (sum / f64::from(n)).sqrt()
}

/// Two designs are one local optimum unless their loaded shapes differ
/// (by more than `SAME_SHAPE` = 0.1 in [`shape_distance`]) *and* a valley separates them: the reach
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
    /// The discretization the design was polished on.
    mesh: StabilityOptions,
    status: &'static str,
    /// `cold`, `warm` or `cold_after_failure`.
    start: &'static str,
    evaluations: usize,
}

impl ArmJob {
    /// The cold search: family 0 and, if asked, the best distinct optimum.
    fn cold(
        &self,
        arm: &ArmProblem,
        scene: &ArmScene,
        search: &SearchOptions,
        stop: &dyn Fn() -> bool,
    ) -> Vec<Found> {
        let mut sampled: Vec<(f64, Vec<f64>)> = (1..=search.samples)
            .take_while(|_| !stop())
            .filter_map(|i| {
                let p = arm.sample_point(i);
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
            if stop() {
                break;
            }
            let (d, used) = arm.polished(scene, start, search.iterations);
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
            mesh: arm.stability,
            start: "cold",
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
    fn warm(
        &self,
        arm: &ArmProblem,
        scene: &ArmScene,
        previous: &Record,
        f: usize,
        stop: &dyn Fn() -> bool,
    ) -> Found {
        if previous
            .labels
            .get(&format!("family_{f}/status"))
            .map(String::as_str)
            == Some("not_found")
        {
            // Absent at the predecessor: carried, not searched for again
            // (module doc).
            return Found {
                design: None,
                mesh: arm.stability,
                status: "not_found",
                start: "carried",
                evaluations: 0,
            };
        }
        // The predecessor's discretization (where its optimum needed a
        // finer one, so does its neighbour's, most likely: a line does not
        // redo the whole refined search at every point).
        // (Not where the reach has no gradient, an actuator limit: there
        // the warm polish is Nelder–Mead's, and the search's own mesh and
        // refinement are kept.)
        let mesh = if scene.max_curvature.is_some() {
            arm.stability
        } else {
            carried_mesh(previous, f, arm.stability.eigenvalues()).unwrap_or(arm.stability)
        };
        let arm = &ArmProblem {
            stability: mesh,
            ..arm.clone()
        };
        let coefficients = previous
            .numbers
            .get(&format!("family_{f}/shape_coefficients"));
        let start: Option<Vec<f64>> = coefficients
            .filter(|c| c.len() == arm.coefficients() && c.iter().all(|v| v.is_finite()))
            .map(|c| c[1..].to_vec());
        let Some(start) = start else {
            return Found {
                design: None,
                mesh,
                status: "not_found",
                start: "warm",
                evaluations: 0,
            };
        };
        // The search's own polish. Without a gradient (an actuator limit)
        // that is Nelder–Mead from the search's 5 % simplex: a 1 % one (the
        // step between neighbours) stopped 2.5e-4 short of the cold optimum
        // within its iterations where the limit changes by half between
        // points (tests/optimizer_trust.rs, the warm line).
        let (mut design, mut evaluations) = arm.polished(scene, &start, self.warm_iterations);
        if f == 0 && self.warm_samples > 0 && !stop() {
            let best_sample = (1..=self.warm_samples)
                .take_while(|_| !stop())
                .filter_map(|i| {
                    let p = arm.sample_point(i);
                    arm.design_in(scene, &p).map(|d| (d.reach, p))
                })
                .max_by(|a, b| a.0.total_cmp(&b.0));
            evaluations += self.warm_samples;
            if let Some((_, p)) = best_sample {
                let (d, used) = arm.polished(scene, &p, self.warm_iterations);
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
            mesh,
            start: "warm",
            design,
            evaluations,
        }
    }

    /// Records family `f`'s outcome: the optimum as reported (checked on
    /// finer meshes, searched again on a finer mesh where the search's does not resolve
    /// it: [`ArmProblem::resolve`]) with its discretization error.
    fn write(record: &mut Record, m: usize, f: usize, outcome: &Outcome) {
        let key = |name: &str| format!("family_{f}/{name}");
        let nan = vec![f64::NAN; m];
        let optimum = outcome.optimum.as_ref();
        let value = |g: fn(&ArmOptimum) -> f64| optimum.map_or(f64::NAN, g);
        let check = optimum.and_then(|o| o.resolution.as_ref());
        let study = |g: fn(&crate::study::arm::Resolution) -> f64| check.map_or(f64::NAN, g);
        record.set(&key("reach"), vec![value(|o| o.design.reach)]);
        record.set(&key("gamma_crit"), vec![value(|o| o.design.gamma)]);
        record.set(
            &key("shape_coefficients"),
            optimum.map_or(nan.clone(), |o| o.design.shape_coefficients.clone()),
        );
        record.set(
            &key("curvature_coefficients"),
            optimum.map_or(nan, |o| o.curvature_coefficients.clone()),
        );
        record.set(&key("reach_fine"), vec![study(|r| r.study.reach[2])]);
        record.set(
            &key("reach_error"),
            vec![study(|r| r.study.error().unwrap_or(f64::NAN))],
        );
        record.set(
            &key("reach_order"),
            vec![study(|r| r.study.order().unwrap_or(f64::NAN))],
        );
        record.set(
            &key("elements"),
            vec![study(|r| r.study.elements[0] as f64)],
        );
        record.set(
            &key("element_order"),
            vec![value(|o| o.mesh.order() as f64)],
        );
        let limit = optimum
            .and_then(|o| o.limit.as_ref())
            .and_then(ReachLimit::converged);
        record.set(
            &key("reach_limit"),
            vec![limit.map_or(f64::NAN, |(r, _)| r)],
        );
        record.set(
            &key("reach_limit_bound"),
            vec![limit.map_or(f64::NAN, |(_, e)| e)],
        );
        record.set(&key("evaluations"), vec![outcome.evaluations as f64]);
        record.label(&key("status"), outcome.status);
        record.label(&key("start"), outcome.start);
        if let Some(r) = check {
            record.label(&key("mesh"), r.verdict.name());
        }
    }
}

/// A family's reported outcome at a point.
struct Outcome {
    optimum: Option<ArmOptimum>,
    status: &'static str,
    start: &'static str,
    evaluations: usize,
}

impl Job for ArmJob {
    fn kind(&self) -> &'static str {
        "arm"
    }

    fn run(
        &self,
        index: usize,
        problem: &Problem,
        previous: Option<&Record>,
        stop: &dyn Fn() -> bool,
    ) -> Record {
        let mut record = Record::new(index);
        if problem.arm_taper.is_some() {
            // Never the prismatic search in place of the tapered one.
            record.label(
                "error",
                "arm.taper: a tapered arm runs with `cosserat optimize` only",
            );
            return record;
        }
        let (Some((arm, search, straight)), Some((scene, _))) = (&problem.arm, &problem.arm_scene)
        else {
            record.label("error", "the problem has no [arm] table");
            return record;
        };
        let mut found = match previous {
            None => self.cold(arm, scene, search, stop),
            Some(p) => {
                let warm: Vec<Found> = (0..self.families)
                    .map(|f| self.warm(arm, scene, p, f, stop))
                    .collect();
                if warm
                    .iter()
                    .all(|w| w.design.is_some() || w.start == "carried")
                {
                    warm
                } else {
                    // A family without a predecessor to start from (it
                    // failed there) or whose warm polish failed is searched
                    // cold: one failure must not end the family for the
                    // rest of the line (issue 14, item 6).
                    let cold = self.cold(arm, scene, search, stop);
                    warm.into_iter()
                        .zip(cold)
                        .map(|(w, c)| match w.design {
                            Some(_) => w,
                            None if w.start == "carried" => w,
                            None => Found {
                                evaluations: w.evaluations + c.evaluations,
                                start: "cold_after_failure",
                                ..c
                            },
                        })
                        .collect()
                }
            }
        };
        // A point that finishes after the stop is discarded
        // (`schedule::run`): its optima are not checked on finer meshes,
        // whose re-polishes do not poll the stop (from an interrupted
        // search's poor start they ran for a minute past SIGTERM).
        if stop() {
            return record;
        }
        if let [first, second] = &mut found[..] {
            if let (Some(a), Some(b)) = (&first.design, &second.design) {
                if !distinct_optima(arm, scene, a, b) {
                    second.status = "merged";
                }
            }
        }
        let mut outcomes: Vec<Outcome> = found
            .into_iter()
            .map(|f| {
                let had_design = f.design.is_some();
                let arm = ArmProblem {
                    stability: f.mesh,
                    ..arm.clone()
                };
                let optimum = f
                    .design
                    .and_then(|d| arm.complete(scene, d, 0))
                    .map(|o| arm.resolve(scene, o, search, REACH_TOLERANCE, stop));
                let evaluations = f.evaluations + optimum.as_ref().map_or(0, |o| o.evaluations);
                Outcome {
                    status: if optimum.is_some() || !had_design {
                        f.status
                    } else {
                        "evaluation_failed"
                    },
                    optimum,
                    start: f.start,
                    evaluations,
                }
            })
            .collect();
        if let [first, second] = &mut outcomes[..] {
            if let (Some(a), Some(b), "optimum") = (&first.optimum, &second.optimum, second.status)
            {
                if b.design.reach > a.design.reach {
                    // Family 0 is the better optimum at every point (the
                    // paper's panel a, "the global optimum"); the two
                    // continued optima swap labels where they cross.
                    std::mem::swap(first, second);
                }
            }
        }
        let m = arm.coefficients();
        for (f, outcome) in outcomes.iter().enumerate() {
            Self::write(&mut record, m, f, outcome);
            if let Some(o) = &outcome.optimum {
                warn_mesh(index, f, o);
            }
        }
        if *straight {
            write_straight(arm, &mut record);
        }
        record
    }
}

/// The discretization family `f`'s optimum was reported on at the
/// predecessor (its `elements` and `element_order`); None where the record
/// has none (no optimum, or a file written before the order was kept).
fn carried_mesh(previous: &Record, f: usize, eigenvalues: usize) -> Option<StabilityOptions> {
    let number = |name: &str| {
        previous
            .number(&format!("family_{f}/{name}"))
            .filter(|v| v.is_finite() && *v >= 1.0)
    };
    let (elements, order) = (number("elements")?, number("element_order")?);
    StabilityOptions::new(elements as usize, order as usize, eigenvalues).ok()
}

/// Says on stderr when a family's optimum was not resolved by the search's
/// mesh (the reported one is then the finer mesh's, or carries its error).
fn warn_mesh(index: usize, f: usize, o: &ArmOptimum) {
    let Some(r) = &o.resolution else { return };
    let Some(&(n, coarse, fine)) = r.rejected.first() else {
        if r.verdict == Verdict::Unresolved {
            eprintln!(
                "warning: point {index}, family {f}: R* = {:.6} on {} elements of order {} is \
                 not resolved ({:.6} on {}); reported with its error",
                r.study.reach[0],
                r.study.elements[0],
                o.mesh.order(),
                r.study.reach[2],
                r.study.elements[2]
            );
        }
        return;
    };
    eprintln!(
        "warning: point {index}, family {f}: R* = {coarse:.6} on {n} elements but {fine:.6} \
         on {}: {} on {} elements of order {}, R* = {:.6}",
        4 * n,
        if r.verdict == Verdict::Refined {
            "searched again"
        } else {
            "still unresolved"
        },
        r.study.elements[0],
        o.mesh.order(),
        r.study.reach[0]
    );
}

/// R0 of the intrinsically straight arm at the point's direction α
/// ([`ArmProblem::straight`]: the level family followed in the load, the
/// farthest stable equilibrium).
fn write_straight(arm: &ArmProblem, record: &mut Record) {
    let s = arm.straight();
    let v = |f: fn(&crate::study::arm::StraightArm) -> f64| s.as_ref().map_or(f64::NAN, f);
    record.set("straight/reach", vec![v(|s| s.reach)]);
    record.set("straight/gamma_crit", vec![v(|s| s.gamma)]);
    record.set("straight/clamp_angle", vec![v(|s| s.clamp_angle)]);
    record.label(
        "straight/status",
        if s.is_some() { "found" } else { "not_found" },
    );
    if let Some(s) = &s {
        record.label("straight/limit", s.limit.name());
    }
}
