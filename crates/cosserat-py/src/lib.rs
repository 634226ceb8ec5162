//! The `cosserat` Python package: the library's solve, stability,
//! continuation and arm optimization called from Python, on the problems
//! the `cosserat` command reads (a problem file, or a dict with its
//! tables) with the command's `--set` overrides as keyword arguments.
//! Results keep the library's data and hand it out as NumPy arrays; each
//! writes the command's HDF5 file (`.to_hdf5`). Failures are Python
//! exceptions ([`errors`]), panics included. The numerics are all the
//! library's: this crate converts arguments and results.
//!
//! Modules: [`problem_source`] (the `problem` argument and overrides),
//! [`equilibrium`], [`stability_report`], [`diagram`], [`arm`] (one result type
//! each), [`output`] (`.to_hdf5`), [`arrays`], [`errors`].

pub mod arm;
pub mod arrays;
pub mod diagram;
pub mod equilibrium;
pub mod errors;
pub mod output;
pub mod problem_source;
pub mod stability_report;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use cosserat::input::Problem;
use errors::guarded;
use problem_source::ProblemRequest;

/// Reads the problem (without the GIL); also the input file to protect.
fn read(
    py: Python<'_>,
    problem: &Bound<'_, PyAny>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Problem, Option<std::path::PathBuf>)> {
    let request = ProblemRequest::from_python(problem, overrides)?;
    let read = py.detach(|| guarded(|| request.read()))?;
    Ok((read, request.file().map(std::path::Path::to_path_buf)))
}

/// solve(problem, **overrides) -> Equilibrium
///
/// The problem's equilibrium, as `cosserat solve` finds it, with its
/// stability verdict. `problem` is a problem file's path or a dict with
/// its tables; each override is a `--set` key and its value, e.g.
/// `solve("problems/cantilever_tip_load.toml", **{"loads.tip_force": [1.0, 0.0, 0.0]})`.
/// Raises ProblemError (a bad problem, `.field` the key) or SolveError.
#[pyfunction]
#[pyo3(signature = (problem, **overrides))]
fn solve(
    py: Python<'_>,
    problem: &Bound<'_, PyAny>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<equilibrium::Equilibrium> {
    let (problem, input) = read(py, problem, overrides)?;
    let (eq, verdict) = py.detach(|| guarded(|| equilibrium::run(&problem)))?;
    if verdict != "stable" {
        let warning = format!(
            "this equilibrium is {verdict}: loading the rod would not settle here; follow the \
             load with cosserat.continuation or try solver.method = \"multiple-shooting\""
        );
        let category = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
        PyErr::warn(py, &category, &std::ffi::CString::new(warning)?, 1)?;
    }
    Ok(equilibrium::Equilibrium::new(
        eq,
        verdict,
        problem.text,
        input,
    ))
}

/// stability(problem, **overrides) -> Stability
///
/// The stability of the problem's equilibrium (spectra and Morse index,
/// decided on refined meshes) or, for a fixed `[shape]`, its critical
/// load, as `cosserat stability` computes them.
#[pyfunction]
#[pyo3(signature = (problem, **overrides))]
fn stability(
    py: Python<'_>,
    problem: &Bound<'_, PyAny>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<stability_report::Stability> {
    let (problem, input) = read(py, problem, overrides)?;
    Ok(py.detach(|| guarded(|| stability_report::Stability::compute(&problem, input)))?)
}

/// continuation(problem, **overrides) -> Diagram
///
/// The bifurcation diagram of the problem's `[continuation]` table, as
/// `cosserat continue` follows it. Ctrl-C stops it (KeyboardInterrupt).
#[pyfunction]
#[pyo3(signature = (problem, **overrides))]
fn continuation(
    py: Python<'_>,
    problem: &Bound<'_, PyAny>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<diagram::Diagram> {
    let (problem, input) = read(py, problem, overrides)?;
    diagram::Diagram::compute(py, &problem, input)
}

/// optimize(problem, **overrides) -> Arm
///
/// The longest arm of the problem's `[arm]` table, as `cosserat optimize`
/// finds it (with R̂0 and the reach map when the table asks for them).
/// Ctrl-C stops it (KeyboardInterrupt).
#[pyfunction]
#[pyo3(signature = (problem, **overrides))]
fn optimize(
    py: Python<'_>,
    problem: &Bound<'_, PyAny>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<arm::Arm> {
    let (problem, input) = read(py, problem, overrides)?;
    arm::Arm::compute(py, &problem, input)
}

/// The extension module `cosserat._cosserat`.
#[pymodule]
#[pyo3(name = "_cosserat")]
fn extension(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(continuation, m)?)?;
    m.add_function(wrap_pyfunction!(optimize, m)?)?;
    m.add_class::<equilibrium::Equilibrium>()?;
    m.add_class::<stability_report::Stability>()?;
    m.add_class::<diagram::Diagram>()?;
    m.add_class::<diagram::Branch>()?;
    m.add_class::<diagram::SpecialPoint>()?;
    m.add_class::<arm::Arm>()?;
    m.add("REACH_TOLERANCE", cosserat::study::arm::REACH_TOLERANCE)?;
    errors::register(m)
}
