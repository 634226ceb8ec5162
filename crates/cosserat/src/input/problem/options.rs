//! The checked settings of the analyses: the solver (method, Newton,
//! integrator, collocation), the `[continuation]` family, the fixed shape
//! of a fixed-shape scene and the discretization of the second variation
//! (with enough unknowns per block for the eigenvalues asked).

use super::checks::{
    vector, within, COLLOCATION_TOLERANCE, INTEGRATION_TOLERANCE, NEWTON_TOLERANCE,
};
use super::rod::profile;
use super::sections::{ProblemFile, ProfileSpec, SolverSection, StabilitySection};
use super::{invalid, ProblemError};
use crate::bvp::newton::NewtonOptions;
use crate::bvp::{Method, SolverOptions, Strategy};
use std::sync::Arc;

use super::key_lens::{KeyLens, KeyPair, LinkedLens};
use crate::continuation::{
    ContinuationOptions, Family, Lens, Lens2, Parameter, ParameterOn, RodLens,
};
use crate::input::mesh::MeshKeys;
use crate::model::{EnergyCatalog, ModelChoice, ModelLevel, Profile, Rod};
use crate::numerics::integrator::Tolerances;
use crate::stability::{FixedShape, StabilityOptions};

/// The family of a `[continuation]` table, discretized by the solver's
/// shooting method at the scene's model level (raised to the spatial
/// model, when the level was chosen automatically, if the parameter takes
/// the rod out of its plane inside the bounds). `text` is the effective
/// problem text: a key that is not one of the library's parameters is
/// continued by rereading it ([`KeyLens`]).
pub(super) fn build_continuation(
    file: &ProblemFile,
    text: &str,
    catalog: &EnergyCatalog,
    rod: &Rod,
    model: &mut ModelChoice,
    options: &SolverOptions,
    shape: Option<&FixedShape>,
) -> Result<Option<(Family, ContinuationOptions)>, ProblemError> {
    let Some(section) = &file.continuation else {
        return Ok(None);
    };
    let (key, mut opts) = section.build()?;
    // The start is solved as the problem's [solver] says.
    opts.start_solver = Some(options.clone());
    eigenvalue_count("continuation", &opts.stability, rod)?;
    let (segments, stages) = match options.method {
        Method::Shooting => (1, None),
        Method::MultipleShooting { segments } => (segments, None),
        Method::Collocation { stages } => {
            if !(1..=10_000).contains(&section.intervals) {
                return Err(invalid(
                    "continuation.intervals",
                    format!("must be between 1 and 10000, got {}", section.intervals),
                ));
            }
            (section.intervals, Some(stages))
        }
    };
    if let Some(shape) = shape {
        check_shape_continuable(shape, rod)?;
    }
    let lens: Arc<dyn Lens> = match Parameter::from_key(&key) {
        _ if !section.link.is_empty() => Arc::new(linked_lens(section, &key, text, catalog)?),
        Some(parameter) => Arc::new(RodLens::new(native_base(file, rod, parameter)?, parameter)),
        None => Arc::new(KeyLens::new(&key, text, catalog)?),
    };
    if file.solver.model == "auto" {
        raise_level(model, lens.as_ref(), &opts);
    }
    check_measures(&opts, model, rod)?;
    let mut family = Family::of_lens(
        lens,
        rod.clone(),
        model.level,
        segments,
        options.integration,
    );
    if let Some(m) = stages {
        family = family.collocated(m);
    }
    // A parameter the energy cannot vary (a varying profile, an energy
    // without that profile) is refused here, not at the first point.
    family
        .rod_at(opts.start)
        .map_err(|e| invalid("continuation.parameter", e.to_string()))?;
    Ok(Some((family, opts)))
}

/// The lens of a parameter with `continuation.link`s: file keys only (a
/// library scaling already moves several numbers), and no curve (its
/// second parameter would be set without the links).
fn linked_lens(
    section: &crate::input::ContinuationSection,
    key: &str,
    text: &str,
    catalog: &EnergyCatalog,
) -> Result<LinkedLens, ProblemError> {
    if Parameter::from_key(key).is_some_and(|p| !p.is_file_key()) {
        return Err(invalid(
            "continuation.link",
            format!("`{key}` already scales several numbers; link file keys only"),
        ));
    }
    if section.curve.is_some() {
        return Err(invalid(
            "continuation.link",
            "a [continuation.curve] does not carry the links yet; continue the linked \
             parameter alone",
        ));
    }
    let links: Vec<(String, f64, f64)> = section
        .link
        .iter()
        .map(|l| (l.key.clone(), l.factor, l.offset))
        .collect();
    LinkedLens::new(key, &links, section.start, text, catalog)
}

