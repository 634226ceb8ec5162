//! Equilibria as HDF5 files (through the HDF5 C library, hdf5-metno).
//!
//! Layout (a contract, see README.md): group `/solution` with datasets `s`
//! (n), `position`, `d1`, `d2`, `d3`, `curvature`, `moment` (body), `force`
//! (global), each n×3, `unknowns` (the solve's shooting unknowns: κ(0)
//! and the interior node states of multiple shooting, what
//! `cosserat continue --from SOLVE.h5` starts Newton from; empty for
//! collocation); attributes `model`, `model_reason`, `method`, `segments`
//! (the shooting segments), `iterations`, `residual`, and more; the
//! problem text as the root attribute `problem`.
//!
//! The file is written under a temporary name in the target directory and
//! renamed at the end, so a failure never leaves half a file behind.

use std::path::Path;

use hdf5::types::VarLenUnicode;

use nalgebra::Vector3;

use crate::bvp::Equilibrium;
use crate::equations::RodSample;
use crate::stability::{Block, CriticalLoad, Stability};

/// Why a result could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The target exists and overwriting was not asked for.
    #[error("{0} exists; pass --force to overwrite it")]
    Exists(String),
    /// The target cannot be replaced (not a regular file, an input).
    #[error("{0}")]
    Unusable(String),
    /// The HDF5 library reported an error.
    #[error("writing {path}: {message}")]
    Hdf5 {
        /// The file being written.
        path: String,
        /// The HDF5 library's error.
        message: String,
    },
    /// The rename into place failed.
    #[error("moving the result to {path}: {source}")]
    Rename {
        /// The final path of the result.
        path: String,
        /// The error of the rename.
        source: std::io::Error,
    },
}

/// Fails early when `path` exists and `force` is false.
pub fn check_target(path: &Path, force: bool) -> Result<(), OutputError> {
    super::target::ensure_replaceable(path).map_err(|e| OutputError::Unusable(e.to_string()))?;
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
    write_atomically(path, force, |file| {
        root_attributes(file, problem)?;
        write_solution(file, eq)
    })
}

/// Writes a stability analysis (with its equilibrium, or the critical load
/// of a fixed shape) to `path` atomically.
pub fn write_stability(
    path: &Path,
    problem: &str,
    result: &StabilityResult,
    force: bool,
) -> Result<(), OutputError> {
    write_atomically(path, force, |file| {
        root_attributes(file, problem)?;
        match result {
            StabilityResult::Equilibrium(eq, stability) => {
                write_solution(file, eq)?;
                write_spectrum(file, stability)
            }
            StabilityResult::FixedShape(critical) => write_critical_load(file, critical),
        }
    })
}

/// What `cosserat stability` computed.
#[derive(Debug, Clone)]
pub enum StabilityResult {
    /// An equilibrium and its spectrum.
    Equilibrium(Box<Equilibrium>, Stability),
    /// The critical load of a fixed loaded shape.
    FixedShape(CriticalLoad),
}

/// Runs `write` on a temporary file next to `path` and renames it into
/// place; removes the temporary on any failure.
pub(crate) fn write_atomically(
    path: &Path,
    force: bool,
    write: impl FnOnce(&hdf5::File) -> hdf5::Result<()>,
) -> Result<(), OutputError> {
    check_target(path, force)?;
    let tmp = super::target::temporary_path(path);
    let result = hdf5::File::create(&tmp)
        .and_then(|file| {
            write(&file)?;
            super::schema::describe_file(&file)?;
            file.flush()
        })
        .map_err(|e| OutputError::Hdf5 {
            path: path.display().to_string(),
            message: e.to_string(),
        });
    let result = result.and_then(|()| {
        super::seal::seal(&tmp).map_err(|e| OutputError::Hdf5 {
            path: path.display().to_string(),
            message: format!("sealing: {e}"),
        })
    });
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    if let Err(e) = super::target::ensure_replaceable(path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(OutputError::Unusable(e.to_string()));
    }
    std::fs::rename(&tmp, path).map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        OutputError::Rename {
            path: path.display().to_string(),
            source,
        }
    })
}

pub(crate) fn text(s: &str) -> hdf5::Result<VarLenUnicode> {
    s.parse::<VarLenUnicode>()
        .map_err(|e| hdf5::Error::from(e.to_string().as_str()))
}

