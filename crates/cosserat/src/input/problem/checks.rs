//! The checks of single numbers shared by the tables: finite numbers and
//! vectors, magnitudes within [`MAGNITUDE_RANGE`] (so that products of
//! three of them stay inside the floating-point range), and the meaningful
//! ranges of the tolerance-like keys.

use nalgebra::Vector3;

use super::{invalid, ProblemError};

pub(super) fn finite(field: &str, v: f64) -> Result<f64, ProblemError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be a finite number, got {v}")))
    }
}

pub(super) fn vector(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, ProblemError> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{field}[{i}]"), *x)?;
    }
    Ok(Vector3::from(v))
}

/// The magnitudes a material or load number may have: 0, or 1e-100 to
/// 1e100. Products of three such numbers (a load times a length squared
/// over a stiffness, B/h · κ²) stay inside the floating-point range
/// (1e±308); beyond it a critical load came out NaN or "none" with exit
/// code 0.
pub const MAGNITUDE_RANGE: (f64, f64) = (1e-100, 1e100);

pub(super) fn magnitude(field: &str, v: f64) -> Result<f64, ProblemError> {
    let v = finite(field, v)?;
    let a = v.abs();
    if a == 0.0 || (MAGNITUDE_RANGE.0..=MAGNITUDE_RANGE.1).contains(&a) {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!(
                "{v:e} is outside the magnitudes [{:e}, {:e}] (or 0) that keep products of the \
                 problem's numbers inside the floating-point range; change the units",
                MAGNITUDE_RANGE.0, MAGNITUDE_RANGE.1
            ),
        ))
    }
}

/// A vector of loads or curvatures: finite, each component within
/// [`MAGNITUDE_RANGE`] or zero.
pub(super) fn load_vector(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, ProblemError> {
    for (i, x) in v.iter().enumerate() {
        magnitude(&format!("{field}[{i}]"), *x)?;
    }
    Ok(Vector3::from(v))
}

/// The meaningful range of a tolerance-like key and why (docs/problem-files.md
/// lists each).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Range {
    /// Smallest value accepted.
    pub lo: f64,
    /// Largest value accepted.
    pub hi: f64,
    /// Why the range ends there and what to choose instead.
    pub why: &'static str,
}

/// Newton's tolerance on the scaled residual (`solver.tolerance`,
/// `continuation.tolerance`): the correction must then be below √τ, so
/// above 1e-6 a "converged" shape may be wrong in its third digit (at τ = 1
/// any iterate passes); below 1e-15 (≈ 5 ε) round-off alone keeps the
/// scaled residual above it.
pub(crate) const NEWTON_TOLERANCE: Range = Range {
    lo: 1e-15,
    hi: 1e-6,
    why: "the scaled residual Newton must reach; above 1e-6 a converged shape may be \
          wrong in its third digit, below 1e-15 round-off cannot reach it; e.g. 1e-10",
};

/// The integrator's relative and absolute tolerance: the shooting
/// residual, and so the shape, is only as accurate as the integration.
pub(crate) const INTEGRATION_TOLERANCE: Range = Range {
    lo: 1e-14,
    hi: 1e-6,
    why: "the shape is only as accurate as the integration; above 1e-6 fewer than six \
          digits are right, below 1e-14 DOP853's steps underflow in round-off; e.g. 1e-12",
};

/// Collocation's target for its accumulated local error estimate.
pub(crate) const COLLOCATION_TOLERANCE: Range = Range {
    lo: 1e-14,
    hi: 1e-6,
    why: "the mesh is refined until the error estimate is below it; above 1e-6 fewer than \
          six digits are right, below 1e-14 round-off in the estimate dominates; e.g. 1e-10",
};

/// A tolerance-like number within its range.
pub(crate) fn within(field: &str, v: f64, range: Range) -> Result<f64, ProblemError> {
    if v.is_finite() && (range.lo..=range.hi).contains(&v) {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!(
                "{v} is outside [{:e}, {:e}] ({})",
                range.lo, range.hi, range.why
            ),
        ))
    }
}
