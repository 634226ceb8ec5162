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
//! `rejected_elements` (k: the mesh of each design given up on the way)
//! and `rejected_reach` (k×2: R̂ there, R̂ on 4× the elements); the
//! attribute `element_order` (the Lagrange order of those meshes' elements:
//! a search redone on a finer discretization may use order 2). The
//! mesh-converged optimum (`ArmOptimum::limit`, in `/optimum`):
//! `reach_limit` (R*(N → ∞), Richardson on three meshes of order-2
//! elements), `reach_limit_bound` (its bound), `limit_elements`,
//! `limit_meshes` (the optimum on each) and the attribute `limit_order`.
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

use super::hdf5_output::{write_atomically, OutputError};
use super::store::{Group, StoreError, StoreResult};
use crate::study::arm::{
    ArmOptimum, ClosestStraight, ReachMap, Resolution, SearchProgress, StraightArm,
};
use crate::study::arm::{LoadingVerdict, TaperedOptimum};

fn points(g: &mut Group, name: &str, v: &[[f64; 3]]) -> StoreResult<()> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    g.floats(name, &[v.len(), 3], &flat)
}

fn rows(g: &mut Group, name: &str, v: &[Vec<f64>]) -> StoreResult<()> {
    let width = v.first().map_or(0, std::vec::Vec::len);
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    g.floats(name, &[v.len(), width], &flat)
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
    write_atomically(path, force, |root| {
        root.attrs.set_text("problem", problem);
        root.attrs.set_text("stop_reason", study.stop_reason.name());
        let g = root.create_group("optimum");
        write_design(g, study.optimum)?;
        g.float("gamma_crit", study.optimum.critical_load)?;
        g.attrs
            .set_count("evaluations", study.optimum.evaluations as u64);
        if let Some(s) = study.straight {
            let g = root.create_group("straight");
            g.float("reach", s.reach)?;
            g.float("gamma_crit", s.gamma)?;
            g.float("clamp_angle", s.clamp_angle)?;
            points(g, "loaded_shape", &s.loaded_shape)?;
            g.attrs.set_text("stop_reason", stop_reason(s.interrupted));
            g.attrs.set_text("limit", s.limit.name());
        }
        if let Some(m) = study.map {
            let g = root.create_group("map");
            g.floats("reach", &[m.reach.len()], &m.reach)?;
            g.floats("load_factor", &[m.gamma.len()], &m.gamma)?;
            rows(g, "shape_coefficients", &m.shape_coefficients)?;
            rows(g, "curvature_coefficients", &m.curvature_coefficients)?;
            g.attrs.set_count("samples", m.samples as u64);
            g.attrs.set_text("stop_reason", stop_reason(m.interrupted));
        }
        for (name, q) in [
            ("closest_straight", study.closest),
            ("least_curvature", study.least_curvature),
        ] {
            if let Some(q) = q {
                let g = root.create_group(name);
                write_design(g, &q.optimum)?;
                g.attrs.set_count("index", q.index as u64);
                g.float("curvature_norm", q.curvature_norm)?;
            }
        }
        if let Some(p) = study.progress {
            write_progress(root, p)?;
        }
        Ok(())
    })
}

fn write_design(g: &mut Group, o: &ArmOptimum) -> StoreResult<()> {
    g.float("reach", o.design.reach)?;
    if let Some(r) = &o.resolution {
        write_resolution(g, r)?;
        g.attrs.set_count("element_order", o.mesh.order() as u64);
    }
    if let Some(l) = &o.limit {
        let (limit, bound) = l.converged().unwrap_or((f64::NAN, f64::NAN));
        g.float("reach_limit", limit)?;
        g.float("reach_limit_bound", bound)?;
        let elements: Vec<u64> = l.study.elements.iter().map(|n| *n as u64).collect();
        g.counts("limit_elements", &elements)?;
        g.floats("limit_meshes", &[3], &l.study.reach)?;
        g.attrs.set_count("limit_order", l.order as u64);
    }
    g.float("load_factor", o.design.gamma)?;
    let c = &o.design.shape_coefficients;
    g.floats("shape_coefficients", &[c.len()], c)?;
    let b = &o.curvature_coefficients;
    g.floats("curvature_coefficients", &[b.len()], b)?;
    points(g, "loaded_shape", &o.loaded_shape)?;
    points(g, "unloaded_shape", &o.unloaded_shape)?;
    let k = &o.intrinsic_curvature;
    g.floats("intrinsic_curvature", &[k.len()], k)
}

