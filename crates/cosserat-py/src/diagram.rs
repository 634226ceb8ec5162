//! `cosserat.continuation`: the bifurcation diagram of a problem's
//! `[continuation]` table, as `cosserat continue` computes it, with its
//! branches and special points as NumPy arrays.

use std::collections::BTreeMap;
use std::path::PathBuf;

use cosserat::continuation::{
    continuation, Branch as FollowedBranch, Diagram as Followed, Point, Progress,
    SpecialPoint as Located,
};
use cosserat::input::Problem;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::arrays::{column, rows, table};
use crate::errors::Failure;
use crate::output::{write_claimed, Written};

/// Follows the problem's family; Ctrl-C (a pending KeyboardInterrupt)
/// stops at the next point and is raised by the caller.
fn follow(problem: &Problem, interrupted: &mut Option<PyErr>) -> Result<Followed, Failure> {
    let Some((family, opts)) = &problem.continuation else {
        return Err(Failure::problem(
            "continuation",
            "the problem has no [continuation] table",
        ));
    };
    if !problem.stage_keys.is_empty() {
        return Err(Failure::problem(
            "continuation.stage",
            "chained stages ([[continuation.stage]]) are run by `cosserat continue`; \
             here continue one stage at a time",
        ));
    }
    let mut monitor = |_: Progress, _: &Followed| match crate::errors::pending_signal() {
        None => true,
        Some(e) => {
            interrupted.get_or_insert(e);
            false
        }
    };
    continuation(family, opts, &mut monitor).map_err(|e| Failure::NoResult(e.to_string()))
}

/// A bifurcation diagram: branches (each a sequence of equilibria along
/// the parameter) and the folds and branch points located on them.
#[pyclass(module = "cosserat", frozen)]
pub struct Diagram {
    followed: Followed,
    parameter_name: String,
    written: Written,
}

impl Diagram {
    /// Continues the problem read from `input` (if a file); the
    /// `KeyboardInterrupt` of a Ctrl-C is returned as the error.
    pub fn compute(py: Python<'_>, problem: &Problem, input: Option<PathBuf>) -> PyResult<Self> {
        let mut interrupted = None;
        let diagram = py.detach(|| crate::errors::guarded(|| follow(problem, &mut interrupted)));
        if let Some(e) = interrupted {
            return Err(e);
        }
        let diagram = diagram?;
        let parameter_name = problem
            .continuation
            .as_ref()
            .map_or_else(String::new, |(f, _)| f.key());
        Ok(Diagram {
            followed: diagram,
            parameter_name,
            written: Written::new(problem.text.clone(), input),
        })
    }
}

#[pymethods]
impl Diagram {
    /// The continued parameter's key (e.g. "load_scale").
    #[getter]
    fn parameter_name(&self) -> &str {
        &self.parameter_name
    }

    /// The branches, in the order they were followed.
    #[getter]
    fn branches(&self) -> Vec<Branch> {
        self.followed
            .branches
            .iter()
            .map(|b| Branch {
                followed: b.clone(),
                measure_names: self.followed.measure_names.clone(),
                eigenvalue_names: self.followed.eigenvalue_names.clone(),
            })
            .collect()
    }

    /// The located folds and branch points.
    #[getter]
    fn special_points(&self) -> Vec<SpecialPoint> {
        self.followed
            .special_points
            .iter()
            .map(|s| SpecialPoint { point: s.clone() })
            .collect()
    }

    /// The names of the eigenvalue columns ("in_plane[0]", …).
    #[getter]
    fn eigenvalue_names(&self) -> Vec<String> {
        self.followed.eigenvalue_names.clone()
    }

