//! The checked rod: geometry, stored energy, clamp and the model level.
//!
//! The length lies in [`LENGTH_RANGE`]; the stiffness profiles are
//! positive, with max/min of the bending and torsional stiffnesses at most
//! [`MAX_STIFFNESS_RATIO`] = 1/(4ε); shear stiffnesses S = (kGA, kGA, EA)
//! are positive and finite; the clamp frame (d1, d3) is orthonormal to
//! 1e-9 (|d1| = |d3| = 1, d1·d3 = 0) and turned by `clamp.angle` about
//! d2, d3 towards d1.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::checks::{finite, load_vector, magnitude, vector};
use super::sections::{ClampSection, EnergySection, PointLoadSection, ProblemFile, ProfileSpec};
use super::{invalid, ProblemError};
use crate::model::{
    Clamp, DeadLoads, EnergyCatalog, EnergySpec, ModelChoice, ModelError, ModelLevel, PointLoad,
    Profile, Rod, Shearable, StoredEnergy,
};

pub(super) fn profile(field: &str, spec: &ProfileSpec) -> Result<Profile, ProblemError> {
    let p = match spec {
        ProfileSpec::Constant(c) => Profile::Constant(*c),
        ProfileSpec::Polynomial { polynomial } => {
            if polynomial.is_empty() {
                return Err(invalid(
                    field,
                    "a polynomial needs at least one coefficient",
                ));
            }
            Profile::Polynomial(polynomial.clone())
        }
        ProfileSpec::Table { s, values } => {
            if s.len() < 2 || s.len() != values.len() {
                return Err(invalid(
                    field,
                    format!(
                        "a table needs at least two points and as many values as s ({} s, {} values)",
                        s.len(),
                        values.len()
                    ),
                ));
            }
            if !s.windows(2).all(|w| w[1] > w[0]) {
                return Err(invalid(format!("{field}.s"), "must be strictly increasing"));
            }
            // Shape checked above with its keys; a refusal all the same is
            // named by the profile's key.
            Profile::table(s.clone(), values.clone()).map_err(|e| invalid(field, e.to_string()))?
        }
    };
    if !p.is_finite() {
        return Err(invalid(field, "must contain finite numbers only"));
    }
    let numbers: Vec<f64> = match spec {
        ProfileSpec::Constant(c) => vec![*c],
        ProfileSpec::Polynomial { polynomial } => polynomial.clone(),
        ProfileSpec::Table { s, values } => s.iter().chain(values).copied().collect(),
    };
    for v in numbers {
        magnitude(field, v)?;
    }
    Ok(p)
}

pub(super) fn build_rod(file: &ProblemFile, catalog: &EnergyCatalog) -> Result<Rod, ProblemError> {
    let length = finite("rod.length", file.rod.length)?;
    if length <= 0.0 {
        return Err(invalid(
            "rod.length",
            format!(
                "must be positive, got {length} (accepted: [{:e}, {:e}] in the file's length \
                 unit)",
                LENGTH_RANGE.0, LENGTH_RANGE.1
            ),
        ));
    }
    if !(LENGTH_RANGE.0..=LENGTH_RANGE.1).contains(&length) {
        return Err(invalid(
            "rod.length",
            format!(
                "{length} is outside [{:e}, {:e}]: positions (of order L) and curvatures (of \
                 order 1/L) are integrated with one absolute tolerance, so a length far from 1 \
                 loses digits (at 1e-320 the finite elements divide by zero); choose the length \
                 unit so that L is near 1 (any consistent units work)",
                LENGTH_RANGE.0, LENGTH_RANGE.1
            ),
        ));
    }
    let mut energy = build_energy(&file.energy, length, catalog)?;
    if let Some(shear) = file.energy.shear {
        if energy.strain_energy().is_some() {
            return Err(invalid(
                "energy.shear",
                "the energy already reads the shear-extension strains v1, v2, v3 (its own \
                 W(s, k, v)); write the shear and extension terms in the formula, or drop \
                 v1..v3 from it"
                    .to_owned(),
            ));
        }
        // A level forced below Cosserat takes the unshearable limit.
        if !matches!(
            file.solver.model.as_str(),
            "planar" | "kirchhoff" | "spatial"
        ) {
            // Checked by shear_stiffness with its keys; a refusal all the
            // same names the component.
            energy = Arc::new(Shearable::new(energy, shear_stiffness(shear)?).map_err(
                |e| match e {
                    ModelError::Stiffness { index, .. } => {
                        invalid(format!("energy.shear[{index}]"), e.to_string())
                    }
                    _ => invalid("energy.shear", e.to_string()),
                },
            )?);
        }
    }
    let clamp = build_clamp(&file.clamp)?;
    let support = file
        .support
        .as_ref()
        .map(|s| s.build(&clamp, length))
        .transpose()?;
    let loads = DeadLoads {
        tip_force: load_vector("loads.tip_force", file.loads.tip_force)?,
        tip_couple: load_vector("loads.tip_couple", file.loads.tip_couple)?,
        distributed_force: load_vector("loads.distributed_force", file.loads.distributed_force)?,
        point_loads: point_loads(&file.loads.point, length)?,
    };
    // Every value was checked above with its key and message; a refusal
    // all the same is named by the key it comes from.
    Rod::new(length, energy, clamp, loads, support)
        .map_err(|e| invalid(model_key(&e), e.to_string()))
}

