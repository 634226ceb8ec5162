//! Longest-arm results as HDF5: `/optimum/reach`, `/optimum/gamma_crit`
//! (the critical load factor of the optimal shape), `/optimum/load_factor`
//! (the design load: γ_crit, or less when actuator-limited),
//! `/optimum/shape_coefficients`, `/optimum/curvature_coefficients`,
//! `/optimum/loaded_shape` (n×3), `/optimum/unloaded_shape` (n×3),
//! `/optimum/intrinsic_curvature` (n), `/straight/reach`, `/straight/gamma_crit`,
//! `/straight/clamp_angle`, `/straight/loaded_shape` (attributes
//! `stop_reason`: `interrupted` when the search for R̂0 was stopped, its
//! reach then a lower bound; `limit`: what ended the stable level family,
//! `stability_loss` or `no_equilibrium` — a fold or a load the solver
//! could not reach, R̂0 then a lower bound); the problem text as the root attribute
//! `problem`, and `stop_reason` (`completed` or `interrupted`: then
//! /optimum is the best design found so far, without a mesh check).
//!
//! The discretization check of a reported design (in `/optimum`,
//! `/closest_straight`, `/least_curvature`): `mesh_elements` (N, 2N, 4N,
//! N the mesh the design was optimized on, also the attribute
//! `elements`), `reach_meshes` (R̂ on each), `reach_fine` (R̂ on 4N),
//! `reach_error` (Richardson's estimate of the error of `reach`, NaN when
//! the order is undecided), `reach_order` (the measured order), the
//! attribute `mesh_values` (`design`: the design's own reach on each
//! mesh; `local_optima`: the design is infeasible on the finer meshes — an
//! optimum on an actuator limit — and the values there are the optima
//! polished from it), the attribute `mesh` (`resolved`, `refined`: searched again on a finer mesh
//! because the search's did not resolve it, `unresolved`), and
//! `rejected_designs` (k×3: elements, R̂ there, R̂ on 4× the elements) of
//! the designs given up on the way.
//!
//! With a reach map (the Fig. 5 data set): `/map/reach` (n),
//! `/map/load_factor` (n), `/map/shape_coefficients` (n×M),
//! `/map/curvature_coefficients` (n×M), attributes `samples` (evaluated)
//! and `stop_reason` (`interrupted`: a partial map), and the sample closest to a
//! straight rod (the paper's 'Q') in `/closest_straight/` (`index`,
//! `curvature_norm` = Σb², `reach`, `load_factor`, `shape_coefficients`,
//! `curvature_coefficients`, `loaded_shape`, `unloaded_shape`); the design
//! of least Σb² found by Nelder–Mead from the map's best (the paper's way
//! to R0, Sec. 3.2) in `/least_curvature/`, same names (`index`: the map
//! sample it started from).
//!
//! `/search/` keeps how far the search came, for `optimize --resume`:
//! attributes `samples_done`, `polishes_done`, `evaluations`, and the
//! datasets `leader_reach` (k) and `leader_points` (k×(M−1)).

use crate::continuation::RunState;
use std::path::Path;

use super::hdf5_output::{array, string_attr, write_atomically, OutputError};
use crate::study::arm::{
    ArmOptimum, ClosestStraight, ReachMap, Resolution, SearchProgress, StraightArm,
};

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

fn rows(g: &hdf5::Group, name: &str, v: &[Vec<f64>]) -> hdf5::Result<()> {
    let width = v.first().map_or(0, std::vec::Vec::len);
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    array(g, name, &[v.len(), width], &flat)
}

fn count(g: &hdf5::Location, name: &str, v: usize) -> hdf5::Result<()> {
    g.new_attr::<u64>().create(name)?.write_scalar(&(v as u64))
}

fn stop_reason(interrupted: bool) -> &'static str {
    if interrupted {
        RunState::Interrupted.name()
    } else {
        RunState::Completed.name()
    }
}

