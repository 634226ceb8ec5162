//! The `problem` argument and the `**overrides` of every function: a
//! problem file's path, or a dict with the problem file's structure
//! (written as TOML text and read by the same reader, so that its errors
//! name the same keys), and keyword overrides that are the command's
//! `--set KEY=VALUE`, with the value written as a TOML value.

use std::path::PathBuf;

use cosserat::input::Problem;
use cosserat::model::EnergyCatalog;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::errors::Failure;

/// A problem as given: a file, or the text of a dict.
pub enum ProblemSource {
    /// A problem file.
    File(PathBuf),
    /// TOML text made from a dict.
    Text(String),
}

/// What a function reads a problem from: the source and the `--set`
/// assignments of its overrides.
pub struct ProblemRequest {
    source: ProblemSource,
    set: Vec<String>,
}

impl ProblemRequest {
    /// Reads the Python arguments (with the GIL); a dict or an override
    /// that is no TOML value is a `ProblemError` naming its key.
    pub fn from_python(
        problem: &Bound<'_, PyAny>,
        overrides: Option<&Bound<'_, PyDict>>,
    ) -> Result<ProblemRequest, Failure> {
        let source = if let Ok(dict) = problem.cast::<PyDict>() {
            let table = table_of(dict, "")?;
            let text = toml::to_string(&table)
                .map_err(|e| Failure::problem("problem", format!("not a TOML document: {e}")))?;
            ProblemSource::Text(text)
        } else {
            let path: PathBuf = problem.extract().map_err(|_| Failure::Problem {
                field: None,
                message: format!(
                    "problem: a problem file's path (str or os.PathLike) or a dict with its \
                     tables, not a {}",
                    type_name(problem)
                ),
            })?;
            ProblemSource::File(path)
        };
        let mut set = Vec::new();
        for (key, value) in overrides.into_iter().flat_map(PyDictMethods::iter) {
            let key: String = key.extract().map_err(|_| Failure::Problem {
                field: None,
                message: "an override's key must be a str such as \"loads.tip_force[0]\"".into(),
            })?;
            let value = toml_value(&value, &key)?;
            set.push(format!("{key}={value}"));
        }
        Ok(ProblemRequest { source, set })
    }

    /// The problem file, when given as one (an input no output may replace).
    pub fn file(&self) -> Option<&std::path::Path> {
        match &self.source {
            ProblemSource::File(p) => Some(p),
            ProblemSource::Text(_) => None,
        }
    }

    /// The checked problem, read with the standard energies (no GIL needed).
    pub fn read(&self) -> Result<Problem, Failure> {
        let catalog = EnergyCatalog::standard();
        let read = match &self.source {
            ProblemSource::File(path) => Problem::from_path_in(path, &self.set, &catalog),
            ProblemSource::Text(text) => Problem::from_str_in(text, &self.set, &catalog),
        };
        read.map_err(Failure::from)
    }
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "?".into(), |n| n.to_string())
}

fn joined(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// A dict as a TOML table; `at` is its dotted key (for errors).
fn table_of(dict: &Bound<'_, PyDict>, at: &str) -> Result<toml::Table, Failure> {
    let mut table = toml::Table::new();
    for (key, value) in dict.iter() {
        let key: String = key.extract().map_err(|_| {
            Failure::problem(
                if at.is_empty() { "problem" } else { at },
                format!("a table's keys are str, not {}", type_name(&key)),
            )
        })?;
        let field = joined(at, &key);
        table.insert(key, toml_value(&value, &field)?);
    }
    Ok(table)
}

/// A Python value as a TOML value: bool, int, float, str, list or tuple,
/// dict, or anything with `tolist()` (NumPy arrays and scalars).
fn toml_value(obj: &Bound<'_, PyAny>, field: &str) -> Result<toml::Value, Failure> {
    let wrong = || {
        Failure::problem(
            field,
            format!(
                "expected a TOML value (bool, int, float, str, list, dict or a NumPy array), \
                 not a {}",
                type_name(obj)
            ),
        )
    };
    if obj.is_instance_of::<PyBool>() {
        return obj
            .extract::<bool>()
            .map(toml::Value::Boolean)
            .map_err(|_| wrong());
    }
    if obj.is_instance_of::<PyInt>() {
        return obj
            .extract::<i64>()
            .map(toml::Value::Integer)
            .map_err(|_| Failure::problem(field, "an integer beyond the 64-bit range"));
    }
    if obj.is_instance_of::<PyFloat>() {
        return obj
            .extract::<f64>()
            .map(toml::Value::Float)
            .map_err(|_| wrong());
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(toml::Value::String(s.to_string()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return table_of(d, field).map(toml::Value::Table);
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let items = obj.try_iter().map_err(|_| wrong())?;
        let mut array = Vec::new();
        for (i, item) in items.enumerate() {
            let item = item.map_err(|_| wrong())?;
            array.push(toml_value(&item, &format!("{field}[{i}]"))?);
        }
        return Ok(toml::Value::Array(array));
    }
    if obj.hasattr("tolist").unwrap_or(false) {
        let plain = obj.call_method0("tolist").map_err(|_| wrong())?;
        if !plain.is(obj) {
            return toml_value(&plain, field);
        }
    }
    Err(wrong())
}