/// The `[continuation.curve]` of a continued problem: the family's
/// parameter and the curve's as one [`Lens2`], the second's start value
/// and the options.
pub(super) fn build_curve(
    file: &ProblemFile,
    text: &str,
    catalog: &EnergyCatalog,
    rod: &Rod,
    opts: Option<&ContinuationOptions>,
) -> Result<Option<crate::study::Curve>, ProblemError> {
    let (Some(section), Some(opts)) = (&file.continuation, opts) else {
        return Ok(None);
    };
    let Some(curve) = &section.curve else {
        return Ok(None);
    };
    let first = section.parameter.trim();
    let (second, start, options) = curve.build(opts)?;
    if second == first {
        return Err(invalid(
            "continuation.curve.parameter",
            "must differ from continuation.parameter",
        ));
    }
    let pair: Arc<dyn Lens2> = match Parameter::from_key(first) {
        Some(Parameter::ClampAngle) if file.clamp.angle != 0.0 => {
            return Err(invalid(
                "continuation.curve",
                "clamp.angle as the first parameter of a curve turns the rods of the second \
                 parameter, which carry the file's clamp.angle: write clamp.angle = 0 (the \
                 continued angle is then absolute)",
            ))
        }
        Some(p) => {
            let lens: Arc<dyn Lens> = match Parameter::from_key(&second) {
                Some(Parameter::ClampAngle) => Arc::new(RodLens::new(
                    native_base(file, rod, Parameter::ClampAngle)?,
                    Parameter::ClampAngle,
                )),
                Some(q) => Arc::new(RodLens::new(rod.clone(), q)),
                None => Arc::new(
                    KeyLens::new(&second, text, catalog)
                        .map_err(|e| rename(e, "continuation.curve.parameter"))?,
                ),
            };
            Arc::new(ParameterOn::new(p, lens))
        }
        None => Arc::new(KeyPair::new(first, &second, text, catalog)?),
    };
    pair.rod_at([opts.start, start])
        .map_err(|e| invalid("continuation.curve.parameter", e.to_string()))?;
    Ok(Some(crate::study::Curve {
        pair,
        start,
        options,
    }))
}

/// A key's error named for the curve's key.
fn rename(e: ProblemError, field: &str) -> ProblemError {
    match e {
        ProblemError::Invalid { message, .. } => invalid(field, message),
        other => other,
    }
}

/// The base rod of a library parameter: the problem's rod, but for
/// `clamp.angle` (the parameter is the absolute angle) the unturned frame.
fn native_base(file: &ProblemFile, rod: &Rod, parameter: Parameter) -> Result<Rod, ProblemError> {
    if parameter != Parameter::ClampAngle {
        return Ok(rod.clone());
    }
    let mut clamp = rod.clamp().clone();
    clamp.frame = clamp
        .turned_frame(-file.clamp.angle)
        .map_err(|e| invalid("clamp.angle", e.to_string()))?;
    rod.clone()
        .with_clamp(clamp)
        .map_err(|e| invalid("clamp.angle", e.to_string()))
}

/// The integral measures need what they integrate: `turning` the planar
/// angle, `stored_energy` and `total_potential_energy` an energy that is
/// all of W (no shear part), the latter a tip whose rotation is either
/// free (no dead couple then: [`crate::stability::check_conservative`]) or
/// held (the couple does no work).
fn check_measures(
    opts: &ContinuationOptions,
    model: &ModelChoice,
    rod: &Rod,
) -> Result<(), ProblemError> {
    use crate::continuation::Measure;
    if opts.measures.contains(&Measure::Turning) && model.level != ModelLevel::Planar {
        return Err(invalid(
            "continuation.measures",
            format!(
                "`turning` is the planar turning angle ∫κ2 ds, but the scene runs {}; sample \
                 `tangent[i]@1` instead",
                model.reason
            ),
        ));
    }
    let shearable = rod.energy().strain_energy().is_some();
    for energy in [Measure::StoredEnergy, Measure::TotalPotentialEnergy] {
        if opts.measures.contains(&energy) && shearable {
            return Err(invalid(
                "continuation.measures",
                format!(
                    "`{}` integrates W(s, κ); a shearable rod's shear and extension energy is \
                     not in it",
                    energy.name()
                ),
            ));
        }
    }
    let integral = opts.measures.iter().find(|m| {
        matches!(
            m,
            Measure::Turning | Measure::StoredEnergy | Measure::TotalPotentialEnergy
        )
    });
    if let (Some(m), false) = (integral, rod.loads().point_loads.is_empty()) {
        // The measure's quadrature straddles the jump of n(s), and the
        // potential has no −F_k·r(s_k) term: refused, not approximate.
        return Err(invalid(
            "continuation.measures",
            format!(
                "`{}` is not computed with [[loads.point]] yet (its quadrature does not stop \
                 at the points, and the potential leaves out their work); sample \
                 `position[i]@σ` instead",
                m.name()
            ),
        ));
    }
    let spins = rod
        .support()
        .as_ref()
        .is_some_and(|s| matches!(s.rotation, crate::model::Freedom::Axial(_)));
    if opts.measures.contains(&Measure::TotalPotentialEnergy) && spins {
        return Err(invalid(
            "continuation.measures",
            "`total_potential_energy` leaves out the work of a dead tip couple, which is only \
             right where the tip's rotation is held; this support lets the tip spin about its \
             axis (support.rotation = \"axial\")",
        ));
    }
    Ok(())
}