/// The `[[loads.point]]` tables as point loads: each `s` finite and
/// inside (0, L), each force and couple a load vector. Which solvers carry
/// a couple's moment jump is checked with the solver options
/// (`options.rs`), never a load silently dropped.
fn point_loads(points: &[PointLoadSection], length: f64) -> Result<Vec<PointLoad>, ProblemError> {
    points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let key = format!("loads.point[{k}]");
            let s = finite(&format!("{key}.s"), p.s)?;
            if !(s > 0.0 && s < length) {
                return Err(invalid(
                    format!("{key}.s"),
                    format!(
                        "must lie inside the rod, 0 < s < L = {length}, got {s} (a load at an \
                         end is loads.tip_force, or a reaction of the clamp)"
                    ),
                ));
            }
            Ok(PointLoad {
                s,
                force: load_vector(&format!("{key}.force"), p.force)?,
                couple: load_vector(&format!("{key}.couple"), p.couple)?,
            })
        })
        .collect()
}

/// The problem-file key a refused model value comes from.
fn model_key(e: &ModelError) -> &'static str {
    match e {
        ModelError::Length(_) => "rod.length",
        ModelError::NotFinite { what, .. } => match *what {
            "tip force" => "loads.tip_force",
            "tip couple" => "loads.tip_couple",
            "distributed force" => "loads.distributed_force",
            "clamp position" => "clamp.position",
            "support position" => "support.position",
            _ => "support.axis",
        },
        ModelError::Axis { .. } => "support.axis",
        ModelError::PointLoad { .. } => "loads.point",
        ModelError::Frame { .. } => "clamp.d3",
        _ => "energy",
    }
}

/// S = (k G A, k G A, E A): positive and finite.
pub(super) fn shear_stiffness(shear: [f64; 3]) -> Result<nalgebra::Vector3<f64>, ProblemError> {
    for (i, v) in shear.iter().enumerate() {
        let field = format!("energy.shear[{i}]");
        let v = magnitude(&field, *v)?;
        if v <= 0.0 {
            return Err(invalid(field, format!("must be positive, got {v}")));
        }
    }
    Ok(nalgebra::Vector3::from(shear))
}

/// The energy named by `energy.kind` in `catalog`, from the validated
/// profiles and parameters (`energy.quartic` is a shorthand for
/// `energy.parameters.quartic`).
pub(super) fn build_energy(
    e: &EnergySection,
    length: f64,
    catalog: &EnergyCatalog,
) -> Result<Arc<dyn StoredEnergy>, ProblemError> {
    let mut spec = EnergySpec {
        stiffness: Default::default(),
        intrinsic_curvature: Default::default(),
        parameters: BTreeMap::default(),
        density: e.density.clone(),
    };
    let mut softest: Option<(f64, String)> = None;
    let mut stiffest: Option<(f64, String)> = None;
    for i in 0..3 {
        let field = format!("energy.stiffness[{i}]");
        spec.stiffness[i] = profile(&field, &e.stiffness[i])?;
        // Exact where the profile allows (Profile::extremes_on): a table at
        // its knots, a polynomial at the roots of its derivative, with a
        // certified lower bound.
        let x = spec.stiffness[i].extremes_on(length);
        if x.min.is_nan() || x.min <= 0.0 {
            return Err(invalid(
                field,
                format!(
                    "must be positive on [0, L], but its minimum is {:.6e} at s = {}; make the \
                     profile positive on the whole rod",
                    x.min, x.argmin
                ),
            ));
        }
        if x.min_lower <= 0.0 {
            return Err(invalid(
                field,
                format!(
                    "its minimum {:.6e} at s = {} is within rounding ({:.1e}) of zero, so it cannot be \
                     certified positive; make the profile clearly positive",
                    x.min,
                    x.argmin,
                    x.min - x.min_lower
                ),
            ));
        }
        if softest.as_ref().is_none_or(|(v, _)| x.min < *v) {
            softest = Some((x.min, field.clone()));
        }
        if stiffest.as_ref().is_none_or(|(v, _)| x.max > *v) {
            stiffest = Some((x.max, field.clone()));
        }
        spec.intrinsic_curvature[i] = profile(
            &format!("energy.intrinsic_curvature[{i}]"),
            &e.intrinsic_curvature[i],
        )?;
    }
    if let (Some((lo, soft)), Some((hi, stiff))) = (softest, stiffest) {
        if hi / lo > MAX_STIFFNESS_RATIO {
            return Err(invalid(
                soft,
                format!(
                    "the stiffness ratio {:.3e} ({stiff} up to {hi:e}, this down to {lo:e}) \
                     exceeds {MAX_STIFFNESS_RATIO:.3e} = 1/(4ε): the softer stiffness is then \
                     below four rounding units of the stiffer one in the sums of the equations \
                     and the second variation, and is lost; a stiffness that large is the \
                     constraint limit — keep the ratio below it",
                    hi / lo
                ),
            ));
        }
    }
    for (name, value) in &e.parameters {
        let v = magnitude(&format!("energy.parameters.{name}"), *value)?;
        spec.parameters.insert(name.clone(), v);
    }
    if let Some(c) = e.quartic {
        let c = magnitude("energy.quartic", c)?;
        if spec.parameters.insert("quartic".into(), c).is_some() {
            return Err(invalid(
                "energy.quartic",
                "given twice (also as energy.parameters.quartic)",
            ));
        }
    }
    let shorthand = e.quartic.is_some();
    match catalog.build(&e.kind, &spec) {
        Some(Ok(energy)) => Ok(energy),
        Some(Err(err)) => {
            let field = if shorthand && err.field == "energy.parameters.quartic" {
                "energy.quartic".to_owned()
            } else {
                err.field
            };
            Err(invalid(field, err.message))
        }
        None => Err(invalid(
            "energy.kind",
            format!(
                "unknown energy `{}`; registered: {}",
                e.kind,
                catalog.names().join(", ")
            ),
        )),
    }
}

