//! Bifurcation diagrams as HDF5 files.
//!
//! Layout (a contract, see README.md): `/branches/<i>/parameter` (m),
//! `tip_position` (m×3), `eigenvalues` (m×k), `stable` (m), `morse_index`
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
//! `parameter`, `tip_position` (s×3), `measures` (s×k), `block`, `symmetry_breaking`,
//! `null_vectors` (s×nodes×3), `singularity` (s×2), `multiplicity` (s:
//! eigenvalues crossing zero; absent in older files, read as 1), `location` (s strings:
//! `augmented` — a fold on the minimally augmented system —, `bracketed` —
//! the root of a test function by regula falsi; absent in older files, read
//! as `bracketed`); `/warnings` (events
//! detected but not located, as text); the problem text as the
//! root attribute `problem`, the run's `stop_reason` and the parameter name
//! as root attributes (the first stage's parameter for a chained run, whose
//! root attribute `stages` counts its stages).

use std::path::Path;

use hdf5::types::VarLenUnicode;

use super::hdf5_output::{array, string_attr, text, write_atomically, OutputError};
use crate::continuation::{
    stage_of, BranchEnd, Diagram, Location, RunState, SavedBranch, SavedDiagram, SavedSpecial,
    SpecialKind, Stage,
};
use crate::stability::Block;

fn integers(group: &hdf5::Group, name: &str, data: &[u64]) -> hdf5::Result<()> {
    group
        .new_dataset::<u64>()
        .shape([data.len()])
        .create(name)?
        .write_raw(data)
}

fn strings(group: &hdf5::Group, name: &str, data: &[&str]) -> hdf5::Result<()> {
    let values: Vec<VarLenUnicode> = data.iter().map(|s| text(s)).collect::<hdf5::Result<_>>()?;
    group
        .new_dataset::<VarLenUnicode>()
        .shape([values.len()])
        .create(name)?
        .write_raw(&values)
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
    write_atomically(path, force, |file| {
        string_attr(file, "problem", problem)?;
        string_attr(file, "parameter_name", parameter)?;
        if stages.len() > 1 {
            file.new_attr::<u64>()
                .create("stages")?
                .write_scalar(&(stages.len() as u64))?;
        }
        string_attr(file, "stop_reason", diagram.stop_reason.name())?;
        string_attr(
            file,
            "generator",
            concat!("cosserat ", env!("CARGO_PKG_VERSION")),
        )?;
        write_branches(file, diagram, stages)?;
        write_special_points(file, diagram)?;
        let warnings: Vec<&str> = diagram.warnings.iter().map(String::as_str).collect();
        strings(file, "warnings", &warnings)
    })
}

fn write_branches(file: &hdf5::File, d: &Diagram, stages: &[Stage]) -> hdf5::Result<()> {
    let root = file.create_group("branches")?;
    let names: Vec<&str> = d.eigenvalue_names.iter().map(String::as_str).collect();
    strings(&root, "eigenvalue_names", &names)?;
    let measure_names: Vec<&str> = d.measure_names.iter().map(String::as_str).collect();
    strings(&root, "measure_names", &measure_names)?;
    for (i, b) in d.branches.iter().enumerate() {
        let g = root.create_group(&i.to_string())?;
        let m = b.points.len();
        let k = d.eigenvalue_names.len();
        let col = |f: &dyn Fn(&crate::continuation::Point) -> f64| {
            b.points.iter().map(f).collect::<Vec<f64>>()
        };
        array(&g, "parameter", &[m], &col(&|p| p.parameter))?;
        let tip: Vec<f64> = b
            .points
            .iter()
            .flat_map(|p| p.tip.position.as_slice().to_vec())
            .collect();
        array(&g, "tip_position", &[m, 3], &tip)?;
        let eig: Vec<f64> = b
            .points
            .iter()
            .flat_map(|p| p.eigenvalues.clone())
            .collect();
        array(&g, "eigenvalues", &[m, k], &eig)?;
        let stable: Vec<u64> = b.points.iter().map(|p| u64::from(p.stable)).collect();
        integers(&g, "stable", &stable)?;
        let morse: Vec<u64> = b.points.iter().map(|p| p.morse_index as u64).collect();
        integers(&g, "morse_index", &morse)?;
        array(&g, "norm", &[m], &col(&|p| p.norm))?;
        array(&g, "tip_angle", &[m], &col(&|p| p.tip_angle))?;
        let measures: Vec<f64> = b.points.iter().flat_map(|p| p.measures.clone()).collect();
        array(&g, "measures", &[m, d.measure_names.len()], &measures)?;
        // The discrete unknowns and tangents: enough to restart a branch.
        let n = b.points.first().map_or(0, |p| p.unknowns.len());
        let x: Vec<f64> = b.points.iter().flat_map(|p| p.unknowns.clone()).collect();
        array(&g, "unknowns", &[m, n], &x)?;
        let t: Vec<f64> = b.points.iter().flat_map(|p| p.tangent.clone()).collect();
        array(&g, "tangent", &[m, n + 1], &t)?;
        let shapes: Vec<f64> = b
            .points
            .iter()
            .flat_map(|p| p.shape.iter().flat_map(|r| r.as_slice().to_vec()))
            .collect();
        let n_shape = b.points.first().map_or(0, |p| p.shape.len());
        array(&g, "shapes", &[m, n_shape, 3], &shapes)?;
        g.new_attr::<i64>()
            .create("parent")?
            .write_scalar(&b.parent.map_or(-1, |p| p as i64))?;
        string_attr(&g, "stop_reason", &b.stop_reason.to_string())?;
        g.new_attr::<f64>()
            .create("direction")?
            .write_scalar(&b.direction)?;
        g.new_attr::<f64>()
            .create("next_step")?
            .write_scalar(&b.next_step)?;
        write_stage(&g, stages, i)?;
    }
    Ok(())
}

