//! Bifurcation diagrams as HDF5 files.
//!
//! Layout (a contract, see README.md): `/branches/<i>/parameter` (m),
//! `tip_position` (m×3), `eigenvalues` (m×k), `stable` (m strings: `stable`, `unstable`), `morse_index`
//! (m), `norm` (m), `measures` (m×k, named by `/branches/measure_names`),
//! `shapes` (m×21×3), `unknowns` (m×n) and `tangent`
//! (m×(n+1)) of the discretization, attributes `parent`, `stop_reason`,
//! `direction` (±1: travel along or against the stored tangents),
//! `next_step` (the arclength step a resumed run goes on with), `stage`
//! (1 for a single run; the stage of a chained run, `[[continuation.stage]]`)
//! and `parameter_name` (the key the branch continues), datasets
//! `held_keys` (strings) and `held_values` (the earlier stages' keys held
//! on the branch and their values; empty on a first stage);
//! `/special_points/kind` (strings), `branch`, `index`,
//! `parameter`, `tip_position` (s×3), `measures` (s×k), `block`, `symmetry_breaking`
//! (s strings: `breaking`, `preserving`; u64 1/0 in files of schema 1),
//! `null_vectors` (s×nodes×3), `singularity` (s×2), `multiplicity` (s:
//! eigenvalues crossing zero; absent in older files, read as 1), `location` (s strings:
//! `augmented` — a fold or simple branch point on a minimally augmented
//! system —, `bracketed` — the root of a test function by regula falsi —,
//! `extrapolated` — a finite-element crossing on three meshes, Richardson;
//! absent in older files, read as `bracketed`), `parameter_error` (s: the
//! parameter's estimated error — the discretization's for a located
//! point, the extrapolations' for an extrapolated crossing, an unclosed
//! bracket's spread —, NaN where not estimated; absent in older files); `/warnings` (events
//! detected but not located, as text); the problem text as the
//! root attribute `problem`, the run's `stop_reason` and the parameter name
//! as root attributes (the first stage's parameter for a chained run, whose
//! root attribute `stages` counts its stages).

use std::path::Path;

use super::hdf5_output::{set_generator, write_atomically, OutputError};
use super::store::{Dataset, Group, StoreError, StoreResult, Values};
use nalgebra::Vector3;

use crate::continuation::{
    stage_of, BranchEnd, Diagram, Location, Point, RunState, SavedBranch, SavedDiagram,
    SavedSpecial, SpecialKind, Stage,
};
use crate::equations::RodSample;
use crate::stability::Block;

/// The names a stored flag takes: (true, false).
const STABLE: (&str, &str) = ("stable", "unstable");
const SYMMETRY_BREAKING: (&str, &str) = ("breaking", "preserving");

/// Flags as named strings.
fn flags(group: &mut Group, name: &str, data: &[bool], names: (&str, &str)) -> StoreResult<()> {
    let v: Vec<&str> = data
        .iter()
        .map(|&b| if b { names.0 } else { names.1 })
        .collect();
    group.texts(name, &v)
}

/// Reads flags written by [`flags`], or as 1/0 by files of schema 1.
pub(crate) fn read_flags(ds: &Dataset, names: (&str, &str)) -> StoreResult<Vec<bool>> {
    match ds.values() {
        Values::Counts(v) => Ok(v.iter().map(|&x| x == 1).collect()),
        Values::Texts(v) => v
            .iter()
            .map(|x| match x.as_str() {
                t if t == names.0 => Ok(true),
                f if f == names.1 => Ok(false),
                other => Err(StoreError::from(format!(
                    "dataset {}: `{other}` is neither `{}` nor `{}`",
                    ds.path(),
                    names.0,
                    names.1
                ))),
            })
            .collect(),
        other => Err(StoreError::from(format!(
            "dataset {} is {}, not strings",
            ds.path(),
            other.type_name()
        ))),
    }
}

/// Reads the stability flags of a branch (`stable`).
pub fn read_stable(ds: &Dataset) -> StoreResult<Vec<bool>> {
    read_flags(ds, STABLE)
}

/// Writes the diagram of a single run in `parameter` atomically (a
/// temporary file renamed into place).
pub fn write_diagram(
    path: &Path,
    problem: &str,
    parameter: &str,
    diagram: &Diagram,
    force: bool,
) -> Result<(), OutputError> {
    write_stages(path, problem, &[Stage::first(parameter)], diagram, force)
}