/// The accepted rod lengths (in the file's length unit).
pub const LENGTH_RANGE: (f64, f64) = (1e-6, 1e6);

/// The largest ratio of the stiffest to the softest bending or torsional
/// stiffness anywhere on the rod: 1/(4ε) ≈ 1.1e15.
pub const MAX_STIFFNESS_RATIO: f64 = 0.25 / f64::EPSILON;

/// Orthonormality tolerance of the clamp frame.
pub(super) const FRAME_TOLERANCE: f64 = 1e-9;

pub(super) fn build_clamp(c: &ClampSection) -> Result<Clamp, ProblemError> {
    let position = vector("clamp.position", c.position)?;
    let d1 = vector("clamp.d1", c.d1)?;
    let d3 = vector("clamp.d3", c.d3)?;
    for (name, d) in [("clamp.d1", d1), ("clamp.d3", d3)] {
        if (d.norm() - 1.0).abs() > FRAME_TOLERANCE {
            return Err(invalid(
                name,
                format!("must be a unit vector, |{name}| = {}", d.norm()),
            ));
        }
    }
    if d1.dot(&d3).abs() > FRAME_TOLERANCE {
        return Err(invalid(
            "clamp.d3",
            format!("must be orthogonal to clamp.d1, d1·d3 = {}", d1.dot(&d3)),
        ));
    }
    let angle = finite("clamp.angle", c.angle)?;
    // Unit and orthogonal to 1e-9 above, so within Frame::TOLERANCE; a
    // frame refused all the same is named by its directors.
    let clamp = Clamp::new(position, d1, d3).map_err(|e| invalid("clamp.d3", e.to_string()))?;
    let mut frame = clamp
        .turned_frame(angle)
        .map_err(|e| invalid("clamp.angle", e.to_string()))?;
    if let Some(turn) = &c.turn {
        frame = turn.apply("clamp.turn", &frame)?;
    }
    Ok(Clamp {
        frame,
        hinge: c.hinge,
        ..clamp
    })
}

/// The model level: automatic, or forced by `solver.model`. `sheared` says
/// whether the file gave shear stiffnesses (dropped by `build_rod` when a
/// lower level is forced, which the reason then says).
pub(super) fn choose_model(
    rod: &Rod,
    model: &str,
    sheared: bool,
) -> Result<ModelChoice, ProblemError> {
    let level = match model {
        "auto" => return Ok(ModelChoice::for_rod(rod)),
        "planar" => ModelLevel::Planar,
        "kirchhoff" | "spatial" => ModelLevel::Kirchhoff,
        "cosserat" => ModelLevel::Cosserat,
        other => {
            return Err(invalid(
                "solver.model",
                format!(
                    "unknown model `{other}`; expected \"auto\", \"planar\", \"kirchhoff\" \
                     or \"cosserat\""
                ),
            ))
        }
    };
    let mut choice = ModelChoice::forced(rod, level).map_err(|m| invalid("solver.model", m))?;
    if sheared && level != ModelLevel::Cosserat {
        choice.reason += "; energy.shear ignored (the unshearable, inextensible limit)";
    }
    Ok(choice)
}