/// Everything an optimize run keeps.
#[derive(Debug, Clone, Copy)]
pub struct ArmStudy<'a> {
    /// The optimum (the best so far when interrupted).
    pub optimum: &'a ArmOptimum,
    /// R̂0 of the straight arm, if computed.
    pub straight: Option<&'a StraightArm>,
    /// The reach map, if asked for.
    pub map: Option<&'a ReachMap>,
    /// The map's sample closest to a straight rod.
    pub closest: Option<&'a ClosestStraight>,
    /// The design of least Σb² (the paper's R0 method).
    pub least_curvature: Option<&'a ClosestStraight>,
    /// How far the search came (to resume from).
    pub progress: Option<&'a SearchProgress>,
    /// Completed, or interrupted (resumable).
    pub stop_reason: RunState,
}

/// Writes the optimum (and the straight arm, if computed) atomically.
pub fn write_arm(
    path: &Path,
    problem: &str,
    optimum: &ArmOptimum,
    straight: Option<&StraightArm>,
    stop_reason: RunState,
    force: bool,
) -> Result<(), OutputError> {
    let study = ArmStudy {
        optimum,
        straight,
        map: None,
        closest: None,
        least_curvature: None,
        progress: None,
        stop_reason,
    };
    write_arm_study(path, problem, &study, force)
}

/// Writes a whole study atomically.
pub fn write_arm_study(
    path: &Path,
    problem: &str,
    study: &ArmStudy,
    force: bool,
) -> Result<(), OutputError> {
    write_atomically(path, force, |file| {
        string_attr(file, "problem", problem)?;
        string_attr(file, "stop_reason", study.stop_reason.name())?;
        let g = file.create_group("optimum")?;
        write_design(&g, study.optimum)?;
        scalar(&g, "gamma_crit", study.optimum.critical_load)?;
        count(&g, "evaluations", study.optimum.evaluations)?;
        if let Some(s) = study.straight {
            let g = file.create_group("straight")?;
            scalar(&g, "reach", s.reach)?;
            scalar(&g, "gamma_crit", s.gamma)?;
            scalar(&g, "clamp_angle", s.clamp_angle)?;
            points(&g, "loaded_shape", &s.loaded_shape)?;
            string_attr(&g, "stop_reason", stop_reason(s.interrupted))?;
            string_attr(&g, "limit", s.limit.name())?;
        }
        if let Some(m) = study.map {
            let g = file.create_group("map")?;
            array(&g, "reach", &[m.reach.len()], &m.reach)?;
            array(&g, "load_factor", &[m.gamma.len()], &m.gamma)?;
            rows(&g, "shape_coefficients", &m.shape_coefficients)?;
            rows(&g, "curvature_coefficients", &m.curvature_coefficients)?;
            count(&g, "samples", m.samples)?;
            string_attr(&g, "stop_reason", stop_reason(m.interrupted))?;
        }
        for (name, q) in [
            ("closest_straight", study.closest),
            ("least_curvature", study.least_curvature),
        ] {
            if let Some(q) = q {
                let g = file.create_group(name)?;
                write_design(&g, &q.optimum)?;
                count(&g, "index", q.index)?;
                scalar(&g, "curvature_norm", q.curvature_norm)?;
            }
        }
        if let Some(p) = study.progress {
            write_progress(file, p)?;
        }
        Ok(())
    })
}

fn write_design(g: &hdf5::Group, o: &ArmOptimum) -> hdf5::Result<()> {
    scalar(g, "reach", o.design.reach)?;
    if let Some(r) = &o.resolution {
        write_resolution(g, r)?;
    }
    scalar(g, "load_factor", o.design.gamma)?;
    let c = &o.design.shape_coefficients;
    array(g, "shape_coefficients", &[c.len()], c)?;
    let b = &o.curvature_coefficients;
    array(g, "curvature_coefficients", &[b.len()], b)?;
    points(g, "loaded_shape", &o.loaded_shape)?;
    points(g, "unloaded_shape", &o.unloaded_shape)?;
    let k = &o.intrinsic_curvature;
    array(g, "intrinsic_curvature", &[k.len()], k)
}