/// The discretization check of a design (`optimize::Resolution`).
pub(super) fn write_resolution(g: &mut Group, r: &Resolution) -> StoreResult<()> {
    let s = &r.study;
    let elements: Vec<u64> = s.elements.iter().map(|n| *n as u64).collect();
    g.counts("mesh_elements", &elements)?;
    g.floats("reach_meshes", &[3], &s.reach)?;
    g.float("reach_fine", s.reach[2])?;
    g.float("reach_error", s.error().unwrap_or(f64::NAN))?;
    g.float("reach_order", s.order().unwrap_or(f64::NAN))?;
    g.attrs.set_count("elements", s.elements[0] as u64);
    g.attrs.set_text("mesh", r.verdict.name());
    let values = if s.local_optima {
        "local_optima"
    } else {
        "design"
    };
    g.attrs.set_text("mesh_values", values);
    if !r.rejected.is_empty() {
        let elements: Vec<u64> = r.rejected.iter().map(|(n, _, _)| *n as u64).collect();
        g.counts("rejected_elements", &elements)?;
        let reach: Vec<Vec<f64>> = r
            .rejected
            .iter()
            .map(|(_, coarse, fine)| vec![*coarse, *fine])
            .collect();
        rows(g, "rejected_reach", &reach)?;
    }
    Ok(())
}

