//! The rod shapes a result file holds, for `cosserat export`: the one
//! place the export reads HDF5 ([`read_shapes`]), so a change of HDF5
//! backend changes this module only. What comes back is plain data:
//! every array with its dataset path and shape in the file (for XDMF,
//! which refers to the file instead of copying it) and its values (for
//! VTK).
//!
//! Kinds of file with a shape: an equilibrium (`solve -o`, `stability -o`:
//! `/solution`, every field), a diagram (`continue -o`, the `--*-path`
//! files of `optimize`: `/branches/<i>/shapes`, the centreline at equally
//! spaced points of each continuation point, and in files written since
//! the diagram keeps the whole rod there: s, directors, curvature, moment
//! and force) and an arm study
//! (`optimize -o`: the designs' loaded and unloaded centrelines). A fixed
//! shape's stability report and a sweep hold none.

use std::path::Path;

use cosserat::output::read_stable;
use cosserat::output::store::{Group, StoreResult};

/// What kind of result a file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// `solve -o` or `stability -o`: one equilibrium.
    Equilibrium,
    /// `continue -o`: a bifurcation diagram.
    Diagram,
    /// `optimize -o`: the designs of an arm study.
    ArmStudy,
}

/// An array of the file: its dataset, the dataset's shape, the row of the
/// first axis taken (a diagram's point), and the values of that selection.
#[derive(Debug, Clone)]
pub struct Array {
    /// Its path in the file.
    pub dataset: String,
    /// The dataset's shape.
    pub dims: Vec<usize>,
    /// The row of the first axis this array is, if not the whole dataset.
    pub row: Option<usize>,
    /// The selected values, row-major.
    pub values: Vec<f64>,
}

impl Array {
    /// Row `k` of the first axis of a whole dataset (a diagram point).
    fn row(&self, k: usize) -> Array {
        let width: usize = self.dims.iter().skip(1).product();
        Array {
            dataset: self.dataset.clone(),
            dims: self.dims.clone(),
            row: Some(k),
            values: self.values[k * width..(k + 1) * width].to_vec(),
        }
    }

    /// The points of the selection (its first axis after the row).
    pub fn points(&self) -> usize {
        let axis = usize::from(self.row.is_some());
        self.dims.get(axis).copied().unwrap_or(0)
    }
}

/// A named array of values at the shape's points.
#[derive(Debug, Clone)]
pub struct Field {
    /// The name it is exported under.
    pub name: &'static str,
    /// Its values.
    pub array: Array,
}

/// One rod shape of the file.
#[derive(Debug, Clone)]
pub struct Frame {
    /// What it shows, e.g. `branch 1 point 12`, `optimum loaded`.
    pub label: String,
    /// The diagram branch it belongs to.
    pub branch: Option<usize>,
    /// The continuation parameter of a diagram point.
    pub parameter: Option<f64>,
    /// The Morse index of a diagram point.
    pub morse_index: Option<u64>,
    /// Whether a diagram point is stable.
    pub stable: Option<bool>,
    /// The centreline, n×3.
    pub points: Array,
    /// Arrays at the points.
    pub fields: Vec<Field>,
    /// The points are at equally spaced arc lengths from s = 0 to s = L.
    pub equally_spaced: bool,
}

impl Frame {
    /// Whether the frame carries a stored field `name`.
    pub fn has_field(&self, name: &str) -> bool {
        self.fields.iter().any(|f| f.name == name)
    }
}

/// A diagram branch's continued key and the earlier stages' keys held on
/// it (what rebuilds the problem at one of its points).
#[derive(Debug, Clone)]
pub struct Branch {
    /// The key the branch continues (absent in older files).
    pub parameter_name: Option<String>,
    /// The keys held at the values of earlier stages.
    pub held: Vec<(String, f64)>,
}

/// Every shape of a result file.
#[derive(Debug, Clone)]
pub struct ShapeFile {
    /// The kind of result.
    pub kind: FileKind,
    /// The problem text stored with the result.
    pub problem: String,
    /// The diagram's branches (empty for other kinds).
    pub branches: Vec<Branch>,
    /// The shapes, branch after branch for a diagram.
    pub frames: Vec<Frame>,
}

