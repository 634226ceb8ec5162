//! Equilibria as HDF5 files (through the HDF5 C library, hdf5-metno).
//!
//! Layout (a contract, see README.md): group `/solution` with datasets `s`
//! (n), `position`, `d1`, `d2`, `d3`, `curvature`, `moment` (body), `force`
//! (global), each n×3; attributes `model`, `model_reason`, `method`,
//! `iterations`, `residual`, and more; the problem text as the root
//! attribute `problem`.
//!
//! The file is written under a temporary name in the target directory and
//! renamed at the end, so a failure never leaves half a file behind.

use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;

use crate::bvp::Equilibrium;
use crate::equations::RodSample;

/// Why a result could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The target exists and overwriting was not asked for.
    #[error("{0} exists; pass --force to overwrite it")]
    Exists(String),
    /// The HDF5 library reported an error.
    #[error("writing {path}: {message}")]
    Hdf5 { path: String, message: String },
    /// The rename into place failed.
    #[error("moving the result to {path}: {source}")]
    Rename {
        path: String,
        source: std::io::Error,
    },
}

/// Fails early when `path` exists and `force` is false.
pub fn check_target(path: &Path, force: bool) -> Result<(), OutputError> {
    if path.exists() && !force {
        return Err(OutputError::Exists(path.display().to_string()));
    }
    Ok(())
}

/// Writes `eq` and the problem text to `path` atomically.
pub fn write_equilibrium(
    path: &Path,
    eq: &Equilibrium,
    problem: &str,
    force: bool,
) -> Result<(), OutputError> {
    check_target(path, force)?;
    let tmp = temporary_path(path);
    let result = write_file(&tmp, eq, problem).map_err(|e| OutputError::Hdf5 {
        path: path.display().to_string(),
        message: e.to_string(),
    });
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        OutputError::Rename {
            path: path.display().to_string(),
            source,
        }
    })
}

fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

fn text(s: &str) -> hdf5::Result<VarLenUnicode> {
    s.parse::<VarLenUnicode>()
        .map_err(|e| hdf5::Error::from(e.to_string().as_str()))
}

fn string_attr(loc: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
    loc.new_attr::<VarLenUnicode>()
        .create(name)?
        .write_scalar(&text(value)?)
}

fn f64_attr(loc: &hdf5::Location, name: &str, value: f64) -> hdf5::Result<()> {
    loc.new_attr::<f64>().create(name)?.write_scalar(&value)
}

fn usize_attr(loc: &hdf5::Location, name: &str, value: usize) -> hdf5::Result<()> {
    loc.new_attr::<u64>()
        .create(name)?
        .write_scalar(&(value as u64))
}

fn vectors(
    group: &hdf5::Group,
    name: &str,
    samples: &[RodSample],
    f: impl Fn(&RodSample) -> nalgebra::Vector3<f64>,
) -> hdf5::Result<()> {
    let data: Vec<f64> = samples
        .iter()
        .flat_map(|p| f(p).as_slice().to_vec())
        .collect();
    group
        .new_dataset::<f64>()
        .shape([samples.len(), 3])
        .create(name)?
        .write_raw(&data)
}

fn write_file(path: &Path, eq: &Equilibrium, problem: &str) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;
    string_attr(&file, "problem", problem)?;
    string_attr(
        &file,
        "generator",
        concat!("cosserat ", env!("CARGO_PKG_VERSION")),
    )?;
    let g = file.create_group("solution")?;
    let s: Vec<f64> = eq.samples.iter().map(|p| p.s).collect();
    g.new_dataset::<f64>()
        .shape([s.len()])
        .create("s")?
        .write_raw(&s)?;
    vectors(&g, "position", &eq.samples, |p| p.position)?;
    for (i, name) in ["d1", "d2", "d3"].iter().enumerate() {
        vectors(&g, name, &eq.samples, |p| p.directors[i])?;
    }
    vectors(&g, "curvature", &eq.samples, |p| p.curvature)?;
    vectors(&g, "moment", &eq.samples, |p| p.moment)?;
    vectors(&g, "force", &eq.samples, |p| p.force)?;
    let h = &eq.residual_history;
    g.new_dataset::<f64>()
        .shape([h.len()])
        .create("residual_history")?
        .write_raw(h)?;
    string_attr(&g, "model", eq.model.level.name())?;
    string_attr(&g, "model_reason", &eq.model.reason)?;
    string_attr(&g, "method", eq.method.name())?;
    usize_attr(&g, "iterations", eq.iterations)?;
    f64_attr(&g, "residual", eq.residual)?;
    string_attr(&g, "converged", "true")?;
    usize_attr(&g, "load_steps", eq.load_steps)?;
    f64_attr(&g, "director_drift", eq.director_drift)?;
    f64_attr(&g, "wall_time", eq.wall_time)?;
    usize_attr(&g, "integration_steps", eq.integration.accepted)?;
    file.flush()?;
    Ok(())
}
