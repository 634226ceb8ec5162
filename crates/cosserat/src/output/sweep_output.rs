//! Sweep results as HDF5 (a contract, see README.md "Sweeps"):
//!
//! - root attributes `problem` (the base problem text), `kind` (`arm` or
//!   `solve`), `shard` (`i/n`, or `merged`), `stop_reason` (`running` in a
//!   checkpoint, `interrupted`, `completed`), `points` (grid size),
//!   `members` (points this file is responsible for);
//! - `/grid/keys` (k strings), `/grid/axis_<j>` (the values of axis j),
//!   `/grid/shape`;
//! - `/points/index` (n, flat row-major grid index, last axis fastest),
//!   `/points/parameters` (n×k), and every result column under
//!   `/points/<name>` (n, or n×w; NaN where a value does not exist),
//!   labels as strings; `/points` attributes `columns` and `labels` list
//!   the names, one per line;
//! - `/maps/<name>`: every one-value column on the full grid (the grid's
//!   shape, NaN where not computed) — e.g. `/maps/family_0/reach`, ready
//!   for a contour plot in h5py.
//!
//! Written atomically (temporary file, then rename), so a checkpoint is
//! always a whole file.

use crate::continuation::RunState;
use std::collections::BTreeSet;
use std::path::Path;

use hdf5::types::VarLenUnicode;

use super::hdf5_output::{array, string_attr, text, write_atomically, OutputError};
use crate::study::sweep::grid_index;
use crate::study::sweep::Record;

/// What a sweep file says about itself.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepHeader {
    /// The base problem text.
    pub problem: String,
    /// `arm` or `solve`.
    pub kind: String,
    /// `i/n` or `merged`.
    pub shard: String,
    /// In progress (a checkpoint), interrupted, completed, or partial (a merge).
    pub stop_reason: RunState,
    /// The swept keys.
    pub keys: Vec<String>,
    /// Their values.
    pub axes: Vec<Vec<f64>>,
    /// Points this file is responsible for.
    pub members: usize,
}

impl SweepHeader {
    /// Grid size.
    pub fn points(&self) -> usize {
        self.axes.iter().map(Vec::len).product()
    }
}

fn strings(g: &hdf5::Group, name: &str, data: &[String]) -> hdf5::Result<()> {
    let values: Vec<VarLenUnicode> = data.iter().map(|s| text(s)).collect::<hdf5::Result<_>>()?;
    g.new_dataset::<VarLenUnicode>()
        .shape([values.len()])
        .create(name)?
        .write_raw(&values)
}

/// The group at `path` below `root`, created as needed; and the last name.
fn parent<'a>(root: &hdf5::Group, path: &'a str) -> hdf5::Result<(hdf5::Group, &'a str)> {
    let mut g = root.clone();
    let mut parts: Vec<&str> = path.split('/').collect();
    let last = parts.pop().unwrap_or_default();
    for p in parts {
        g = match g.group(p) {
            Ok(sub) => sub,
            Err(_) => g.create_group(p)?,
        };
    }
    Ok((g, last))
}

/// Writes `records` (sorted by index) under `header`, atomically.
pub fn write_sweep(
    path: &Path,
    header: &SweepHeader,
    records: &[Record],
    force: bool,
) -> Result<(), OutputError> {
    write_atomically(path, force, |file| {
        for (name, value) in [
            ("problem", &header.problem),
            ("kind", &header.kind),
            ("shard", &header.shard),
            ("stop_reason", &header.stop_reason.name().to_string()),
            (
                "generator",
                &concat!("cosserat ", env!("CARGO_PKG_VERSION")).to_string(),
            ),
        ] {
            string_attr(file, name, value)?;
        }
        for (name, v) in [("points", header.points()), ("members", header.members)] {
            file.new_attr::<u64>()
                .create(name)?
                .write_scalar(&(v as u64))?;
        }
        write_grid(file, header)?;
        write_points(file, header, records)?;
        write_maps(file, header, records)
    })
}

fn write_grid(file: &hdf5::File, header: &SweepHeader) -> hdf5::Result<()> {
    let g = file.create_group("grid")?;
    strings(&g, "keys", &header.keys)?;
    for (j, values) in header.axes.iter().enumerate() {
        array(&g, &format!("axis_{j}"), &[values.len()], values)?;
    }
    let shape: Vec<u64> = header.axes.iter().map(|a| a.len() as u64).collect();
    g.new_dataset::<u64>()
        .shape([shape.len()])
        .create("shape")?
        .write_raw(&shape)
}

/// The axis values at flat index `i` on the grid of `axes`.
fn parameters(axes: &[Vec<f64>], i: usize) -> Vec<f64> {
    let shape: Vec<usize> = axes.iter().map(Vec::len).collect();
    grid_index(&shape, i)
        .iter()
        .zip(axes)
        .map(|(j, a)| a[*j])
        .collect()
}