/// The discretization check of a design (`optimize::Resolution`).
fn write_resolution(g: &hdf5::Group, r: &Resolution) -> hdf5::Result<()> {
    let s = &r.study;
    let elements: Vec<f64> = s.elements.iter().map(|n| *n as f64).collect();
    array(g, "mesh_elements", &[3], &elements)?;
    array(g, "reach_meshes", &[3], &s.reach)?;
    scalar(g, "reach_fine", s.reach[2])?;
    scalar(g, "reach_error", s.error().unwrap_or(f64::NAN))?;
    scalar(g, "reach_order", s.order().unwrap_or(f64::NAN))?;
    count(g, "elements", s.elements[0])?;
    string_attr(g, "mesh", r.verdict.name())?;
    let values = if s.local_optima {
        "local_optima"
    } else {
        "design"
    };
    string_attr(g, "mesh_values", values)?;
    let rejected: Vec<Vec<f64>> = r
        .rejected
        .iter()
        .map(|(n, coarse, fine)| vec![*n as f64, *coarse, *fine])
        .collect();
    if !rejected.is_empty() {
        rows(g, "rejected_designs", &rejected)?;
    }
    Ok(())
}

fn write_progress(file: &hdf5::File, p: &SearchProgress) -> hdf5::Result<()> {
    let g = file.create_group("search")?;
    count(&g, "samples_done", p.samples_done)?;
    count(&g, "polishes_done", p.polishes_done)?;
    count(&g, "evaluations", p.evaluations)?;
    let reach: Vec<f64> = p.leaders.iter().map(|l| l.0).collect();
    array(&g, "leader_reach", &[reach.len()], &reach)?;
    let pts: Vec<Vec<f64>> = p.leaders.iter().map(|l| l.1.clone()).collect();
    rows(&g, "leader_points", &pts)
}

/// What an interrupted optimize run kept: the problem text, the stop
/// reason, the search progress (its `best` left empty) and the shape
/// coefficients c1..cM of the best design so far.
#[derive(Debug, Clone, PartialEq)]
pub struct SavedSearch {
    /// The effective problem text the run was made from.
    pub problem: String,
    /// Completed, or interrupted (resumable).
    pub stop_reason: RunState,
    /// How far the search came.
    pub progress: SearchProgress,
    /// c1..cM of the best design so far.
    pub best: Vec<f64>,
}

/// Reads what [`write_arm_study`] kept of a search.
pub fn read_search(path: &Path) -> hdf5::Result<SavedSearch> {
    use hdf5::types::VarLenUnicode;
    let file = super::seal::open(path)?;
    let text = |name: &str| -> hdf5::Result<String> {
        Ok(file
            .attr(name)?
            .read_scalar::<VarLenUnicode>()?
            .as_str()
            .to_owned())
    };
    let g = file.group("search")?;
    let n =
        |name: &str| -> hdf5::Result<usize> { Ok(g.attr(name)?.read_scalar::<u64>()? as usize) };
    let reach = g.dataset("leader_reach")?.read_raw::<f64>()?;
    let flat = g.dataset("leader_points")?.read_raw::<f64>()?;
    let width = if reach.is_empty() {
        0
    } else {
        flat.len() / reach.len()
    };
    let leaders = reach
        .iter()
        .enumerate()
        .map(|(i, r)| (*r, flat[i * width..(i + 1) * width].to_vec()))
        .collect();
    Ok(SavedSearch {
        problem: text("problem")?,
        stop_reason: {
            let name = text("stop_reason")?;
            RunState::from_name(&name).ok_or_else(|| {
                hdf5::Error::from(format!("unknown stop_reason `{name}`").as_str())
            })?
        },
        progress: SearchProgress {
            samples_done: n("samples_done")?,
            polishes_done: n("polishes_done")?,
            evaluations: n("evaluations")?,
            leaders,
            best: None,
        },
        best: file
            .dataset("optimum/shape_coefficients")?
            .read_raw::<f64>()?,
    })
}
