//! Longest-arm results as HDF5: `/optimum/reach`, `/optimum/gamma_crit`,
//! `/optimum/shape_coefficients`, `/optimum/curvature_coefficients`,
//! `/optimum/loaded_shape` (n×3), `/optimum/unloaded_shape` (n×3),
//! `/optimum/intrinsic_curvature` (n), `/straight/reach`, `/straight/gamma_crit`,
//! `/straight/clamp_angle`, `/straight/loaded_shape`; the problem text as the
//! root attribute `problem`, and `stop_reason` (`completed` or
//! `interrupted`: then /optimum is the best design found so far).

use std::path::Path;

use super::hdf5_output::{array, string_attr, write_atomically, OutputError};
use crate::optimize::{ArmOptimum, StraightArm};

fn scalar(g: &hdf5::Group, name: &str, v: f64) -> hdf5::Result<()> {
    g.new_dataset::<f64>().create(name)?.write_scalar(&v)
}

fn points(g: &hdf5::Group, name: &str, v: &[[f64; 3]]) -> hdf5::Result<()> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    g.new_dataset::<f64>()
        .shape([v.len(), 3])
        .create(name)?
        .write_raw(&flat)
}

/// Writes the optimum (and the straight arm, if computed) atomically.
pub fn write_arm(
    path: &Path,
    problem: &str,
    optimum: &ArmOptimum,
    straight: Option<&StraightArm>,
    stop_reason: &str,
    force: bool,
) -> Result<(), OutputError> {
    write_atomically(path, force, |file| {
        string_attr(file, "problem", problem)?;
        string_attr(file, "stop_reason", stop_reason)?;
        let g = file.create_group("optimum")?;
        scalar(&g, "reach", optimum.design.reach)?;
        scalar(&g, "gamma_crit", optimum.design.gamma)?;
        array(
            &g,
            "shape_coefficients",
            &[optimum.design.shape_coefficients.len()],
            &optimum.design.shape_coefficients,
        )?;
        let b = &optimum.curvature_coefficients;
        array(&g, "curvature_coefficients", &[b.len()], b)?;
        points(&g, "loaded_shape", &optimum.loaded_shape)?;
        points(&g, "unloaded_shape", &optimum.unloaded_shape)?;
        array(
            &g,
            "intrinsic_curvature",
            &[optimum.intrinsic_curvature.len()],
            &optimum.intrinsic_curvature,
        )?;
        g.new_attr::<u64>()
            .create("evaluations")?
            .write_scalar(&(optimum.evaluations as u64))?;
        if let Some(s) = straight {
            let g = file.create_group("straight")?;
            scalar(&g, "reach", s.reach)?;
            scalar(&g, "gamma_crit", s.gamma)?;
            scalar(&g, "clamp_angle", s.clamp_angle)?;
            points(&g, "loaded_shape", &s.loaded_shape)?;
        }
        Ok(())
    })
}