fn write_progress(root: &mut Group, p: &SearchProgress) -> StoreResult<()> {
    let g = root.create_group("search");
    g.attrs.set_count("samples_done", p.samples_done as u64);
    g.attrs.set_count("polishes_done", p.polishes_done as u64);
    g.attrs.set_count("evaluations", p.evaluations as u64);
    let reach: Vec<f64> = p.leaders.iter().map(|l| l.0).collect();
    g.floats("leader_reach", &[reach.len()], &reach)?;
    let pts: Vec<Vec<f64>> = p.leaders.iter().map(|l| l.1.clone()).collect();
    rows(g, "leader_points", &pts)
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
pub fn read_search(path: &Path) -> StoreResult<SavedSearch> {
    let file = super::seal::open(path)?;
    let g = file.group("search")?;
    let n = |name: &str| -> StoreResult<usize> { Ok(g.attrs.count(name)? as usize) };
    let reach = g.dataset("leader_reach")?.floats()?;
    let flat = g.dataset("leader_points")?.floats()?;
    let width = if reach.is_empty() {
        0
    } else {
        flat.len() / reach.len()
    };
    if width * reach.len() != flat.len() {
        return Err("leader_points does not have one row per leader".into());
    }
    let leaders = reach
        .iter()
        .enumerate()
        .map(|(i, r)| (*r, flat[i * width..(i + 1) * width].to_vec()))
        .collect();
    Ok(SavedSearch {
        problem: file.attrs.text("problem")?.to_owned(),
        stop_reason: {
            let name = file.attrs.text("stop_reason")?;
            RunState::from_name(name)
                .ok_or_else(|| StoreError::from(format!("unknown stop_reason `{name}`")))?
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
            .floats()?
            .to_vec(),
    })
}

/// A tapered-arm study (`[arm] taper`): the optimum and the verdict of its
/// loading path (None where the path was not computed).
pub struct TaperedStudy<'a> {
    /// The optimum.
    pub optimum: &'a TaperedOptimum,
    /// The loading path's verdict.
    pub loading: Option<LoadingVerdict>,
}

/// Writes a tapered-arm study atomically: `/optimum/` as for the prismatic
/// arm (`reach`, `load_factor`, `gamma_crit` — the designed rod's by the
/// library's fixed-shape pencil —, `shape_coefficients`, `loaded_shape`,
/// `unloaded_shape`, `intrinsic_curvature`, and the mesh study of the
/// optimum re-polished on N, 2N, 4N elements: `mesh_elements`,
/// `reach_meshes`, `reach_fine` on 4N, `reach_error` and `reach_order` by
/// Richardson) with the section: `section` (A at the knots, unit volume),
/// `section_knots` (s̄ of the knots), `section_profile` (A at the shape
/// points); the joint ascent's `projected_gradient`; attributes
/// `elements`, `min_section`, `critical_block`, `evaluations`, `ascent`
/// (how the joint ascent ended: `converged`, `flat`, `no_gradient`,
/// `capped`), `ascent_iterations`, `loading_path` (the verdict:
/// `reaches_design`, `loses_stability`, `other_equilibrium`, `undecided`,
/// or `not_computed`) and `loading_path_value` (the load factor where
/// stability is lost, the tip's miss per L, or where the path ended);
/// `/prismatic/` the prismatic optimum the search started from (`reach`,
/// `load_factor`, `shape_coefficients`).
pub fn write_tapered_arm(
    path: &Path,
    problem: &str,
    study: &TaperedStudy,
    force: bool,
) -> Result<(), OutputError> {
    let o = study.optimum;
    write_atomically(path, force, |root| {
        root.attrs.set_text("problem", problem);
        root.attrs
            .set_text("stop_reason", RunState::Completed.name());
        let g = root.create_group("optimum");
        g.float("reach", o.design.reach)?;
        let m = &o.mesh;
        let elements: Vec<u64> = m.elements.iter().map(|n| *n as u64).collect();
        g.counts("mesh_elements", &elements)?;
        g.floats("reach_meshes", &[3], &m.reach)?;
        g.float("reach_fine", m.reach[2])?;
        g.float("reach_error", o.reach_error())?;
        g.float("reach_order", m.order().unwrap_or(f64::NAN))?;
        g.float("projected_gradient", o.ascent.projected_gradient)?;
        g.float("load_factor", o.design.gamma)?;
        g.float("gamma_crit", o.critical_load)?;
        let c = &o.design.shape_coefficients;
        g.floats("shape_coefficients", &[c.len()], c)?;
        points(g, "loaded_shape", &o.loaded_shape)?;
        points(g, "unloaded_shape", &o.unloaded_shape)?;
        let k = &o.intrinsic_curvature;
        g.floats("intrinsic_curvature", &[k.len()], k)?;
        let a = o.section.values();
        g.floats("section", &[a.len()], a)?;
        let s = o.section.knots();
        g.floats("section_knots", &[s.len()], &s)?;
        let p = &o.section_at_points;
        g.floats("section_profile", &[p.len()], p)?;
        g.float("min_section", o.min_section)?;
        g.attrs.set_count("elements", o.elements as u64);
        g.attrs.set_text("critical_block", o.block.name());
        g.attrs.set_count("evaluations", o.evaluations as u64);
        g.attrs.set_text("ascent", o.ascent.end.name());
        g.attrs
            .set_count("ascent_iterations", o.ascent.iterations as u64);
        let (verdict, value) = match study.loading {
            None => ("not_computed", f64::NAN),
            Some(v) => (v.name(), v.value()),
        };
        g.attrs.set_text("loading_path", verdict);
        g.float("loading_path_value", value)?;
        let g = root.create_group("prismatic");
        g.float("reach", o.prismatic.reach)?;
        g.float("load_factor", o.prismatic.gamma)?;
        let c = &o.prismatic.shape_coefficients;
        g.floats("shape_coefficients", &[c.len()], c)?;
        Ok(())
    })
}