/// Writes the diagram of a chained run atomically, each branch tagged with
/// its stage (`stages` in order, the first starting at branch 0).
pub fn write_stages(
    path: &Path,
    problem: &str,
    stages: &[Stage],
    diagram: &Diagram,
    force: bool,
) -> Result<(), OutputError> {
    let parameter = stages.first().map_or("", Stage::key);
    write_atomically(path, force, |root| {
        root.attrs.set_text("problem", problem);
        root.attrs.set_text("parameter_name", parameter);
        if stages.len() > 1 {
            root.attrs.set_count("stages", stages.len() as u64);
        }
        root.attrs
            .set_text("stop_reason", diagram.stop_reason.name());
        set_generator(root);
        write_branches(root, diagram, stages)?;
        write_special_points(root, diagram)?;
        root.texts("warnings", &diagram.warnings)
    })
}

fn write_branches(root: &mut Group, d: &Diagram, stages: &[Stage]) -> StoreResult<()> {
    let all = root.create_group("branches");
    all.texts("eigenvalue_names", &d.eigenvalue_names)?;
    all.texts("measure_names", &d.measure_names)?;
    for (i, b) in d.branches.iter().enumerate() {
        let g = all.create_group(&i.to_string());
        let m = b.points.len();
        let k = d.eigenvalue_names.len();
        let col = |f: &dyn Fn(&crate::continuation::Point) -> f64| {
            b.points.iter().map(f).collect::<Vec<f64>>()
        };
        g.floats("parameter", &[m], &col(&|p| p.parameter))?;
        let tip: Vec<f64> = b
            .points
            .iter()
            .flat_map(|p| p.tip.position.as_slice().to_vec())
            .collect();
        g.floats("tip_position", &[m, 3], &tip)?;
        let eig: Vec<f64> = b
            .points
            .iter()
            .flat_map(|p| p.eigenvalues.clone())
            .collect();
        g.floats("eigenvalues", &[m, k], &eig)?;
        let stable: Vec<bool> = b.points.iter().map(|p| p.stable).collect();
        flags(g, "stable", &stable, STABLE)?;
        let morse: Vec<u64> = b.points.iter().map(|p| p.morse_index as u64).collect();
        g.counts("morse_index", &morse)?;
        g.floats("norm", &[m], &col(&|p| p.norm))?;
        g.floats("tip_angle", &[m], &col(&|p| p.tip_angle))?;
        let measures: Vec<f64> = b.points.iter().flat_map(|p| p.measures.clone()).collect();
        g.floats("measures", &[m, d.measure_names.len()], &measures)?;
        // The discrete unknowns and tangents: enough to restart a branch.
        let n = b.points.first().map_or(0, |p| p.unknowns.len());
        let x: Vec<f64> = b.points.iter().flat_map(|p| p.unknowns.clone()).collect();
        g.floats("unknowns", &[m, n], &x)?;
        let t: Vec<f64> = b.points.iter().flat_map(|p| p.tangent.clone()).collect();
        g.floats("tangent", &[m, n + 1], &t)?;
        write_shapes(g, &b.points)?;
        // −1: a primary branch, with no parent.
        g.attrs
            .set_signed("parent", b.parent.map_or(-1, |p| p as i64));
        g.attrs.set_text("stop_reason", &b.stop_reason.to_string());
        g.attrs.set_float("direction", b.direction);
        g.attrs.set_float("next_step", b.next_step);
        write_stage(g, stages, i)?;
    }
    Ok(())
}

/// The rod at each point's equally spaced shape points: the centreline
/// (`shapes`, m×n×3) and the fields ParaView shows (`shape_s` m×n; the
/// directors, curvature, moment and force m×n×3).
fn write_shapes(g: &mut Group, points: &[Point]) -> StoreResult<()> {
    let m = points.len();
    let n = points.first().map_or(0, |p| p.shape.len());
    if points.iter().any(|p| p.shape.len() != n) {
        return Err("the points of a branch have different numbers of shape points".into());
    }
    let vectors = |f: &dyn Fn(&RodSample) -> Vector3<f64>| -> Vec<f64> {
        points
            .iter()
            .flat_map(|p| p.shape.iter().flat_map(|r| f(r).as_slice().to_vec()))
            .collect()
    };
    g.floats("shapes", &[m, n, 3], &vectors(&|r| r.position))?;
    let s: Vec<f64> = points
        .iter()
        .flat_map(|p| p.shape.iter().map(|r| r.s))
        .collect();
    g.floats("shape_s", &[m, n], &s)?;
    for (i, name) in ["shape_d1", "shape_d2", "shape_d3"].into_iter().enumerate() {
        g.floats(name, &[m, n, 3], &vectors(&|r| r.directors[i]))?;
    }
    g.floats("shape_curvature", &[m, n, 3], &vectors(&|r| r.curvature))?;
    g.floats("shape_moment", &[m, n, 3], &vectors(&|r| r.moment))?;
    g.floats("shape_force", &[m, n, 3], &vectors(&|r| r.force))
}