/// The stage of branch `i`: its number, key and held keys.
fn write_stage(g: &hdf5::Group, stages: &[Stage], i: usize) -> hdf5::Result<()> {
    let k = stage_of(stages, i);
    g.new_attr::<u64>()
        .create("stage")?
        .write_scalar(&(k as u64 + 1))?;
    let Some(stage) = stages.get(k) else {
        return Ok(());
    };
    string_attr(g, "parameter_name", stage.key())?;
    let keys: Vec<&str> = stage.held().iter().map(|(k, _)| k.as_str()).collect();
    strings(g, "held_keys", &keys)?;
    let values: Vec<f64> = stage.held().iter().map(|(_, v)| *v).collect();
    array(g, "held_values", &[values.len()], &values)
}

/// The keys held on a branch and their values.
type Held = Vec<(String, f64)>;

/// The key and held keys of a stored branch (absent in older files).
fn read_stage(g: &hdf5::Group) -> hdf5::Result<(Option<String>, Held)> {
    let Ok(name) = read_string(g, "parameter_name") else {
        return Ok((None, vec![]));
    };
    let keys = g.dataset("held_keys")?.read_raw::<VarLenUnicode>()?;
    let values = g.dataset("held_values")?.read_raw::<f64>()?;
    if keys.len() != values.len() {
        return Err("held_keys and held_values have different lengths".into());
    }
    let held = keys
        .iter()
        .map(|k| k.as_str().to_string())
        .zip(values)
        .collect();
    Ok((Some(name), held))
}