/// Points of the bounds probed for a rod that leaves the plane.
const LEVEL_PROBES: u32 = 16;

/// An automatically chosen planar level raised to the spatial model when
/// the rod at some probed parameter value (the start, the bounds and
/// [`LEVEL_PROBES`] points between) cannot be planar; a point the probes
/// miss is refused at run time ([`crate::continuation::FamilyError::NeedsModel`]).
fn raise_level(model: &mut ModelChoice, lens: &dyn Lens, opts: &ContinuationOptions) {
    if model.level != ModelLevel::Planar {
        return;
    }
    let (lo, hi) = opts.bounds;
    let probes = (0..=LEVEL_PROBES)
        .map(|i| lo + (hi - lo) * f64::from(i) / f64::from(LEVEL_PROBES))
        .chain([opts.start]);
    for p in probes {
        let Ok(rod) = lens.rod_at(p) else { continue };
        let choice = ModelChoice::for_rod(&rod);
        if choice.level != ModelLevel::Planar {
            *model = ModelChoice {
                level: choice.level,
                reason: format!(
                    "{}: continuation.parameter = {} takes the rod out of the plane (at {p}: {})",
                    choice.level.name(),
                    lens.key(),
                    choice.reason
                ),
            };
            return;
        }
    }
}

/// A fixed shape's κ⁰ follows from the load; continuation needs a rod with
/// one κ⁰: only shapes on which the loads make no moment (κ⁰ = φ', e.g. a
/// straight column under an axial load) qualify.
fn check_shape_continuable(shape: &FixedShape, rod: &Rod) -> Result<(), ProblemError> {
    let fe_points: Vec<f64> = (0..=64)
        .map(|i| rod.length() * f64::from(i) / 64.0)
        .collect();
    let moment = shape
        .samples(rod, &fe_points)
        .map_err(|e| invalid("shape", e.to_string()))?
        .iter()
        .map(|p| p.moment.norm())
        .fold(0.0, f64::max);
    if moment > 1e-12 * rod.moment_scale() || !matches!(shape.turning_angle, Profile::Constant(_)) {
        return Err(invalid(
            "shape",
            "continuation from a fixed shape needs a straight shape on which the loads make no moment",
        ));
    }
    Ok(())
}

pub(super) fn build_shape(file: &ProblemFile) -> Result<Option<FixedShape>, ProblemError> {
    let Some(shape) = &file.shape else {
        return Ok(None);
    };
    let turning_angle = profile("shape.turning_angle", &shape.turning_angle)?;
    if file.energy.kind != "linear" {
        return Err(invalid(
            "shape",
            "a fixed-shape scene needs energy.kind = \"linear\" (K is then linear in the load)",
        ));
    }
    if file
        .energy
        .intrinsic_curvature
        .iter()
        .any(|p| *p != ProfileSpec::Constant(0.0))
    {
        return Err(invalid(
            "energy.intrinsic_curvature",
            "a fixed-shape scene derives κ⁰ from the shape and the load (paper (43)); remove it",
        ));
    }
    if file.loads.tip_couple != [0.0; 3] {
        return Err(invalid(
            "loads.tip_couple",
            "a fixed-shape scene takes forces only",
        ));
    }
    Ok(Some(FixedShape { turning_angle }))
}