/// The stage of branch `i`: its number, key and held keys.
fn write_stage(g: &mut Group, stages: &[Stage], i: usize) -> StoreResult<()> {
    let k = stage_of(stages, i);
    g.attrs.set_count("stage", k as u64 + 1);
    let Some(stage) = stages.get(k) else {
        return Ok(());
    };
    g.attrs.set_text("parameter_name", stage.key());
    let keys: Vec<&str> = stage.held().iter().map(|(k, _)| k.as_str()).collect();
    g.texts("held_keys", &keys)?;
    let values: Vec<f64> = stage.held().iter().map(|(_, v)| *v).collect();
    g.floats("held_values", &[values.len()], &values)
}

/// The keys held on a branch and their values.
type Held = Vec<(String, f64)>;

/// The key and held keys of a stored branch (absent in older files).
fn read_stage(g: &Group) -> StoreResult<(Option<String>, Held)> {
    let Ok(name) = g.attrs.text("parameter_name") else {
        return Ok((None, vec![]));
    };
    let keys = g.dataset("held_keys")?.texts()?;
    let values = g.dataset("held_values")?.floats()?;
    if keys.len() != values.len() {
        return Err("held_keys and held_values have different lengths".into());
    }
    let held = keys.iter().cloned().zip(values.iter().copied()).collect();
    Ok((Some(name.to_owned()), held))
}

fn write_special_points(root: &mut Group, d: &Diagram) -> StoreResult<()> {
    let g = root.create_group("special_points");
    let sp = &d.special_points;
    let kinds: Vec<&str> = sp.iter().map(|s| s.kind.name()).collect();
    g.texts("kind", &kinds)?;
    let blocks: Vec<&str> = sp.iter().map(|s| s.block.name()).collect();
    g.texts("block", &blocks)?;
    g.counts(
        "branch",
        &sp.iter().map(|s| s.branch as u64).collect::<Vec<_>>(),
    )?;
    g.counts(
        "index",
        &sp.iter().map(|s| s.index as u64).collect::<Vec<_>>(),
    )?;
    let breaking: Vec<bool> = sp.iter().map(|s| s.symmetry_breaking).collect();
    flags(g, "symmetry_breaking", &breaking, SYMMETRY_BREAKING)?;
    g.floats(
        "parameter",
        &[sp.len()],
        &sp.iter().map(|s| s.point.parameter).collect::<Vec<_>>(),
    )?;
    let tip: Vec<f64> = sp
        .iter()
        .flat_map(|s| s.point.tip.position.as_slice().to_vec())
        .collect();
    g.floats("tip_position", &[sp.len(), 3], &tip)?;
    let measures: Vec<f64> = sp.iter().flat_map(|s| s.point.measures.clone()).collect();
    g.floats("measures", &[sp.len(), d.measure_names.len()], &measures)?;
    let sing: Vec<f64> = sp
        .iter()
        .flat_map(|s| [s.singularity.0, s.singularity.1])
        .collect();
    g.floats("singularity", &[sp.len(), 2], &sing)?;
    g.counts(
        "multiplicity",
        &sp.iter().map(|s| s.multiplicity as u64).collect::<Vec<_>>(),
    )?;
    g.texts(
        "location",
        &sp.iter().map(|s| s.location.name()).collect::<Vec<_>>(),
    )?;
    g.floats(
        "parameter_error",
        &[sp.len()],
        &sp.iter()
            .map(|s| s.parameter_error.unwrap_or(f64::NAN))
            .collect::<Vec<_>>(),
    )?;
    let nodes = d.nodes.len();
    let null: Vec<f64> = sp
        .iter()
        .flat_map(|s| {
            let mut v: Vec<f64> = s
                .null_mode
                .iter()
                .flat_map(|w| w.as_slice().to_vec())
                .collect();
            v.resize(nodes * 3, 0.0);
            v
        })
        .collect();
    g.floats("null_vectors", &[sp.len(), nodes, 3], &null)?;
    g.floats("nodes", &[nodes], &d.nodes)?;
    let n = sp.first().map_or(0, |s| s.point.unknowns.len());
    let x: Vec<f64> = sp.iter().flat_map(|s| s.point.unknowns.clone()).collect();
    g.floats("unknowns", &[sp.len(), n], &x)?;
    let t: Vec<f64> = sp.iter().flat_map(|s| s.point.tangent.clone()).collect();
    g.floats("tangent", &[sp.len(), n + 1], &t)
}

fn rows(g: &Group, name: &str) -> StoreResult<Vec<Vec<f64>>> {
    g.dataset(name)?.float_rows()
}

/// How each of `count` special points was located; files written before
/// fold location by the augmented system hold bracketed roots only.
fn locations(g: &Group, count: usize) -> StoreResult<Vec<Location>> {
    let Ok(ds) = g.dataset("location") else {
        return Ok(vec![Location::Bracketed; count]);
    };
    ds.texts()?
        .iter()
        .map(|v| match v.as_str() {
            "augmented" => Ok(Location::Augmented),
            "bracketed" => Ok(Location::Bracketed),
            "extrapolated" => Ok(Location::Extrapolated),
            "interpolated" => Ok(Location::Interpolated),
            other => Err(format!("unknown location `{other}`").into()),
        })
        .collect()
}

