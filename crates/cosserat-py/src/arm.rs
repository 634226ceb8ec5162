//! `cosserat.optimize`: the longest arm of a problem's `[arm]` table
//! (Sipos & Várkonyi 2019), as `cosserat optimize` computes it: the
//! search, the straight arm R̂0 when asked, the reach map when asked.

use std::cell::RefCell;
use std::path::PathBuf;

use cosserat::continuation::RunState;
use cosserat::input::Problem;
use cosserat::output::ArmStudy;
use cosserat::study::arm::{
    ArmOptimum, ArmProblem, ArmScene, ArmWeight, ClosestStraight, ReachMap, SearchOptions,
    SearchProgress, StraightArm,
};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::arrays::{column, rows};
use crate::errors::{guarded, Failure};
use crate::output::{write_claimed, Written};

/// Everything a completed `cosserat optimize` study holds.
struct Study {
    optimum: ArmOptimum,
    progress: SearchProgress,
    straight: Option<StraightArm>,
    map: Option<ReachMap>,
    closest: Option<ClosestStraight>,
    least: Option<ClosestStraight>,
}

/// A stop test that is true once Ctrl-C is pending, keeping its
/// `KeyboardInterrupt` to raise.
struct Interruption(RefCell<Option<PyErr>>);

impl Interruption {
    fn requested(&self) -> bool {
        if self.0.borrow().is_some() {
            return true;
        }
        match crate::errors::pending_signal() {
            None => false,
            Some(e) => {
                *self.0.borrow_mut() = Some(e);
                true
            }
        }
    }
}

fn arm_of(
    problem: &Problem,
) -> Result<(&ArmProblem, &SearchOptions, bool, &ArmScene, usize), Failure> {
    if problem.arm_taper.is_some() {
        return Err(Failure::problem(
            "arm.taper",
            "a tapered arm runs with `cosserat optimize` only (not yet in Python)",
        ));
    }
    if problem.arm_spatial.is_some() {
        // The planar search would run silently in its place.
        return Err(Failure::problem(
            "arm.spatial",
            "spatial arms run from the command line only (`cosserat optimize`)",
        ));
    }
    match (&problem.arm, &problem.arm_scene) {
        (Some((arm, search, straight)), Some((scene, samples))) => {
            Ok((arm, search, *straight, scene, *samples))
        }
        _ => Err(Failure::problem("arm", "the problem has no [arm] table")),
    }
}

/// The search and what follows it, stopped by `stop`.
fn study(problem: &Problem, stop: &dyn Fn() -> bool) -> Result<Option<Study>, Failure> {
    let (arm, search, straight, scene, samples) = arm_of(problem)?;
    let (optimum, progress, interrupted) =
        arm.search(scene, search, SearchProgress::default(), stop, &mut |_| {});
    let Some(optimum) = optimum else {
        let limit = scene.max_curvature.map_or(String::new(), |k| {
            format!(" that the actuator limit arm.max_curvature = {k} can hold")
        });
        return Err(Failure::NoResult(format!(
            "arm.bounds: no design with a finite critical load{limit} was found in the bounds"
        )));
    };
    if interrupted {
        return Ok(None);
    }
    let straight = (straight && scene.weight == ArmWeight::Weightless)
        .then(|| arm.straight_until(stop))
        .flatten();
    let (map, closest, least) = if samples > 0 {
        let map = arm.reach_map(scene, samples, stop);
        let closest = map.closest_straight(arm, scene);
        let (least, _) = arm.least_curvature(scene, &map, search.starts, search.iterations, stop);
        (Some(map), closest, least)
    } else {
        (None, None, None)
    };
    Ok(Some(Study {
        optimum,
        progress,
        straight,
        map,
        closest,
        least,
    }))
}

/// The optimal design of a soft robotic arm and its study.
#[pyclass(module = "cosserat", frozen)]
pub struct Arm {
    study: Study,
    written: Written,
}

impl Arm {
    /// Optimizes the arm of the problem read from `input` (if a file); the
    /// `KeyboardInterrupt` of a Ctrl-C is returned as the error.
    pub fn compute(py: Python<'_>, problem: &Problem, input: Option<PathBuf>) -> PyResult<Self> {
        let (found, interrupted) = py.detach(|| {
            let stop = Interruption(RefCell::new(None));
            let found = guarded(|| study(problem, &|| stop.requested()));
            (found, stop.0.into_inner())
        });
        if let Some(e) = interrupted {
            return Err(e);
        }
        let Some(study) = found? else {
            return Err(Failure::Internal("the search stopped without a signal".into()).into());
        };
        Ok(Arm {
            study,
            written: Written::new(problem.text.clone(), input),
        })
    }

