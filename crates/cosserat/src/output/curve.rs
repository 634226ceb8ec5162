//! Curves of singular points (two-parameter continuation) as HDF5 files.
//!
//! Layout: `/curve/parameters` (m×2: p₁, p₂), `unknowns` (m×n), `tangent`
//! (m×(n+2) or m×(n+3) with the branch point's ψ), `null_vector` (m×n),
//! `singularity` (m: |g|), `parameter_error` (m×2: the estimated
//! discretization errors of p₁ at the point's p₂ and of p₂ at its p₁, NaN
//! where unknown), `cusps` (the index of the point before each cusp),
//! `cusp_parameters` (c×2: the located cusps), `cusp_parameter_error`
//! (c×2), `warnings` (why an error is unknown); root attributes `problem` (the problem text), `parameter_names`
//! (the two keys, comma separated), `kind` (`fold` or `branch_point`),
//! `ends` (why each end stopped, `;` separated).

use std::path::Path;

use super::hdf5_output::{set_generator, write_atomically, OutputError};
use crate::continuation::{SingularCurve, SpecialKind};

fn rows(
    curve: &SingularCurve,
    f: impl Fn(&crate::continuation::CurvePoint) -> Vec<f64>,
) -> (usize, Vec<f64>) {
    let width = curve.points.first().map_or(0, |p| f(p).len());
    (width, curve.points.iter().flat_map(f).collect())
}

/// Writes the curve atomically (a temporary file renamed into place).
pub fn write_curve(
    path: &Path,
    problem: &str,
    kind: SpecialKind,
    curve: &SingularCurve,
    force: bool,
) -> Result<(), OutputError> {
    write_atomically(path, force, |root| {
        root.attrs.set_text("problem", problem);
        root.attrs
            .set_text("parameter_names", &curve.keys.join(","));
        root.attrs.set_text("kind", kind.name());
        root.attrs.set_text("ends", &curve.ends.join(";"));
        set_generator(root);
        let g = root.create_group("curve");
        let m = curve.points.len();
        let (_, p) = rows(curve, |c| c.parameters.to_vec());
        g.floats("parameters", &[m, 2], &p)?;
        let (n, x) = rows(curve, |c| c.unknowns.clone());
        g.floats("unknowns", &[m, n], &x)?;
        let (k, t) = rows(curve, |c| c.tangent.clone());
        g.floats("tangent", &[m, k], &t)?;
        let (nv, v) = rows(curve, |c| c.null_vector.clone());
        g.floats("null_vector", &[m, nv], &v)?;
        let s: Vec<f64> = curve.points.iter().map(|c| c.singularity).collect();
        g.floats("singularity", &[m], &s)?;
        let unknown = [f64::NAN; 2];
        let (_, e) = rows(curve, |c| c.parameter_error.unwrap_or(unknown).to_vec());
        g.floats("parameter_error", &[m, 2], &e)?;
        let ce: Vec<f64> = curve
            .cusps
            .iter()
            .flat_map(|c| c.parameter_error.unwrap_or(unknown))
            .collect();
        g.floats("cusp_parameter_error", &[curve.cusps.len(), 2], &ce)?;
        g.texts("warnings", &curve.warnings)?;
        let after: Vec<u64> = curve.cusps.iter().map(|c| c.after as u64).collect();
        g.counts("cusps", &after)?;
        let at: Vec<f64> = curve
            .cusps
            .iter()
            .flat_map(|c| c.point.parameters)
            .collect();
        g.floats("cusp_parameters", &[curve.cusps.len(), 2], &at)
    })
}
