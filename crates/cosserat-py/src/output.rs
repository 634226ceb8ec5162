//! `.to_hdf5(path, force=False)` of every result: claimed as the commands
//! claim their outputs (never the problem file, never a non-regular file,
//! an existing file only with `force`), then written by the library's
//! writer atomically.

use std::path::{Path, PathBuf};

use cosserat::output::target::claim;
use cosserat::output::OutputError as WriteError;
use pyo3::prelude::*;

use crate::errors::{guarded, Failure};

/// What a result keeps for writing: the effective problem text (stored in
/// the file) and the problem file it was read from, if any.
pub struct Written {
    text: String,
    input: Option<PathBuf>,
}

impl Written {
    /// The text and the input file of a result.
    pub fn new(text: String, input: Option<PathBuf>) -> Self {
        Written { text, input }
    }

    /// The effective problem text.
    pub fn text(&self) -> &str {
        &self.text
    }
}

/// Claims `path` and runs `write` on it without the GIL; a refused claim
/// or a failed write is an `OutputError`.
pub fn write_claimed(
    py: Python<'_>,
    written: &Written,
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> Result<(), WriteError> + Send,
) -> PyResult<()> {
    let inputs: Vec<&Path> = written.input.iter().map(PathBuf::as_path).collect();
    py.detach(|| {
        guarded(|| {
            let _claim = claim(path, &inputs, force).map_err(|e| Failure::Output(e.to_string()))?;
            write(path).map_err(|e| Failure::Output(e.to_string()))
        })
    })
    .map_err(PyErr::from)
}
