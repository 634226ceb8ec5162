//! `cosserat.solve`: one equilibrium, as the `solve` command computes it,
//! with its samples as NumPy arrays and its stability verdict.

use std::path::PathBuf;

use cosserat::bvp::{solve, Equilibrium as Solved, SolveError as BvpError};
use cosserat::input::Problem;
use cosserat::stability::{decide, Verdict};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::arrays::{column, vectors};
use crate::errors::Failure;
use crate::output::{write_claimed, Written};

/// A solve failure as the command classifies it: options or model the
/// solver cannot run are a problem error, the rest no result; each with
/// what to try next.
pub fn solve_failure(e: &BvpError) -> Failure {
    let hint = match e {
        BvpError::Options(_) | BvpError::Model(_) => {
            return Failure::Problem {
                field: None,
                message: e.to_string(),
            }
        }
        BvpError::NoConvergence { .. } | BvpError::RampStalled { .. } => {
            "try solver.strategy = \"ramp\", solver.method = \"multiple-shooting\" or \
             \"collocation\", or a guess solver.initial_curvature"
        }
        BvpError::Sampling(_) => "raise solver.max_steps or loosen solver.integration_tolerance",
        BvpError::Collocation { .. } => {
            "raise solver.max_intervals or loosen solver.collocation_tolerance"
        }
        BvpError::ShearStrain { .. } => {
            "the energy cannot carry the force there (no shear-extension strain with \
             W_ν = N): check its shear and extension terms, or lower the loads"
        }
    };
    Failure::NoResult(format!("{e}; what to do: {hint}"))
}

/// Solves the problem's equilibrium and decides its stability, as
/// `cosserat solve` does; a fixed-shape scene has nothing to solve.
pub fn run(problem: &Problem) -> Result<(Solved, String), Failure> {
    if problem.shape.is_some() {
        return Err(Failure::problem(
            "shape",
            "a fixed-shape scene has no fixed intrinsic curvature to solve for; use \
             cosserat.stability",
        ));
    }
    let eq =
        solve(&problem.rod, &problem.model, &problem.options).map_err(|e| solve_failure(&e))?;
    let tolerance = problem.options.newton.tolerance;
    if eq.residual.is_nan() || eq.residual > tolerance {
        return Err(Failure::NoResult(format!(
            "residual {:.3e} exceeds the tolerance {tolerance:.1e}",
            eq.residual
        )));
    }
    let verdict = match decide(&problem.rod, &eq, &problem.options, &problem.stability) {
        Ok(d) => match d.verdict {
            Verdict::Stable => "stable".to_string(),
            Verdict::Unstable { morse_index } => format!("unstable (Morse index {morse_index})"),
            Verdict::Undecided { reason } => format!("undecided: {reason}"),
        },
        Err(e) => format!("undecided: {e}"),
    };
    Ok((eq, verdict))
}

/// An equilibrium: the rod's state at the output points (one row per
/// arc length), how it was found, and its stability verdict.
#[pyclass(module = "cosserat", frozen)]
pub struct Equilibrium {
    eq: Solved,
    verdict: String,
    written: Written,
}

impl Equilibrium {
    /// The result of [`run`] on a problem read from `input` (if a file).
    pub fn new(eq: Solved, verdict: String, text: String, input: Option<PathBuf>) -> Self {
        Equilibrium {
            eq,
            verdict,
            written: Written::new(text, input),
        }
    }

    /// The solved equilibrium.
    pub fn solved(&self) -> &Solved {
        &self.eq
    }
}

#[pymethods]
impl Equilibrium {
    /// Arc lengths s of the samples (m), shape (n,).
    #[getter]
    fn s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.eq.samples.iter().map(|x| x.s).collect())
    }

    /// Centreline positions r(s), global, shape (n, 3).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, self.eq.samples.iter().map(|x| &x.position))
    }

    /// Director d1(s), global components, shape (n, 3).
    #[getter]
    fn d1<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, self.eq.samples.iter().map(|x| &x.directors[0]))
    }

    /// Director d2(s), global components, shape (n, 3).
    #[getter]
    fn d2<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, self.eq.samples.iter().map(|x| &x.directors[1]))
    }

    /// Director d3(s) (the tangent of an unshearable rod), global, (n, 3).
    #[getter]
    fn d3<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, self.eq.samples.iter().map(|x| &x.directors[2]))
    }

    /// Curvature κ(s), body components (1/m), shape (n, 3).
    #[getter]
    fn curvature<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, self.eq.samples.iter().map(|x| &x.curvature))
    }

    /// Internal moment M = ∂W/∂κ, body components (N·m), shape (n, 3).
    #[getter]
    fn moment<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, self.eq.samples.iter().map(|x| &x.moment))
    }

    /// Internal force n(s), global components (N), shape (n, 3).
    #[getter]
    fn force<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, self.eq.samples.iter().map(|x| &x.force))
    }

    /// The tip position r(L), shape (3,).
    #[getter]
    fn tip<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let p = self.eq.tip().position;
        column(py, vec![p[0], p[1], p[2]])
    }

    /// The solver method used ("shooting", "multiple-shooting", "collocation").
    #[getter]
    fn method(&self) -> &'static str {
        self.eq.method.name()
    }

    /// The model level used ("planar", "kirchhoff", …).
    #[getter]
    fn model(&self) -> &'static str {
        self.eq.model.level.name()
    }

    /// The final scaled residual (max-norm).
    #[getter]
    fn residual(&self) -> f64 {
        self.eq.residual
    }

    /// Newton iterations of the final solve.
    #[getter]
    fn iterations(&self) -> usize {
        self.eq.iterations
    }

    /// Load-ramp steps (0 when the direct solve converged).
    #[getter]
    fn load_steps(&self) -> usize {
        self.eq.load_steps
    }

    /// The largest |d_i·d_j − δ_ij| over the samples.
    #[getter]
    fn director_drift(&self) -> f64 {
        self.eq.director_drift
    }

    /// The stability verdict, decided on refined meshes: "stable",
    /// "unstable (Morse index k)" — an equilibrium loading would not
    /// reach — or "undecided: why".
    #[getter]
    fn verdict(&self) -> &str {
        &self.verdict
    }

    /// The effective problem text (overrides applied), as stored in files.
    #[getter]
    fn problem(&self) -> &str {
        self.written.text()
    }

    /// Writes the equilibrium as `cosserat solve -o` does (docs/hdf5-schema.md);
    /// an existing file is replaced only with `force=True`.
    #[pyo3(signature = (path, force = false))]
    #[allow(clippy::needless_pass_by_value)] // pyo3 hands arguments over owned
    fn to_hdf5(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<()> {
        let text = self.written.text();
        write_claimed(py, &self.written, &path, force, |p| {
            cosserat::output::write_equilibrium(p, &self.eq, text, true)
        })
    }

    fn __repr__(&self) -> String {
        let t = self.eq.tip().position;
        format!(
            "Equilibrium({} samples, tip [{:.6}, {:.6}, {:.6}], method {}, residual {:.1e}, {})",
            self.eq.samples.len(),
            t[0],
            t[1],
            t[2],
            self.eq.method.name(),
            self.eq.residual,
            self.verdict
        )
    }
}
