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
//! path ended or lost stability; NaN when none). With `arm.directions`, the
//! group `/directions`: `alpha` (rad), `planar_reach`, `planar_error`,
//! `spatial_reach`, `spatial_error` (Richardson errors, NaN undecided),
//! `loading_path` (the spatial optimum's verdict per direction) and
//! `loading_path_end`. Root attributes `problem`, `stop_reason`,
//! `schema_version`.

use std::path::Path;

use super::arm_output::write_resolution;
use super::hdf5_output::{write_atomically, OutputError};
use super::store::StoreResult;
use crate::continuation::RunState;
use crate::study::arm::{DirectionComparison, PathVerdict, SpatialOptimum};

fn points(g: &mut super::store::Group, name: &str, v: &[[f64; 3]]) -> StoreResult<()> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    g.floats(name, &[v.len(), 3], &flat)
}

/// What a spatial arm run keeps.
#[derive(Debug, Clone, Copy)]
pub struct SpatialStudy<'a> {
    /// The optimum in the problem's direction.
    pub optimum: &'a SpatialOptimum,
    /// Its loading-path verdict (None: not run).
    pub verdict: Option<&'a PathVerdict>,
    /// The planar and spatial optima of `arm.directions`.
    pub directions: &'a [DirectionComparison],
}

fn verdict_text(verdict: Option<&PathVerdict>) -> (&'static str, String, f64) {
    match verdict {
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
    }
}

/// Writes a spatial arm study atomically.
pub fn write_spatial_arm(
    path: &Path,
    problem: &str,
    study: &SpatialStudy,
    stop_reason: RunState,
    force: bool,
) -> Result<(), OutputError> {
    let (optimum, verdict) = (study.optimum, study.verdict);
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
        let (name, detail, end) = verdict_text(verdict);
        g.attrs.set_text("loading_path", name);
        g.attrs.set_text("loading_path_detail", &detail);
        g.float("loading_path_end", end)?;
        if !study.directions.is_empty() {
            let g = root.create_group("directions");
            let d = study.directions;
            let column =
                |f: &dyn Fn(&DirectionComparison) -> f64| d.iter().map(f).collect::<Vec<_>>();
            g.floats("alpha", &[d.len()], &column(&|c| c.alpha))?;
            g.floats("planar_reach", &[d.len()], &column(&|c| c.planar.0))?;
            g.floats("planar_error", &[d.len()], &column(&|c| c.planar.1))?;
            g.floats("spatial_reach", &[d.len()], &column(&|c| c.spatial.0))?;
            g.floats("spatial_error", &[d.len()], &column(&|c| c.spatial.1))?;
            g.floats(
                "loading_path_end",
                &[d.len()],
                &column(&|c| verdict_text(Some(&c.verdict)).2),
            )?;
            let names: Vec<String> = d.iter().map(|c| c.verdict.name().to_owned()).collect();
            g.texts("loading_path", &names)?;
        }
        Ok(())
    })
}