fn write_points(file: &hdf5::File, header: &SweepHeader, records: &[Record]) -> hdf5::Result<()> {
    let g = file.create_group("points")?;
    let n = records.len();
    let index: Vec<u64> = records.iter().map(|r| r.index as u64).collect();
    g.new_dataset::<u64>()
        .shape([n])
        .create("index")?
        .write_raw(&index)?;
    let k = header.axes.len();
    let params: Vec<f64> = records
        .iter()
        .flat_map(|r| parameters(&header.axes, r.index))
        .collect();
    array(&g, "parameters", &[n, k], &params)?;
    let columns: BTreeSet<&String> = records.iter().flat_map(|r| r.numbers.keys()).collect();
    for name in &columns {
        let width = records
            .iter()
            .filter_map(|r| r.numbers.get(*name).map(Vec::len))
            .max()
            .unwrap_or(1);
        let mut data = vec![f64::NAN; n * width];
        for (row, r) in records.iter().enumerate() {
            for (j, v) in r.numbers.get(*name).into_iter().flatten().enumerate() {
                data[row * width + j] = *v;
            }
        }
        let (parent, last) = parent(&g, name)?;
        let shape: Vec<usize> = if width == 1 { vec![n] } else { vec![n, width] };
        array(&parent, last, &shape, &data)?;
    }
    let labels: BTreeSet<&String> = records.iter().flat_map(|r| r.labels.keys()).collect();
    for name in &labels {
        let values: Vec<String> = records
            .iter()
            .map(|r| r.labels.get(*name).cloned().unwrap_or_default())
            .collect();
        let (parent, last) = parent(&g, name)?;
        strings(&parent, last, &values)?;
    }
    let list = |s: &BTreeSet<&String>| s.iter().map(|x| x.as_str()).collect::<Vec<_>>().join("\n");
    string_attr(&g, "columns", &list(&columns))?;
    string_attr(&g, "labels", &list(&labels))
}

fn write_maps(file: &hdf5::File, header: &SweepHeader, records: &[Record]) -> hdf5::Result<()> {
    let g = file.create_group("maps")?;
    let shape: Vec<usize> = header.axes.iter().map(Vec::len).collect();
    let columns: BTreeSet<&String> = records
        .iter()
        .flat_map(|r| {
            r.numbers
                .iter()
                .filter(|(_, v)| v.len() == 1)
                .map(|(k, _)| k)
        })
        .collect();
    for name in columns {
        let mut data = vec![f64::NAN; header.points()];
        for r in records {
            if let Some(v) = r.numbers.get(name).filter(|v| v.len() == 1) {
                data[r.index] = v[0];
            }
        }
        let (parent, last) = parent(&g, name)?;
        array(&parent, last, &shape, &data)?;
    }
    Ok(())
}

fn read_string(loc: &hdf5::Location, name: &str) -> hdf5::Result<String> {
    Ok(loc
        .attr(name)?
        .read_scalar::<VarLenUnicode>()?
        .as_str()
        .to_string())
}

/// Reads a sweep file: its header and records.
pub fn read_sweep(path: &Path) -> hdf5::Result<(SweepHeader, Vec<Record>)> {
    let f = super::seal::open(path)?;
    let grid = f.group("grid")?;
    let keys: Vec<String> = grid
        .dataset("keys")?
        .read_raw::<VarLenUnicode>()?
        .iter()
        .map(|s| s.as_str().to_string())
        .collect();
    let axes = (0..keys.len())
        .map(|j| grid.dataset(&format!("axis_{j}"))?.read_raw::<f64>())
        .collect::<hdf5::Result<Vec<_>>>()?;
    let header = SweepHeader {
        problem: read_string(&f, "problem")?,
        kind: read_string(&f, "kind")?,
        shard: read_string(&f, "shard")?,
        stop_reason: {
            let name = read_string(&f, "stop_reason")?;
            RunState::from_name(&name).ok_or_else(|| {
                hdf5::Error::from(format!("unknown stop_reason `{name}`").as_str())
            })?
        },
        keys,
        axes,
        members: f.attr("members")?.read_scalar::<u64>()? as usize,
    };
    let g = f.group("points")?;
    let index = g.dataset("index")?.read_raw::<u64>()?;
    let points: usize = header.axes.iter().map(Vec::len).product();
    let mut seen = std::collections::BTreeSet::new();
    if index
        .iter()
        .any(|&i| i as usize >= points || !seen.insert(i))
    {
        return Err("a point index is outside the grid or repeated".into());
    }
    let mut records: Vec<Record> = index.iter().map(|i| Record::new(*i as usize)).collect();
    let names = |attr: &str| -> hdf5::Result<Vec<String>> {
        Ok(read_string(&g, attr)?
            .lines()
            .filter(|l| !l.is_empty())
            .map(String::from)
            .collect())
    };
    for name in names("columns")? {
        let d = g.dataset(&name)?;
        let width = d.shape().get(1).copied().unwrap_or(1);
        let data = d.read_raw::<f64>()?;
        if data.len() != width.max(1) * records.len() {
            return Err(format!("column {name}: not one row per point")
                .as_str()
                .into());
        }
        for (r, row) in records.iter_mut().zip(data.chunks(width.max(1))) {
            r.set(&name, row.to_vec());
        }
    }
    for name in names("labels")? {
        let data = g.dataset(&name)?.read_raw::<VarLenUnicode>()?;
        if data.len() != records.len() {
            return Err(format!("label {name}: not one per point").as_str().into());
        }
        for (r, v) in records.iter_mut().zip(data) {
            if !v.as_str().is_empty() {
                r.label(&name, v.as_str());
            }
        }
    }
    Ok((header, records))
}