    fn optimum(&self) -> &ArmOptimum {
        &self.study.optimum
    }
}

#[pymethods]
impl Arm {
    /// R̂*: the reach of the design, √γ |r̄(1)| (units of √(B2/F)).
    #[getter]
    fn reach(&self) -> f64 {
        self.optimum().design.reach
    }

    /// The design load γ = F L²/B2 (the critical load unless the actuators
    /// limit it).
    #[getter]
    fn gamma(&self) -> f64 {
        self.optimum().design.gamma
    }

    /// The critical load factor of the loaded shape, γ_crit.
    #[getter]
    fn gamma_crit(&self) -> f64 {
        self.optimum().critical_load
    }

    /// c1..cM of the loaded shape φ(s̄) = Σ c_i s̄^(i−1).
    #[getter]
    fn design<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.optimum().design.shape_coefficients.clone())
    }

    /// b1..bM: the Taylor fit of the intrinsic curvature κ̄⁰2(s̄).
    #[getter]
    fn curvature_coefficients<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.optimum().curvature_coefficients.clone())
    }

    /// The loaded shape (x̂, ŷ, ẑ) = √γ (x̄, ȳ, z̄), shape (n, 3).
    #[getter]
    fn loaded_shape<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rows(py, self.optimum().loaded_shape.iter().copied())
    }

    /// The unloaded (intrinsic) shape, same scaling, shape (n, 3).
    #[getter]
    fn unloaded_shape<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rows(py, self.optimum().unloaded_shape.iter().copied())
    }

    /// κ̄⁰2 at the shape points, shape (n,).
    #[getter]
    fn intrinsic_curvature<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.optimum().intrinsic_curvature.clone())
    }

    /// Designs evaluated.
    #[getter]
    fn evaluations(&self) -> usize {
        self.optimum().evaluations
    }

    /// R̂* on the search mesh and on 2× and 4× its elements.
    #[getter]
    fn mesh_reach(&self) -> Option<Vec<f64>> {
        self.optimum()
            .resolution
            .as_ref()
            .map(|r| r.study.reach.to_vec())
    }

    /// The Richardson estimate of R̂*'s discretization error (None:
    /// undecided, the differences do not converge geometrically).
    #[getter]
    fn reach_error(&self) -> Option<f64> {
        self.optimum()
            .resolution
            .as_ref()
            .and_then(|r| r.study.error())
    }

    /// "resolved", "refined" or "unresolved": whether the search mesh
    /// resolves R̂* to `cosserat.REACH_TOLERANCE`.
    #[getter]
    fn resolution(&self) -> Option<&'static str> {
        self.optimum().resolution.as_ref().map(|r| r.verdict.name())
    }

    /// R̂0 of the best straight arm (when `arm.straight` asks for it).
    #[getter]
    fn straight_reach(&self) -> Option<f64> {
        self.study.straight.as_ref().map(|s| s.reach)
    }

    /// The effective problem text (overrides applied).
    #[getter]
    fn problem(&self) -> &str {
        self.written.text()
    }

    /// Writes the study as `cosserat optimize -o` does; an existing file
    /// is replaced only with `force=True`.
    #[pyo3(signature = (path, force = false))]
    #[allow(clippy::needless_pass_by_value)] // pyo3 hands arguments over owned
    fn to_hdf5(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<()> {
        let s = &self.study;
        let text = self.written.text();
        write_claimed(py, &self.written, &path, force, |p| {
            let study = ArmStudy {
                optimum: &s.optimum,
                straight: s.straight.as_ref(),
                map: s.map.as_ref(),
                closest: s.closest.as_ref(),
                least_curvature: s.least.as_ref(),
                progress: Some(&s.progress),
                stop_reason: RunState::Completed,
            };
            cosserat::output::write_arm_study(p, text, &study, true)
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Arm(reach {:.6}, gamma_crit {:.6}, {} coefficients, {} evaluations)",
            self.reach(),
            self.gamma_crit(),
            self.optimum().design.shape_coefficients.len(),
            self.evaluations()
        )
    }
}