fn write_special_points(file: &hdf5::File, d: &Diagram) -> hdf5::Result<()> {
    let g = file.create_group("special_points")?;
    let sp = &d.special_points;
    let kinds: Vec<&str> = sp.iter().map(|s| s.kind.name()).collect();
    strings(&g, "kind", &kinds)?;
    let blocks: Vec<&str> = sp.iter().map(|s| s.block.name()).collect();
    strings(&g, "block", &blocks)?;
    integers(
        &g,
        "branch",
        &sp.iter().map(|s| s.branch as u64).collect::<Vec<_>>(),
    )?;
    integers(
        &g,
        "index",
        &sp.iter().map(|s| s.index as u64).collect::<Vec<_>>(),
    )?;
    integers(
        &g,
        "symmetry_breaking",
        &sp.iter()
            .map(|s| u64::from(s.symmetry_breaking))
            .collect::<Vec<_>>(),
    )?;
    array(
        &g,
        "parameter",
        &[sp.len()],
        &sp.iter().map(|s| s.point.parameter).collect::<Vec<_>>(),
    )?;
    let tip: Vec<f64> = sp
        .iter()
        .flat_map(|s| s.point.tip.position.as_slice().to_vec())
        .collect();
    array(&g, "tip_position", &[sp.len(), 3], &tip)?;
    let measures: Vec<f64> = sp.iter().flat_map(|s| s.point.measures.clone()).collect();
    array(
        &g,
        "measures",
        &[sp.len(), d.measure_names.len()],
        &measures,
    )?;
    let sing: Vec<f64> = sp
        .iter()
        .flat_map(|s| [s.singularity.0, s.singularity.1])
        .collect();
    array(&g, "singularity", &[sp.len(), 2], &sing)?;
    integers(
        &g,
        "multiplicity",
        &sp.iter().map(|s| s.multiplicity as u64).collect::<Vec<_>>(),
    )?;
    strings(
        &g,
        "location",
        &sp.iter().map(|s| s.location.name()).collect::<Vec<_>>(),
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
    array(&g, "null_vectors", &[sp.len(), nodes, 3], &null)?;
    array(&g, "nodes", &[nodes], &d.nodes)?;
    let n = sp.first().map_or(0, |s| s.point.unknowns.len());
    let x: Vec<f64> = sp.iter().flat_map(|s| s.point.unknowns.clone()).collect();
    array(&g, "unknowns", &[sp.len(), n], &x)?;
    let t: Vec<f64> = sp.iter().flat_map(|s| s.point.tangent.clone()).collect();
    array(&g, "tangent", &[sp.len(), n + 1], &t)
}

fn rows(g: &hdf5::Group, name: &str) -> hdf5::Result<Vec<Vec<f64>>> {
    let ds = g.dataset(name)?;
    let width = ds.shape().get(1).copied().unwrap_or(0).max(1);
    Ok(ds
        .read_raw::<f64>()?
        .chunks(width)
        .map(<[f64]>::to_vec)
        .collect())
}

fn read_string(loc: &hdf5::Location, name: &str) -> hdf5::Result<String> {
    Ok(loc
        .attr(name)?
        .read_scalar::<VarLenUnicode>()?
        .as_str()
        .to_string())
}

/// How each of `count` special points was located; files written before
/// fold location by the augmented system hold bracketed roots only.
fn locations(g: &hdf5::Group, count: usize) -> hdf5::Result<Vec<Location>> {
    let Ok(ds) = g.dataset("location") else {
        return Ok(vec![Location::Bracketed; count]);
    };
    ds.read_raw::<VarLenUnicode>()?
        .iter()
        .map(|v| match v.as_str() {
            "augmented" => Ok(Location::Augmented),
            "bracketed" => Ok(Location::Bracketed),
            other => Err(format!("unknown location `{other}`").as_str().into()),
        })
        .collect()
}

/// The problem text and what a diagram file keeps of its run (for
/// `cosserat continue --resume`).
pub fn read_saved(path: &Path) -> hdf5::Result<(String, SavedDiagram)> {
    let f = super::seal::open(path)?;
    let problem = read_string(&f, "problem")?;
    let root = f.group("branches")?;
    let mut branches = vec![];
    for i in 0.. {
        let Ok(g) = root.group(&i.to_string()) else {
            break;
        };
        let parent = g.attr("parent")?.read_scalar::<i64>()?;
        let (parameter_name, held) = read_stage(&g)?;
        branches.push(SavedBranch {
            parameter: g.dataset("parameter")?.read_raw::<f64>()?,
            unknowns: rows(&g, "unknowns")?,
            tangent: rows(&g, "tangent")?,
            parent: usize::try_from(parent).ok(),
            stop_reason: BranchEnd::from_text(&read_string(&g, "stop_reason")?),
            direction: g.attr("direction")?.read_scalar::<f64>()?,
            next_step: g.attr("next_step")?.read_scalar::<f64>()?,
            parameter_name,
            held,
        });
    }
    let g = f.group("special_points")?;
    let kinds = g.dataset("kind")?.read_raw::<VarLenUnicode>()?;
    let blocks = g.dataset("block")?.read_raw::<VarLenUnicode>()?;
    let branch = g.dataset("branch")?.read_raw::<u64>()?;
    let index = g.dataset("index")?.read_raw::<u64>()?;
    let sym = g.dataset("symmetry_breaking")?.read_raw::<u64>()?;
    let parameter = g.dataset("parameter")?.read_raw::<f64>()?;
    let sing = rows(&g, "singularity")?;
    // Files written before the multiplicity was recorded hold simple
    // points only: the Morse index changed by one, or the change was not
    // located at all.
    let multiplicity = match g.dataset("multiplicity") {
        Ok(ds) => ds.read_raw::<u64>()?,
        Err(_) => vec![1; kinds.len()],
    };
    let location = locations(&g, kinds.len())?;
    let (x, t) = (rows(&g, "unknowns")?, rows(&g, "tangent")?);
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
        x.len(),
        t.len(),
    ];
    if lengths.iter().any(|&l| l != count) || sing.iter().any(|r| r.len() != 2) {
        return Err("the special-point datasets have different lengths".into());
    }
    let unknown = |what: &str, v: &str| hdf5::Error::from(format!("unknown {what} `{v}`").as_str());
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
            symmetry_breaking: sym[i] == 1,
            singularity: (sing[i][0], sing[i][1]),
            multiplicity: multiplicity[i] as usize,
            location: location[i],
            parameter: parameter[i],
            unknowns: x[i].clone(),
            tangent: t[i].clone(),
        });
    }
    Ok((
        problem,
        SavedDiagram {
            branches,
            specials,
            stop_reason: {
                let name = read_string(&f, "stop_reason")?;
                RunState::from_name(&name).ok_or_else(|| {
                    hdf5::Error::from(format!("unknown stop_reason `{name}`").as_str())
                })?
            },
            warnings: f
                .dataset("warnings")?
                .read_raw::<VarLenUnicode>()?
                .iter()
                .map(|w| w.as_str().to_string())
                .collect(),
        },
    ))
}