/// The fewest unknowns a block of the second variation can have: the
/// in-plane block has one rotation per node but the clamped one
/// (elements × order), and a tip support removes up to six more
/// (three held translations, three held rotations).
pub(crate) fn fewest_block_unknowns(opts: &StabilityOptions, rod: &Rod) -> usize {
    let nodes = opts.elements().saturating_mul(opts.order());
    if rod.support().is_some() {
        nodes.saturating_sub(6)
    } else {
        nodes
    }
}

/// The eigenvalues asked per block exist on the mesh (a count beyond the
/// block's unknowns made the continuation tracker index past its columns).
pub(super) fn eigenvalue_count(
    table: &str,
    opts: &StabilityOptions,
    rod: &Rod,
) -> Result<(), ProblemError> {
    let most = fewest_block_unknowns(opts, rod);
    if opts.eigenvalues() > most {
        return Err(invalid(
            format!("{table}.eigenvalues"),
            format!(
                "{} eigenvalues per block, but the smallest block of {} elements of order {} \
                 has {most} unknowns{}: lower {table}.eigenvalues to at most {most} or raise \
                 {table}.elements",
                opts.eigenvalues(),
                opts.elements(),
                opts.order(),
                if rod.support().is_some() {
                    " (elements × order, less six held by the support)"
                } else {
                    " (elements × order)"
                },
            ),
        ));
    }
    Ok(())
}

pub(super) fn build_stability(s: &StabilitySection) -> Result<StabilityOptions, ProblemError> {
    MeshKeys {
        table: "stability",
        elements: s.elements,
        order: s.order,
        eigenvalues: s.eigenvalues,
        min_elements: 1,
    }
    .build()
}

pub(super) fn build_options(s: &SolverSection) -> Result<SolverOptions, ProblemError> {
    let method = match s.method.as_str() {
        "shooting" => Method::Shooting,
        "multiple-shooting" => {
            if s.segments < 1 {
                return Err(invalid("solver.segments", "must be at least 1"));
            }
            Method::MultipleShooting {
                segments: s.segments,
            }
        }
        "collocation" => {
            if !(1..=3).contains(&s.stages) {
                return Err(invalid("solver.stages", "must be 1, 2 or 3"));
            }
            Method::Collocation { stages: s.stages }
        }
        other => {
            return Err(invalid(
                "solver.method",
                format!(
                    "unknown method `{other}`; expected \"shooting\", \"multiple-shooting\" \
                     or \"collocation\""
                ),
            ))
        }
    };
    let defaults = crate::bvp::CollocationOptions::default();
    if s.max_intervals < defaults.intervals {
        return Err(invalid(
            "solver.max_intervals",
            format!("must be at least {}", defaults.intervals),
        ));
    }
    let collocation = crate::bvp::CollocationOptions {
        stages: s.stages,
        tolerance: within(
            "solver.collocation_tolerance",
            s.collocation_tolerance,
            COLLOCATION_TOLERANCE,
        )?,
        max_intervals: s.max_intervals,
        ..defaults
    };
    let strategy = match s.strategy.as_str() {
        "auto" => Strategy::Auto,
        "direct" => Strategy::Direct,
        "ramp" => Strategy::Ramp,
        other => {
            return Err(invalid(
                "solver.strategy",
                format!("unknown strategy `{other}`; expected \"auto\", \"direct\" or \"ramp\""),
            ))
        }
    };
    let tol = within(
        "solver.integration_tolerance",
        s.integration_tolerance,
        INTEGRATION_TOLERANCE,
    )?;
    if s.max_steps < 1 {
        return Err(invalid(
            "solver.max_steps",
            "must be at least 1 (the step budget of one integration; e.g. 100000)",
        ));
    }
    if s.output_points < 2 {
        return Err(invalid("solver.output_points", "must be at least 2"));
    }
    if s.max_iterations < 1 {
        return Err(invalid("solver.max_iterations", "must be at least 1"));
    }
    let initial_guess = match s.initial_curvature {
        Some(k) => Some(vector("solver.initial_curvature", k)?.as_slice().to_vec()),
        None => None,
    };
    let initial_reaction = s
        .initial_reaction
        .map(|r| vector("solver.initial_reaction", r))
        .transpose()?;
    Ok(SolverOptions {
        method,
        newton: NewtonOptions {
            tolerance: within("solver.tolerance", s.tolerance, NEWTON_TOLERANCE)?,
            max_iterations: s.max_iterations,
            ..Default::default()
        },
        integration: Tolerances {
            rtol: tol,
            atol: tol,
            max_steps: s.max_steps,
        },
        collocation,
        output_points: s.output_points,
        initial_guess,
        initial_reaction,
        strategy,
    })
}
