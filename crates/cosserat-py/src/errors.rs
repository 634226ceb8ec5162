//! The exceptions Python sees, and the one way a failure crosses the FFI
//! boundary: as a [`Failure`] turned into one of them. A Rust panic is
//! caught ([`guarded`]) and raised as `CosseratError`, never left to
//! unwind into the interpreter.

use std::panic::{catch_unwind, AssertUnwindSafe};

use cosserat::input::ProblemError as ReadError;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    cosserat,
    CosseratError,
    PyException,
    "Any failure of the cosserat package (an internal error raises it directly)."
);
create_exception!(
    cosserat,
    ProblemError,
    CosseratError,
    "The problem (file, dict or override) is not valid, as `cosserat` exits 2: `.field` is \
     the dotted key at fault (e.g. `energy.stiffness[0]`; None when the TOML does not \
     parse or the file cannot be read), `.message` says why."
);
create_exception!(
    cosserat,
    SolveError,
    CosseratError,
    "The problem is valid but gave no result (no equilibrium, an undecided stability, no \
     start of continuation, no feasible arm), as `cosserat` exits 3."
);
create_exception!(
    cosserat,
    OutputError,
    CosseratError,
    "A result could not be written (an existing file without force=True, a directory, an \
     input file, an unwritable place), as `cosserat` exits 1 or 2."
);

/// Why a call gave no result, before it becomes a Python exception.
#[derive(Debug)]
pub enum Failure {
    /// The problem is not valid; `field` names the key when known.
    Problem {
        /// The dotted key at fault.
        field: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// A valid problem without a result.
    NoResult(String),
    /// A result not written.
    Output(String),
    /// A panic inside the library: a bug, reported as one.
    Internal(String),
}

impl Failure {
    /// A problem error naming its key.
    pub fn problem(field: impl Into<String>, message: impl Into<String>) -> Failure {
        Failure::Problem {
            field: Some(field.into()),
            message: message.into(),
        }
    }
}

impl From<ReadError> for Failure {
    fn from(e: ReadError) -> Failure {
        match e {
            ReadError::Invalid { field, message } => Failure::Problem {
                field: Some(field),
                message,
            },
            ReadError::Override {
                assignment,
                message,
            } => {
                let key = assignment.split_once('=').map_or(&*assignment, |(k, _)| k);
                Failure::Problem {
                    field: Some(key.trim().to_string()),
                    message: format!("cannot set {assignment}: {message}"),
                }
            }
            other => Failure::Problem {
                field: None,
                message: other.to_string(),
            },
        }
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> PyErr {
        match f {
            Failure::Problem { field, message } => Python::attach(|py| {
                let shown = match &field {
                    Some(k) => format!("{k}: {message}"),
                    None => message.clone(),
                };
                let err = ProblemError::new_err(shown);
                let value = err.value(py);
                // Setting attributes on a fresh exception instance cannot fail.
                let _ = value.setattr("field", field);
                let _ = value.setattr("message", message);
                err
            }),
            Failure::NoResult(m) => SolveError::new_err(m),
            Failure::Output(m) => OutputError::new_err(m),
            Failure::Internal(m) => CosseratError::new_err(format!(
                "internal error (a bug in cosserat, please report it): {m}"
            )),
        }
    }
}

/// Runs `work`, turning a panic into [`Failure::Internal`]: nothing
/// unwinds across the FFI boundary, and the interpreter goes on.
pub fn guarded<T>(work: impl FnOnce() -> Result<T, Failure>) -> Result<T, Failure> {
    catch_unwind(AssertUnwindSafe(work)).unwrap_or_else(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(ToString::to_string)
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into());
        Err(Failure::Internal(message))
    })
}

/// The exception of a signal Python has received but not yet handled
/// (Ctrl-C: `KeyboardInterrupt`), for the long runs to stop at their next
/// point; callable without the GIL.
#[allow(clippy::redundant_closure_for_method_calls)] // the closure fixes the lifetime
pub fn pending_signal() -> Option<PyErr> {
    Python::attach(|py| py.check_signals()).err()
}

/// Registers the exception classes in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("CosseratError", py.get_type::<CosseratError>())?;
    m.add("ProblemError", py.get_type::<ProblemError>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    m.add("OutputError", py.get_type::<OutputError>())?;
    Ok(())
}
