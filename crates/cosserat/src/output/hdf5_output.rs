//! Equilibria as HDF5 files (built as a [`store`] tree).
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

use nalgebra::Vector3;

use super::store::{self, Group, StoreError, StoreResult};

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
    /// The HDF5 file could not be built or written.
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
    write_atomically(path, force, |root| {
        root_attributes(root, problem);
        write_solution(root, eq)
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
    write_atomically(path, force, |root| {
        root_attributes(root, problem);
        match result {
            StabilityResult::Equilibrium(eq, stability) => {
                write_solution(root, eq)?;
                write_spectrum(root, stability)
            }
            StabilityResult::FixedShape(critical) => write_critical_load(root, critical),
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

/// Builds the file's tree with `write`, describes it ([`super::schema`]),
/// writes it to a temporary file next to `path`, seals it and renames it
/// into place; removes the temporary on any failure.
pub(crate) fn write_atomically(
    path: &Path,
    force: bool,
    write: impl FnOnce(&mut Group) -> StoreResult<()>,
) -> Result<(), OutputError> {
    check_target(path, force)?;
    let tmp = super::target::temporary_path(path);
    let failed = |message: String| OutputError::Hdf5 {
        path: path.display().to_string(),
        message,
    };
    let mut root = Group::root();
    let result = write(&mut root)
        .and_then(|()| {
            super::schema::describe_file(&mut root);
            store::write(&tmp, &root)
        })
        .map_err(|e| failed(e.to_string()))
        .and_then(|()| super::seal::seal(&tmp).map_err(|e| failed(format!("sealing: {e}"))));
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

/// The root attribute naming the program that wrote a file.
pub(crate) fn set_generator(root: &mut Group) {
    root.attrs
        .set_text("generator", concat!("cosserat ", env!("CARGO_PKG_VERSION")));
}

/// Samples' vectors as an n×3 dataset.
fn vectors(
    group: &mut Group,
    name: &str,
    samples: &[RodSample],
    f: impl Fn(&RodSample) -> nalgebra::Vector3<f64>,
) -> StoreResult<()> {
    let data: Vec<f64> = samples
        .iter()
        .flat_map(|p| f(p).as_slice().to_vec())
        .collect();
    group.floats(name, &[samples.len(), 3], &data)
}

fn root_attributes(root: &mut Group, problem: &str) {
    root.attrs.set_text("problem", problem);
    set_generator(root);
}

fn write_solution(root: &mut Group, eq: &Equilibrium) -> StoreResult<()> {
    let g = root.create_group("solution");
    let s: Vec<f64> = eq.samples.iter().map(|p| p.s).collect();
    g.floats("s", &[s.len()], &s)?;
    vectors(g, "position", &eq.samples, |p| p.position)?;
    for (i, name) in ["d1", "d2", "d3"].iter().enumerate() {
        vectors(g, name, &eq.samples, |p| p.directors[i])?;
    }
    vectors(g, "curvature", &eq.samples, |p| p.curvature)?;
    vectors(g, "moment", &eq.samples, |p| p.moment)?;
    vectors(g, "force", &eq.samples, |p| p.force)?;
    let h = &eq.residual_history;
    g.floats("residual_history", &[h.len()], h)?;
    g.floats("unknowns", &[eq.unknowns.len()], &eq.unknowns)?;
    let a = &mut g.attrs;
    a.set_count("segments", eq.method.segments() as u64);
    a.set_text("model", eq.model.level.name());
    a.set_text("model_reason", &eq.model.reason);
    a.set_text("method", eq.method.name());
    a.set_count("iterations", eq.iterations as u64);
    a.set_float("residual", eq.residual);
    a.set_text("converged", "true");
    a.set_count("load_steps", eq.load_steps as u64);
    a.set_float("director_drift", eq.director_drift);
    a.set_float("wall_time", eq.wall_time);
    a.set_count("integration_steps", eq.integration.accepted as u64);
    Ok(())
}

/// Modes as (count × nodes × 3).
fn modes(
    group: &mut Group,
    name: &str,
    modes: &[&Vec<Vector3<f64>>],
    nodes: usize,
) -> StoreResult<()> {
    let data: Vec<f64> = modes
        .iter()
        .flat_map(|m| m.iter().flat_map(|w| w.as_slice().to_vec()))
        .collect();
    group.floats(name, &[modes.len(), nodes, 3], &data)
}

fn write_spectrum(root: &mut Group, st: &Stability) -> StoreResult<()> {
    let g = root.create_group("stability");
    let n = st.nodes.len();
    g.floats("nodes", &[n], &st.nodes)?;
    let mut all: Vec<(f64, &Vec<Vector3<f64>>)> = st
        .blocks
        .iter()
        .flat_map(|b| b.eigenvalues.iter().copied().zip(b.modes.iter()))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    all.truncate(st.blocks.first().map_or(0, |b| b.eigenvalues.len()));
    let values: Vec<f64> = all.iter().map(|a| a.0).collect();
    g.floats("eigenvalues", &[values.len()], &values)?;
    modes(
        g,
        "eigenvectors",
        &all.iter().map(|a| a.1).collect::<Vec<_>>(),
        n,
    )?;
    g.attrs.set_count("morse_index", st.morse_index as u64);
    g.count("morse_index", st.morse_index as u64)?;
    g.attrs
        .set_text("verdict", if st.stable { "stable" } else { "unstable" });
    for b in st.blocks.iter().filter(|b| b.block != Block::Full) {
        let sub = g.create_group(b.block.name());
        sub.floats("eigenvalues", &[b.eigenvalues.len()], &b.eigenvalues)?;
        modes(sub, "eigenvectors", &b.modes.iter().collect::<Vec<_>>(), n)?;
        sub.count("morse_index", b.morse_index as u64)?;
    }
    Ok(())
}

fn write_critical_load(root: &mut Group, c: &CriticalLoad) -> StoreResult<()> {
    let g = root.create_group("stability");
    let n = c.nodes.len();
    g.floats("nodes", &[n], &c.nodes)?;
    // None: stable under any load, so the critical load is +∞ (the value,
    // not a placeholder).
    g.float("critical_load", c.gamma.unwrap_or(f64::INFINITY))?;
    g.float("load_factor", c.load_factor.unwrap_or(f64::INFINITY))?;
    for (block, factor, mode) in &c.blocks {
        let sub = g.create_group(block.name());
        sub.float("load_factor", factor.unwrap_or(f64::INFINITY))?;
        if !mode.is_empty() {
            modes(sub, "null_vector", &[mode], n)?;
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
pub fn read_solved(path: &Path) -> StoreResult<SolvedUnknowns> {
    let f = super::seal::open(path)?;
    let g = f
        .group("solution")
        .map_err(|_| StoreError::from("it has no /solution group"))?;
    let unknowns = g
        .dataset("unknowns")
        .map_err(|_| {
            StoreError::from(
                "its /solution has no unknowns (written before solve files kept them): solve again",
            )
        })?
        .floats()?
        .to_vec();
    Ok(SolvedUnknowns {
        problem: f.attrs.text("problem")?.to_owned(),
        model: g.attrs.text("model")?.to_owned(),
        method: g.attrs.text("method")?.to_owned(),
        unknowns,
    })
}