    /// "completed" (or "interrupted").
    #[getter]
    fn stop_reason(&self) -> &'static str {
        self.followed.stop_reason.name()
    }

    /// What the run noticed but could not settle (events not located).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.followed.warnings.clone()
    }

    /// The effective problem text (overrides applied).
    #[getter]
    fn problem(&self) -> &str {
        self.written.text()
    }

    /// Writes the diagram as `cosserat continue -o` does (readable by
    /// `cosserat plot`); an existing file is replaced only with `force=True`.
    #[pyo3(signature = (path, force = false))]
    #[allow(clippy::needless_pass_by_value)] // pyo3 hands arguments over owned
    fn to_hdf5(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<()> {
        let text = self.written.text();
        write_claimed(py, &self.written, &path, force, |p| {
            cosserat::output::write_diagram(p, text, &self.parameter_name, &self.followed, true)
        })
    }

    fn __repr__(&self) -> String {
        let points: usize = self.followed.branches.iter().map(|b| b.points.len()).sum();
        format!(
            "Diagram({} over {} branches, {points} points, {} special points, {})",
            self.parameter_name,
            self.followed.branches.len(),
            self.followed.special_points.len(),
            self.followed.stop_reason.name()
        )
    }
}

/// A quantity read off a point.
type PointValue = fn(&Point) -> f64;

/// One branch: its points' parameter, measures, eigenvalues and stability.
#[pyclass(module = "cosserat", frozen)]
pub struct Branch {
    followed: FollowedBranch,
    measure_names: Vec<String>,
    eigenvalue_names: Vec<String>,
}

impl Branch {
    fn each(&self, value: impl Fn(&Point) -> f64) -> Vec<f64> {
        self.followed.points.iter().map(value).collect()
    }
}

#[pymethods]
impl Branch {
    /// The parameter at each point, shape (n,).
    #[getter]
    fn parameter<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.each(|p| p.parameter))
    }

    /// The measures at each point by name, each (n,): the tip measures
    /// every diagram has ("tip_x", "tip_y", "tip_z", "norm", "tip_angle",
    /// as `cosserat plot --measure` names them) and the run's own
    /// (`[continuation] measures`).
    #[getter]
    fn measures<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<BTreeMap<String, Bound<'py, PyArray1<f64>>>> {
        let tip: [(&str, PointValue); 5] = [
            ("tip_x", |p| p.tip.position[0]),
            ("tip_y", |p| p.tip.position[1]),
            ("tip_z", |p| p.tip.position[2]),
            ("norm", |p| p.norm),
            ("tip_angle", |p| p.tip_angle),
        ];
        let mut measures: BTreeMap<String, _> = tip
            .into_iter()
            .map(|(name, value)| (name.to_string(), column(py, self.each(value))))
            .collect();
        for (i, name) in self.measure_names.iter().enumerate() {
            let values: Option<Vec<f64>> = self
                .followed
                .points
                .iter()
                .map(|p| p.measures.get(i).copied())
                .collect();
            let values = values
                .ok_or_else(|| Failure::Internal(format!("a point lacks the measure {name}")))?;
            measures.insert(name.clone(), column(py, values));
        }
        Ok(measures)
    }

    /// The tip position at each point, shape (n, 3).
    #[getter]
    fn tip<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let tips = self.followed.points.iter().map(|p| p.tip.position);
        rows(
            py,
            tips.map(|v| [v[0], v[1], v[2]])
                .collect::<Vec<_>>()
                .into_iter(),
        )
    }

    /// The angle (rad) between the tip and clamp tangents, shape (n,).
    #[getter]
    fn tip_angle<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.each(|p| p.tip_angle))
    }

    /// The L² norm of the curvature √∫|κ|², shape (n,).
    #[getter]
    fn norm<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.each(|p| p.norm))
    }

    /// The tracked eigenvalues, shape (n, k); columns `eigenvalue_names`.
    #[getter]
    fn eigenvalues<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let k = self.eigenvalue_names.len();
        let rows: Vec<&[f64]> = self
            .followed
            .points
            .iter()
            .map(|p| &p.eigenvalues[..])
            .collect();
        match rows.iter().find(|r| r.len() != k) {
            None => Ok(table(py, &rows, k)),
            Some(r) => Err(Failure::Internal(format!(
                "a point tracks {} eigenvalues, the diagram names {k}",
                r.len()
            ))
            .into()),
        }
    }

    /// The names of the eigenvalue columns.
    #[getter]
    fn eigenvalue_names(&self) -> Vec<String> {
        self.eigenvalue_names.clone()
    }

    /// The Morse index at each point, shape (n,).
    #[getter]
    fn morse_index<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let m = self.followed.points.iter().map(|p| p.morse_index as i64);
        PyArray1::from_vec(py, m.collect())
    }

    /// Stable (Morse index 0) at each point, shape (n,).
    #[getter]
    fn stable<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_vec(py, self.followed.points.iter().map(|p| p.stable).collect())
    }

    /// The centreline at each point: a list of (m, 3) arrays.
    #[getter]
    fn shapes<'py>(&self, py: Python<'py>) -> Vec<Bound<'py, PyArray2<f64>>> {
        self.followed
            .points
            .iter()
            .map(|p| crate::arrays::vectors(py, p.shape.iter().map(|r| &r.position)))
            .collect()
    }

    /// The special point this branch was switched from (None: the start).
    #[getter]
    fn parent(&self) -> Option<usize> {
        self.followed.parent
    }

    /// Why it ended.
    #[getter]
    fn stop_reason(&self) -> String {
        self.followed.stop_reason.to_string()
    }

    fn __len__(&self) -> usize {
        self.followed.points.len()
    }

    fn __repr__(&self) -> String {
        let p = self.each(|p| p.parameter);
        format!(
            "Branch({} points, parameter {:.6} → {:.6}, {})",
            p.len(),
            p.first().copied().unwrap_or(f64::NAN),
            p.last().copied().unwrap_or(f64::NAN),
            self.followed.stop_reason
        )
    }
}