/// Why a file gives no shape.
#[derive(Debug, thiserror::Error)]
pub enum ShapeFileError {
    /// Not a readable result file (missing, damaged, not HDF5, datasets
    /// that contradict each other).
    #[error("{path}: {reason}")]
    Unreadable {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// A result file of a kind that stores no rod shape.
    #[error("{path} holds no rod shape ({what}); export reads solve, stability, continue and optimize files")]
    NoShape {
        /// The file.
        path: String,
        /// What it is instead.
        what: String,
    },
}

/// The equilibrium's datasets and the names they are exported under (the
/// names of [`cosserat::output::vtk::Polyline::from_samples`]).
pub const EQUILIBRIUM_FIELDS: [(&str, &str); 7] = [
    ("s", "s"),
    ("d1", "d1"),
    ("d2", "d2"),
    ("d3", "d3"),
    ("curvature", "curvature_body"),
    ("moment", "moment_body"),
    ("force", "force"),
];

/// The designs of an arm study that may be stored, in the order exported.
const ARM_SHAPES: [(&str, &str); 7] = [
    ("optimum", "loaded_shape"),
    ("optimum", "unloaded_shape"),
    ("straight", "loaded_shape"),
    ("closest_straight", "loaded_shape"),
    ("closest_straight", "unloaded_shape"),
    ("least_curvature", "loaded_shape"),
    ("least_curvature", "unloaded_shape"),
];

/// The shapes of the result file at `path`.
pub fn read_shapes(path: &Path) -> Result<ShapeFile, ShapeFileError> {
    let unreadable = |reason: String| ShapeFileError::Unreadable {
        path: path.display().to_string(),
        reason,
    };
    // The seal is checked before the HDF5 parser sees the bytes.
    let file = cosserat::output::seal::open(path)
        .map_err(|e| unreadable(format!("not a readable cosserat result file: {e}")))?;
    let problem = file
        .attrs
        .text("problem")
        .map_err(|e| unreadable(e.to_string()))?
        .to_string();
    let read = if file.group("solution").is_ok() {
        read_equilibrium(&file).map(|frames| (FileKind::Equilibrium, vec![], frames))
    } else if file.group("branches").is_ok() {
        read_diagram(&file).map(|(b, f)| (FileKind::Diagram, b, f))
    } else if file.group("optimum").is_ok() {
        read_arm(&file).map(|frames| (FileKind::ArmStudy, vec![], frames))
    } else {
        let what = if file.group("stability").is_ok() {
            "the critical load of a fixed shape"
        } else if file.group("points").is_ok() {
            "a sweep"
        } else {
            "no /solution, /branches or /optimum group"
        };
        return Err(ShapeFileError::NoShape {
            path: path.display().to_string(),
            what: what.into(),
        });
    };
    let (kind, branches, frames) = read.map_err(|e| unreadable(e.to_string()))?;
    Ok(ShapeFile {
        kind,
        problem,
        branches,
        frames,
    })
}

/// A whole float dataset, checked to hold `points`×`width` values
/// (`width` 1: a vector of `points`).
fn whole(file: &Group, dataset: &str, width: usize) -> StoreResult<Array> {
    let ds = file.dataset(dataset)?;
    let dims = ds.shape().to_vec();
    let expected = if width == 1 { 1 } else { 2 };
    if dims.len() != expected || (width > 1 && dims[1] != width) {
        return Err(format!("/{dataset} has shape {dims:?}, not n×{width}").into());
    }
    let values = ds.floats()?.to_vec();
    Ok(Array {
        dataset: format!("/{dataset}"),
        dims,
        row: None,
        values,
    })
}

fn read_equilibrium(file: &Group) -> StoreResult<Vec<Frame>> {
    let points = whole(file, "solution/position", 3)?;
    let n = points.points();
    let mut fields = Vec::with_capacity(EQUILIBRIUM_FIELDS.len());
    for (dataset, name) in EQUILIBRIUM_FIELDS {
        let width = if dataset == "s" { 1 } else { 3 };
        let array = whole(file, &format!("solution/{dataset}"), width)?;
        if array.points() != n {
            return Err(format!(
                "/solution/{dataset} has {} rows for {n} positions",
                array.points()
            )
            .into());
        }
        fields.push(Field { name, array });
    }
    Ok(vec![Frame {
        label: "equilibrium".into(),
        branch: None,
        parameter: None,
        morse_index: None,
        stable: None,
        points,
        fields,
        equally_spaced: false,
    }])
}

fn read_branch_info(g: &Group) -> StoreResult<Branch> {
    let Ok(parameter_name) = g.attrs.text("parameter_name") else {
        return Ok(Branch {
            parameter_name: None,
            held: vec![],
        });
    };
    let keys = g.dataset("held_keys")?.texts()?;
    let values = g.dataset("held_values")?.floats()?;
    if keys.len() != values.len() {
        return Err("held_keys and held_values have different lengths".into());
    }
    Ok(Branch {
        parameter_name: Some(parameter_name.to_string()),
        held: keys.iter().cloned().zip(values.iter().copied()).collect(),
    })
}

fn read_diagram(file: &Group) -> StoreResult<(Vec<Branch>, Vec<Frame>)> {
    let root = file.group("branches")?;
    let (mut branches, mut frames) = (vec![], vec![]);
    for i in 0.. {
        let Ok(g) = root.group(&i.to_string()) else {
            break;
        };
        branches.push(read_branch_info(g)?);
        frames.extend(branch_frames(g, i)?);
    }
    Ok((branches, frames))
}

/// The points of branch `i`, one frame each.
fn branch_frames(g: &Group, i: usize) -> StoreResult<Vec<Frame>> {
    let shapes = g.dataset("shapes")?;
    let dims = shapes.shape().to_vec();
    let parameter = g.dataset("parameter")?.floats()?;
    let stable = read_stable(g.dataset("stable")?)?;
    let morse = g.dataset("morse_index")?.counts()?;
    let m = parameter.len();
    if dims.len() != 3 || dims[0] != m || dims[2] != 3 || stable.len() != m || morse.len() != m {
        return Err(format!(
            "branch {i}: shapes {dims:?}, parameter {m}, stable {}, morse_index {} disagree",
            stable.len(),
            morse.len()
        )
        .into());
    }
    let values = shapes.floats()?;
    let width = dims[1] * 3;
    let stored = branch_fields(g, i, &dims)?;
    Ok((0..m)
        .map(|k| Frame {
            label: format!("branch {i} point {k}"),
            branch: Some(i),
            parameter: Some(parameter[k]),
            morse_index: Some(morse[k]),
            stable: Some(stable[k]),
            points: Array {
                dataset: format!("/branches/{i}/shapes"),
                dims: dims.clone(),
                row: Some(k),
                values: values[k * width..(k + 1) * width].to_vec(),
            },
            fields: stored
                .iter()
                .map(|(name, a)| Field {
                    name,
                    array: a.row(k),
                })
                .collect(),
            equally_spaced: true,
        })
        .collect())
}

/// The fields stored at a branch's shape points (files written since the
/// diagram keeps the whole rod at its shape points; older files hold the
/// centreline only): the same names as an equilibrium's.
const BRANCH_FIELDS: [(&str, &str); 7] = [
    ("shape_s", "s"),
    ("shape_d1", "d1"),
    ("shape_d2", "d2"),
    ("shape_d3", "d3"),
    ("shape_curvature", "curvature_body"),
    ("shape_moment", "moment_body"),
    ("shape_force", "force"),
];

/// Branch `i`'s stored fields, each checked against the centreline's
/// shape `dims` (m×n×3; `shape_s` m×n).
fn branch_fields(g: &Group, i: usize, dims: &[usize]) -> StoreResult<Vec<(&'static str, Array)>> {
    let mut fields = vec![];
    for (dataset, name) in BRANCH_FIELDS {
        let Ok(ds) = g.dataset(dataset) else {
            continue;
        };
        let want: &[usize] = if dataset == "shape_s" {
            &dims[..2]
        } else {
            dims
        };
        if ds.shape() != want {
            return Err(format!(
                "branch {i}: {dataset} has shape {:?}, the centreline {dims:?}",
                ds.shape()
            )
            .into());
        }
        fields.push((
            name,
            Array {
                dataset: format!("/branches/{i}/{dataset}"),
                dims: ds.shape().to_vec(),
                row: None,
                values: ds.floats()?.to_vec(),
            },
        ));
    }
    Ok(fields)
}

fn read_arm(file: &Group) -> StoreResult<Vec<Frame>> {
    let mut frames = vec![];
    for (group, shape) in ARM_SHAPES {
        if file.dataset(&format!("{group}/{shape}")).is_err() {
            continue;
        }
        let points = whole(file, &format!("{group}/{shape}"), 3)?;
        // κ⁰2 at the same material points as the design's shapes.
        let mut fields = vec![];
        if let Ok(k) = whole(file, &format!("{group}/intrinsic_curvature"), 1) {
            if k.points() == points.points() {
                fields.push(Field {
                    name: "intrinsic_curvature_2",
                    array: k,
                });
            }
        }
        let state = shape.trim_end_matches("_shape");
        frames.push(Frame {
            label: format!("{group} {state}"),
            branch: None,
            parameter: None,
            morse_index: None,
            stable: None,
            points,
            fields,
            equally_spaced: false,
        });
    }
    Ok(frames)
}