pub(crate) fn string_attr(loc: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
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

fn root_attributes(file: &hdf5::File, problem: &str) -> hdf5::Result<()> {
    string_attr(file, "problem", problem)?;
    string_attr(
        file,
        "generator",
        concat!("cosserat ", env!("CARGO_PKG_VERSION")),
    )
}

pub(crate) fn array(
    group: &hdf5::Group,
    name: &str,
    shape: &[usize],
    data: &[f64],
) -> hdf5::Result<()> {
    group
        .new_dataset::<f64>()
        .shape(shape)
        .create(name)?
        .write_raw(data)
}

fn write_solution(file: &hdf5::File, eq: &Equilibrium) -> hdf5::Result<()> {
    let g = file.create_group("solution")?;
    let s: Vec<f64> = eq.samples.iter().map(|p| p.s).collect();
    array(&g, "s", &[s.len()], &s)?;
    vectors(&g, "position", &eq.samples, |p| p.position)?;
    for (i, name) in ["d1", "d2", "d3"].iter().enumerate() {
        vectors(&g, name, &eq.samples, |p| p.directors[i])?;
    }
    vectors(&g, "curvature", &eq.samples, |p| p.curvature)?;
    vectors(&g, "moment", &eq.samples, |p| p.moment)?;
    vectors(&g, "force", &eq.samples, |p| p.force)?;
    let h = &eq.residual_history;
    array(&g, "residual_history", &[h.len()], h)?;
    array(&g, "unknowns", &[eq.unknowns.len()], &eq.unknowns)?;
    usize_attr(&g, "segments", eq.method.segments())?;
    string_attr(&g, "model", eq.model.level.name())?;
    string_attr(&g, "model_reason", &eq.model.reason)?;
    string_attr(&g, "method", eq.method.name())?;
    usize_attr(&g, "iterations", eq.iterations)?;
    f64_attr(&g, "residual", eq.residual)?;
    string_attr(&g, "converged", "true")?;
    usize_attr(&g, "load_steps", eq.load_steps)?;
    f64_attr(&g, "director_drift", eq.director_drift)?;
    f64_attr(&g, "wall_time", eq.wall_time)?;
    usize_attr(&g, "integration_steps", eq.integration.accepted)
}

/// Modes as (count × nodes × 3).
fn modes(
    group: &hdf5::Group,
    name: &str,
    modes: &[&Vec<Vector3<f64>>],
    nodes: usize,
) -> hdf5::Result<()> {
    let data: Vec<f64> = modes
        .iter()
        .flat_map(|m| m.iter().flat_map(|w| w.as_slice().to_vec()))
        .collect();
    array(group, name, &[modes.len(), nodes, 3], &data)
}

fn write_spectrum(file: &hdf5::File, st: &Stability) -> hdf5::Result<()> {
    let g = file.create_group("stability")?;
    let n = st.nodes.len();
    array(&g, "nodes", &[n], &st.nodes)?;
    let mut all: Vec<(f64, &Vec<Vector3<f64>>)> = st
        .blocks
        .iter()
        .flat_map(|b| b.eigenvalues.iter().copied().zip(b.modes.iter()))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    all.truncate(st.blocks.first().map_or(0, |b| b.eigenvalues.len()));
    let values: Vec<f64> = all.iter().map(|a| a.0).collect();
    array(&g, "eigenvalues", &[values.len()], &values)?;
    modes(
        &g,
        "eigenvectors",
        &all.iter().map(|a| a.1).collect::<Vec<_>>(),
        n,
    )?;
    usize_attr(&g, "morse_index", st.morse_index)?;
    g.new_dataset::<u64>()
        .create("morse_index")?
        .write_scalar(&(st.morse_index as u64))?;
    string_attr(&g, "verdict", if st.stable { "stable" } else { "unstable" })?;
    for b in st.blocks.iter().filter(|b| b.block != Block::Full) {
        let sub = g.create_group(b.block.name())?;
        array(&sub, "eigenvalues", &[b.eigenvalues.len()], &b.eigenvalues)?;
        modes(&sub, "eigenvectors", &b.modes.iter().collect::<Vec<_>>(), n)?;
        sub.new_dataset::<u64>()
            .create("morse_index")?
            .write_scalar(&(b.morse_index as u64))?;
    }
    Ok(())
}

fn write_critical_load(file: &hdf5::File, c: &CriticalLoad) -> hdf5::Result<()> {
    let g = file.create_group("stability")?;
    let n = c.nodes.len();
    array(&g, "nodes", &[n], &c.nodes)?;
    g.new_dataset::<f64>()
        .create("critical_load")?
        // None: stable under any load, so the critical load is +∞ (the
        // value, not a placeholder).
        .write_scalar(&c.gamma.unwrap_or(f64::INFINITY))?;
    g.new_dataset::<f64>()
        .create("load_factor")?
        .write_scalar(&c.load_factor.unwrap_or(f64::INFINITY))?;
    for (block, factor, mode) in &c.blocks {
        let sub = g.create_group(block.name())?;
        sub.new_dataset::<f64>()
            .create("load_factor")?
            .write_scalar(&factor.unwrap_or(f64::INFINITY))?;
        if !mode.is_empty() {
            modes(&sub, "null_vector", &[mode], n)?;
        }
    }
    Ok(())
}

/// What a solve file keeps to start a continuation from its equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct SolvedUnknowns {
    /// The problem text it was solved from.
    pub problem: String,
    /// The model level's name (`planar`, `kirchhoff`, `cosserat`).
    pub model: String,
    /// The method's name (`shooting`, `multiple-shooting`, `collocation`).
    pub method: String,
    /// The shooting unknowns (empty for collocation).
    pub unknowns: Vec<f64>,
}

/// The equilibrium's unknowns of a file `cosserat solve` (or
/// `cosserat stability` on an equilibrium) wrote, its seal checked; an
/// error names what is missing (a file of another kind, or one written
/// before solve files kept their unknowns).
pub fn read_solved(path: &Path) -> hdf5::Result<SolvedUnknowns> {
    let f = super::seal::open(path)?;
    let g = f
        .group("solution")
        .map_err(|_| hdf5::Error::from("it has no /solution group"))?;
    let unknowns = g
        .dataset("unknowns")
        .map_err(|_| {
            hdf5::Error::from(
                "its /solution has no unknowns (written before solve files kept them): solve again",
            )
        })?
        .read_raw::<f64>()?;
    let read = |loc: &hdf5::Location, name: &str| -> hdf5::Result<String> {
        Ok(loc
            .attr(name)?
            .read_scalar::<VarLenUnicode>()?
            .as_str()
            .to_string())
    };
    Ok(SolvedUnknowns {
        problem: read(&f, "problem")?,
        model: read(&g, "model")?,
        method: read(&g, "method")?,
        unknowns,
    })
}
