//! Rust vectors as NumPy arrays: one row per sample.

use nalgebra::Vector3;
use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

/// An n × 3 array of the rows.
pub fn rows(
    py: Python<'_>,
    rows: impl ExactSizeIterator<Item = [f64; 3]>,
) -> Bound<'_, PyArray2<f64>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.flatten().collect();
    let array = Array2::from_shape_vec((n, 3), flat).expect("three values per row");
    PyArray2::from_owned_array(py, array)
}

/// An n × 3 array of vectors.
pub fn vectors<'a, 'py>(
    py: Python<'py>,
    vectors: impl ExactSizeIterator<Item = &'a Vector3<f64>>,
) -> Bound<'py, PyArray2<f64>> {
    rows(py, vectors.map(|v| [v[0], v[1], v[2]]))
}

/// An n × k array of rows of equal length `k` (`k` given for n = 0).
pub fn table<'py>(py: Python<'py>, rows: &[&[f64]], k: usize) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flat_map(|r| r.iter().copied()).collect();
    let array = Array2::from_shape_vec((rows.len(), k), flat).expect("rows of equal length");
    PyArray2::from_owned_array(py, array)
}

/// A 1-D array.
pub fn column(py: Python<'_>, values: Vec<f64>) -> Bound<'_, PyArray1<f64>> {
    PyArray1::from_vec(py, values)
}