/// A located fold or branch point.
#[pyclass(module = "cosserat", frozen)]
pub struct SpecialPoint {
    point: Located,
}

#[pymethods]
impl SpecialPoint {
    /// "fold" or "branch_point".
    #[getter]
    fn kind(&self) -> &'static str {
        self.point.kind.name()
    }

    /// The index of the branch it lies on.
    #[getter]
    fn branch(&self) -> usize {
        self.point.branch
    }

    /// The parameter where it was located.
    #[getter]
    fn parameter(&self) -> f64 {
        self.point.point.parameter
    }

    /// The tip position there, shape (3,).
    #[getter]
    fn tip<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let p = self.point.point.tip.position;
        column(py, vec![p[0], p[1], p[2]])
    }

    /// The block whose eigenvalue vanishes ("in_plane", "out_of_plane", "spatial").
    #[getter]
    fn block(&self) -> &'static str {
        self.point.block.name()
    }

    /// How it was located: "augmented", "bracketed", "interpolated" or
    /// "extrapolated".
    #[getter]
    fn location(&self) -> &'static str {
        self.point.location.name()
    }

    /// The estimated error of the parameter: the discretization's for an
    /// "augmented" location (located again on a refined discretization),
    /// the extrapolations' plus the BVP discretization's for an
    /// "extrapolated" one, the interpolants' difference (plus the
    /// discretization's where known) for an "interpolated" one, the
    /// bracket's spread for a "bracketed" one not closed, and the
    /// discretization's for a multiple branch point whose bracket closed and
    /// for a fold on a branch of symmetric copies (located again on a
    /// refined discretization); None where not estimated (a refined
    /// location that failed, and a simple branch point on a branch of
    /// symmetric copies, which the diagram's warnings say).
    #[getter]
    fn parameter_error(&self) -> Option<f64> {
        self.point.parameter_error
    }

    /// How many eigenvalues cross zero there.
    #[getter]
    fn multiplicity(&self) -> usize {
        self.point.multiplicity
    }

    /// The Morse index at the located point.
    #[getter]
    fn morse_index(&self) -> usize {
        self.point.point.morse_index
    }

    /// The bifurcating mode breaks a symmetry of the branch.
    #[getter]
    fn symmetry_breaking(&self) -> bool {
        self.point.symmetry_breaking
    }

    /// The branches started here.
    #[getter]
    fn children(&self) -> Vec<usize> {
        self.point.children.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "SpecialPoint({} on branch {} at {:.10}, {} block, located {})",
            self.kind(),
            self.point.branch,
            self.point.point.parameter,
            self.block(),
            self.location()
        )
    }
}