/// The estimated parameter error of each of `count` special points (NaN
/// stored where there is none); files written before the estimate was
/// recorded hold points located on the BVP only, or on one mesh's
/// eigenvalue with no estimate.
fn parameter_errors(g: &Group, count: usize) -> StoreResult<Vec<Option<f64>>> {
    let Ok(ds) = g.dataset("parameter_error") else {
        return Ok(vec![None; count]);
    };
    Ok(ds
        .floats()?
        .iter()
        .map(|e| (!e.is_nan()).then_some(*e))
        .collect())
}

/// The problem text and what a diagram file keeps of its run (for
/// `cosserat continue --resume`).
pub fn read_saved(path: &Path) -> StoreResult<(String, SavedDiagram)> {
    let f = super::seal::open(path)?;
    let problem = f.attrs.text("problem")?.to_owned();
    let all = f.group("branches")?;
    let mut branches = vec![];
    for i in 0.. {
        let Ok(g) = all.group(&i.to_string()) else {
            break;
        };
        let parent = g.attrs.signed("parent")?;
        let (parameter_name, held) = read_stage(g)?;
        branches.push(SavedBranch {
            parameter: g.dataset("parameter")?.floats()?.to_vec(),
            unknowns: rows(g, "unknowns")?,
            tangent: rows(g, "tangent")?,
            parent: usize::try_from(parent).ok(),
            stop_reason: BranchEnd::from_text(g.attrs.text("stop_reason")?),
            direction: g.attrs.float("direction")?,
            next_step: g.attrs.float("next_step")?,
            parameter_name,
            held,
        });
    }
    let g = f.group("special_points")?;
    let kinds = g.dataset("kind")?.texts()?;
    let blocks = g.dataset("block")?.texts()?;
    let branch = g.dataset("branch")?.counts()?;
    let index = g.dataset("index")?.counts()?;
    let sym = read_flags(g.dataset("symmetry_breaking")?, SYMMETRY_BREAKING)?;
    let parameter = g.dataset("parameter")?.floats()?;
    let sing = rows(g, "singularity")?;
    // Files written before the multiplicity was recorded hold simple
    // points only: the Morse index changed by one, or the change was not
    // located at all.
    let multiplicity = match g.dataset("multiplicity") {
        Ok(ds) => ds.counts()?.to_vec(),
        Err(_) => vec![1; kinds.len()],
    };
    let location = locations(g, kinds.len())?;
    let parameter_error = parameter_errors(g, kinds.len())?;
    let (x, t) = (rows(g, "unknowns")?, rows(g, "tangent")?);
    let count = kinds.len();
    let lengths = [
        blocks.len(),
        branch.len(),
        index.len(),
        sym.len(),
        parameter.len(),
        sing.len(),
        multiplicity.len(),
        location.len(),
        parameter_error.len(),
        x.len(),
        t.len(),
    ];
    if lengths.iter().any(|&l| l != count) || sing.iter().any(|r| r.len() != 2) {
        return Err("the special-point datasets have different lengths".into());
    }
    let unknown = |what: &str, v: &str| StoreError::from(format!("unknown {what} `{v}`"));
    let mut specials = Vec::with_capacity(kinds.len());
    for i in 0..kinds.len() {
        let kind = match kinds[i].as_str() {
            "fold" => SpecialKind::Fold,
            "branch_point" => SpecialKind::BranchPoint,
            other => return Err(unknown("special point kind", other)),
        };
        let block = match blocks[i].as_str() {
            "in_plane" => Block::InPlane,
            "out_of_plane" => Block::OutOfPlane,
            "full" => Block::Full,
            other => return Err(unknown("block", other)),
        };
        specials.push(SavedSpecial {
            kind,
            branch: branch[i] as usize,
            index: index[i] as usize,
            block,
            symmetry_breaking: sym[i],
            singularity: (sing[i][0], sing[i][1]),
            multiplicity: multiplicity[i] as usize,
            location: location[i],
            parameter_error: parameter_error[i],
            parameter: parameter[i],
            unknowns: x[i].clone(),
            tangent: t[i].clone(),
        });
    }
    let stop_reason = {
        let name = f.attrs.text("stop_reason")?;
        RunState::from_name(name).ok_or_else(|| unknown("stop_reason", name))?
    };
    Ok((
        problem,
        SavedDiagram {
            branches,
            specials,
            stop_reason,
            warnings: f.dataset("warnings")?.texts()?.to_vec(),
        },
    ))
}
