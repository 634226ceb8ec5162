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
//!   `/points/<name>` (n, or n×w; NaN where a value does not exist; a
//!   count column — [`super::schema::is_count_column`] — as i64, −1 where
//!   it does not exist), labels as strings; `/points` attributes `columns` and `labels` list
//!   the names, one per line;
//! - `/maps/<name>`: every one-value column on the full grid (the grid's
//!   shape, NaN — or −1 for a count — where not computed) — e.g. `/maps/family_0/reach`, ready
//!   for a contour plot in h5py.
//!
//! Written atomically (temporary file, then rename), so a checkpoint is
//! always a whole file.

use crate::continuation::RunState;
use std::collections::BTreeSet;
use std::path::Path;

use super::hdf5_output::{set_generator, write_atomically, OutputError};
use super::schema::is_count_column;
use super::store::{Dataset, Group, StoreError, StoreResult, Values};
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

/// A numeric column as stored: floats, or for a count column i64 with −1
/// where the value does not exist (NaN in the record). A count that is
/// not a whole number ≥ 0 is refused, never rounded.
fn column(name: &str, data: Vec<f64>) -> StoreResult<Values> {
    if !is_count_column(name) {
        return Ok(Values::Floats(data));
    }
    data.iter()
        .map(|&v| {
            if v.is_nan() {
                Ok(-1)
            } else if v >= 0.0 && v.fract() == 0.0 && v < 9.0e15 {
                Ok(v as i64)
            } else {
                Err(StoreError::from(format!(
                    "column {name}: {v} is not a count"
                )))
            }
        })
        .collect::<StoreResult<Vec<i64>>>()
        .map(Values::Signed)
}

/// A stored numeric column back as the record's floats (−1 of a count
/// column: NaN, the value does not exist).
fn column_values(d: &Dataset) -> StoreResult<Vec<f64>> {
    match d.values() {
        Values::Floats(v) => Ok(v.clone()),
        Values::Signed(v) => Ok(v
            .iter()
            .map(|&x| if x < 0 { f64::NAN } else { x as f64 })
            .collect()),
        other => Err(format!(
            "dataset {} is {}, not a column",
            d.path(),
            other.type_name()
        )
        .into()),
    }
}

/// Writes `records` (sorted by index) under `header`, atomically.
pub fn write_sweep(
    path: &Path,
    header: &SweepHeader,
    records: &[Record],
    force: bool,
) -> Result<(), OutputError> {
    write_atomically(path, force, |root| {
        for (name, value) in [
            ("problem", header.problem.as_str()),
            ("kind", header.kind.as_str()),
            ("shard", header.shard.as_str()),
            ("stop_reason", header.stop_reason.name()),
        ] {
            root.attrs.set_text(name, value);
        }
        set_generator(root);
        root.attrs.set_count("points", header.points() as u64);
        root.attrs.set_count("members", header.members as u64);
        write_grid(root, header)?;
        write_points(root, header, records)?;
        write_maps(root, header, records)
    })
}

fn write_grid(root: &mut Group, header: &SweepHeader) -> StoreResult<()> {
    let g = root.create_group("grid");
    g.texts("keys", &header.keys)?;
    for (j, values) in header.axes.iter().enumerate() {
        g.floats(&format!("axis_{j}"), &[values.len()], values)?;
    }
    let shape: Vec<u64> = header.axes.iter().map(|a| a.len() as u64).collect();
    g.counts("shape", &shape)
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

fn write_points(root: &mut Group, header: &SweepHeader, records: &[Record]) -> StoreResult<()> {
    let g = root.create_group("points");
    let n = records.len();
    let index: Vec<u64> = records.iter().map(|r| r.index as u64).collect();
    g.counts("index", &index)?;
    let k = header.axes.len();
    let params: Vec<f64> = records
        .iter()
        .flat_map(|r| parameters(&header.axes, r.index))
        .collect();
    g.floats("parameters", &[n, k], &params)?;
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
        let shape: Vec<usize> = if width == 1 { vec![n] } else { vec![n, width] };
        g.put(name, &shape, column(name, data)?)?;
    }
    let labels: BTreeSet<&String> = records.iter().flat_map(|r| r.labels.keys()).collect();
    for name in &labels {
        let values: Vec<String> = records
            .iter()
            .map(|r| r.labels.get(*name).cloned().unwrap_or_default())
            .collect();
        g.texts(name, &values)?;
    }
    let list = |s: &BTreeSet<&String>| s.iter().map(|x| x.as_str()).collect::<Vec<_>>().join("\n");
    g.attrs.set_text("columns", &list(&columns));
    g.attrs.set_text("labels", &list(&labels));
    Ok(())
}

fn write_maps(root: &mut Group, header: &SweepHeader, records: &[Record]) -> StoreResult<()> {
    let g = root.create_group("maps");
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
        g.put(name, &shape, column(name, data)?)?;
    }
    Ok(())
}

/// Reads a sweep file: its header and records.
pub fn read_sweep(path: &Path) -> StoreResult<(SweepHeader, Vec<Record>)> {
    let f = super::seal::open(path)?;
    let grid = f.group("grid")?;
    let keys = grid.dataset("keys")?.texts()?.to_vec();
    let axes = (0..keys.len())
        .map(|j| Ok(grid.dataset(&format!("axis_{j}"))?.floats()?.to_vec()))
        .collect::<StoreResult<Vec<_>>>()?;
    let text = |name: &str| -> StoreResult<String> { Ok(f.attrs.text(name)?.to_owned()) };
    let header = SweepHeader {
        problem: text("problem")?,
        kind: text("kind")?,
        shard: text("shard")?,
        stop_reason: {
            let name = text("stop_reason")?;
            RunState::from_name(&name)
                .ok_or_else(|| StoreError::from(format!("unknown stop_reason `{name}`")))?
        },
        keys,
        axes,
        members: f.attrs.count("members")? as usize,
    };
    let g = f.group("points")?;
    let index = g.dataset("index")?.counts()?;
    let points: usize = header.axes.iter().map(Vec::len).product();
    let mut seen = std::collections::BTreeSet::new();
    if index
        .iter()
        .any(|&i| i as usize >= points || !seen.insert(i))
    {
        return Err("a point index is outside the grid or repeated".into());
    }
    let mut records: Vec<Record> = index.iter().map(|i| Record::new(*i as usize)).collect();
    let names = |attr: &str| -> StoreResult<Vec<String>> {
        Ok(g.attrs
            .text(attr)?
            .lines()
            .filter(|l| !l.is_empty())
            .map(String::from)
            .collect())
    };
    for name in names("columns")? {
        let d = g.dataset(&name)?;
        let width = d.shape().get(1).copied().unwrap_or(1);
        let data = column_values(d)?;
        if data.len() != width.max(1) * records.len() {
            return Err(format!("column {name}: not one row per point").into());
        }
        for (r, row) in records.iter_mut().zip(data.chunks(width.max(1))) {
            r.set(&name, row.to_vec());
        }
    }
    for name in names("labels")? {
        let data = g.dataset(&name)?.texts()?;
        if data.len() != records.len() {
            return Err(format!("label {name}: not one per point").into());
        }
        for (r, v) in records.iter_mut().zip(data) {
            if !v.is_empty() {
                r.label(&name, v);
            }
        }
    }
    Ok((header, records))
}
