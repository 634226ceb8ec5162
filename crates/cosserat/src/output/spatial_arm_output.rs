//! Spatial longest-arm results as HDF5 (`[arm] spatial = true`, issue 20):
//! the group `/spatial` with `reach`, `gamma_crit` (the critical load
//! factor of the loaded shape, also the design load), `design` (the
//! searched vector c2..cM, a.., t.., ψ), `bend_coefficients`,
//! `bending_coefficients`, `twist_coefficients` (Taylor coefficients of
//! κ̄1, κ̄2 = φ', κ̄3), `roll` (rad), `clamp_frame` (3×3, columns d1(0),
//! d2(0), d3(0)), `shape_s` (arc lengths of the shape points),
//! `loaded_shape` and `unloaded_shape` (n×3, scaled by √γ),
//! `intrinsic_curvature` (n×3, κ̄⁰ body components), the mesh check as for
//! planar arms (`mesh_elements`, `reach_meshes`, `reach_fine`,
//! `reach_error`, `reach_order`, attributes `elements`, `mesh`,
//! `mesh_values`), and the loading-path verdict: attribute `loading_path`
//! (`reaches`, `misses`, `undecided` or `not_run`), `loading_path_detail`
//! (text) and the dataset `loading_path_end` (the load factor where the
//! path ended or lost stability; NaN when none). Root attributes `problem`,
//! `stop_reason`, `schema_version`.

use std::path::Path;

use super::arm_output::write_resolution;
use super::hdf5_output::{write_atomically, OutputError};
use super::store::StoreResult;
use crate::continuation::RunState;
use crate::study::arm::{PathVerdict, SpatialOptimum};

fn points(g: &mut super::store::Group, name: &str, v: &[[f64; 3]]) -> StoreResult<()> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    g.floats(name, &[v.len(), 3], &flat)
}

/// Writes a spatial arm's optimum and its loading-path verdict (None: not
/// run) atomically.
pub fn write_spatial_arm(
    path: &Path,
    problem: &str,
    optimum: &SpatialOptimum,
    verdict: Option<&PathVerdict>,
    stop_reason: RunState,
    force: bool,
) -> Result<(), OutputError> {
    write_atomically(path, force, |root| {
        root.attrs.set_text("problem", problem);
        root.attrs.set_text("stop_reason", stop_reason.name());
        let g = root.create_group("spatial");
        let d = &optimum.design;
        g.float("reach", d.reach)?;
        g.float("gamma_crit", d.gamma)?;
        g.floats("design", &[d.parameters.len()], &d.parameters)?;
        let names = [
            "bend_coefficients",
            "bending_coefficients",
            "twist_coefficients",
        ];
        for (name, c) in names.iter().zip(&d.curvature_coefficients) {
            g.floats(name, &[c.len()], c)?;
        }
        g.float("roll", d.roll)?;
        let q: Vec<f64> = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| d.clamp_frame[(i, j)])
            .collect();
        g.floats("clamp_frame", &[3, 3], &q)?;
        g.floats("shape_s", &[optimum.points.len()], &optimum.points)?;
        points(g, "loaded_shape", &optimum.loaded_shape)?;
        points(g, "unloaded_shape", &optimum.unloaded_shape)?;
        points(g, "intrinsic_curvature", &optimum.intrinsic_curvature)?;
        write_resolution(g, &optimum.resolution)?;
        g.attrs.set_count("evaluations", optimum.evaluations as u64);
        let (name, detail, end) = match verdict {
            None => ("not_run", String::new(), f64::NAN),
            Some(v @ PathVerdict::Reaches { miss }) => (
                v.name(),
                format!("reaches the design, tip {miss:.3e} L from it"),
                1.0,
            ),
            Some(v @ PathVerdict::Misses { parameter, reason }) => {
                (v.name(), reason.clone(), *parameter)
            }
            Some(v @ PathVerdict::Undecided(why)) => (v.name(), why.clone(), f64::NAN),
        };
        g.attrs.set_text("loading_path", name);
        g.attrs.set_text("loading_path_detail", &detail);
        g.float("loading_path_end", end)?;
        Ok(())
    })
}
