//! Problem files: a TOML description of a rod scene and how to solve it.
//!
//! Every table rejects unknown keys; syntax errors carry line and column;
//! physical validation names the offending field. `--set key=value`
//! overrides are applied to the parsed document before it is read, so they
//! go through exactly the same checks. The reference of every key is in
//! docs/problem-files.md.
//!
//! Submodules: `sections` (the serde structs of the tables as written),
//! `overrides` (`--set`), `checks` (finite numbers, magnitudes, ranges),
//! `rod` (the checked rod, energy, clamp and model level) and `options`
//! (solver, continuation, fixed shape and stability settings); this module
//! reads the file and assembles the checked [`Problem`].

mod checks;
mod key_lens;
mod options;
mod overrides;
mod rod;
mod sections;
mod stages;

use std::path::Path;

use crate::bvp::{Method, SolverOptions};
use crate::input::strict;
use crate::input::sweep_section::SweepSection;
use crate::model::{EnergyCatalog, ModelChoice, ModelLevel, Rod};
pub use crate::study::Problem;
pub(crate) use checks::{within, NEWTON_TOLERANCE};
use options::{
    build_continuation, build_curve, build_options, build_shape, build_stability, eigenvalue_count,
};
use overrides::apply_overrides;
use rod::{build_rod, choose_model};
pub use sections::{ProblemFile, ProfileSpec};

/// Why a problem could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ProblemError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The problem file.
        path: String,
        /// The error of the read.
        source: std::io::Error,
    },
    /// TOML syntax, an unknown or missing key, or a wrong type.
    #[error("{0}")]
    Parse(String),
    /// A `--set` override that cannot be applied.
    #[error("--set {assignment}: {message}")]
    Override {
        /// The `KEY=VALUE` as given.
        assignment: String,
        /// Why it cannot be applied.
        message: String,
    },
    /// A value that is well-formed but not physical or not consistent.
    #[error("{field}: {message}")]
    Invalid {
        /// The dotted key of the offending value (e.g. `rod.length`).
        field: String,
        /// What is wrong with it.
        message: String,
    },
}

pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> ProblemError {
    ProblemError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}

impl Problem {
    /// Reads a problem file and applies `key=value` overrides.
    pub fn from_path(path: &Path, overrides: &[String]) -> Result<Problem, ProblemError> {
        Problem::from_path_in(path, overrides, &EnergyCatalog::standard())
    }

    /// [`Problem::from_path`] with the energies of `catalog` (a program's
    /// own energies by name: examples/custom_energy.rs).
    pub fn from_path_in(
        path: &Path,
        overrides: &[String],
        catalog: &EnergyCatalog,
    ) -> Result<Problem, ProblemError> {
        let text = read_problem_file(path)?;
        Problem::from_str_in(&text, overrides, catalog)
    }

    /// Reads a problem from TOML text and applies `key=value` overrides.
    pub fn from_str_with(text: &str, overrides: &[String]) -> Result<Problem, ProblemError> {
        Problem::from_str_in(text, overrides, &EnergyCatalog::standard())
    }

    /// [`Problem::from_str_with`] with the energies of `catalog`.
    pub fn from_str_in(
        text: &str,
        overrides: &[String],
        catalog: &EnergyCatalog,
    ) -> Result<Problem, ProblemError> {
        if text.len() > MAX_PROBLEM_BYTES as usize {
            return Err(ProblemError::Parse(format!(
                "the problem text is {} bytes, more than the {MAX_PROBLEM_BYTES} a problem file \
                 may have; a problem file describes a rod, not data",
                text.len()
            )));
        }
        let text = apply_overrides(text, overrides)?;
        let file: ProblemFile = strict::parse(&text)?;
        let rod = build_rod(&file, catalog)?;
        let mut model = choose_model(&rod, &file.solver.model, file.energy.shear.is_some())?;
        let options = build_options(&file.solver)?;
        guesses_fit(&rod, &options)?;
        point_couples_carried(&rod, &model, &options)?;
        let shape = build_shape(&file)?;
        if shape.is_some() && !rod.loads().point_loads.is_empty() {
            // The fixed-shape critical load's moments are built from the
            // tip and distributed loads only.
            return Err(invalid(
                "loads.point",
                "a [shape] (fixed-shape critical load) does not take point forces yet",
            ));
        }
        let stability = build_stability(&file.stability)?;
        eigenvalue_count("stability", &stability, &rod)?;
        let continuation = build_continuation(
            &file,
            &text,
            catalog,
            &rod,
            &mut model,
            &options,
            shape.as_ref(),
        )?;
        let curve = build_curve(
            &file,
            &text,
            catalog,
            &rod,
            continuation.as_ref().map(|(_, o)| o),
        )?;
        if rod.clamp().hinge && model.level != ModelLevel::Planar {
            return Err(invalid(
                "clamp.hinge",
                format!(
                    "a hinged base needs the planar model, but the scene runs {}",
                    model.reason
                ),
            ));
        }
        let arm = file.arm.as_ref().map(|a| a.build(&rod)).transpose()?;
        let arm_scene = file
            .arm
            .as_ref()
            .map(|a| a.scene(&rod).map(|s| (s, a.map_samples)))
            .transpose()?;
        let (arm_taper, arm_spatial) =
            arm_extensions(&file, &rod, arm.as_ref(), arm_scene.as_ref())?;
        let sweep = file.sweep.as_ref().map(SweepSection::build).transpose()?;
        let problem = Problem {
            rod,
            model,
            options,
            text,
            shape,
            stability,
            continuation,
            curve,
            arm,
            arm_scene,
            arm_taper,
            arm_spatial,
            sweep,
            stage_keys: vec![],
        };
        // Before any command allocates: what the sizes ask for must fit.
        super::memory::check(&problem)?;
        let count = file.continuation.as_ref().map_or(0, |c| c.stage.len());
        if count == 0 {
            return Ok(problem);
        }
        let first_key = problem.continuation.as_ref().map(|(f, _)| f.key());
        let stage_keys = stages::check_stages(&problem, first_key.as_deref(), count, catalog)?;
        Ok(Problem {
            stage_keys,
            ..problem
        })
    }
}

/// The largest problem file read: 1 MiB (the shipped ones are under 3 KiB).
pub const MAX_PROBLEM_BYTES: u64 = 1 << 20;

/// The text of a problem file, refusing before reading anything what is not
/// a regular file (a directory; a device such as /dev/zero or a FIFO would
/// be read without end, or block) or is larger than [`MAX_PROBLEM_BYTES`];
/// at most that many bytes are read even if the file grows meanwhile.
/// The extensions of `[arm]` beyond the paper's planar prismatic arm: a
/// tapered section (`arm.taper`) or spatial loaded shapes (`arm.spatial`),
/// never both (the section's optimizer works on planar shapes), and a
/// spatial arm never in a sweep (the sweep's arm job is planar).
#[allow(clippy::type_complexity)]
fn arm_extensions(
    file: &ProblemFile,
    rod: &crate::model::Rod,
    arm: Option<&(
        crate::study::arm::ArmProblem,
        crate::study::arm::SearchOptions,
        bool,
    )>,
    arm_scene: Option<&(crate::study::arm::ArmScene, usize)>,
) -> Result<
    (
        Option<crate::study::arm::taper::Taper>,
        Option<crate::study::arm::SpatialArm>,
    ),
    ProblemError,
> {
    let arm_taper = match (&file.arm, arm) {
        (Some(a), Some((p, _, _))) => a.taper(rod, p)?,
        _ => None,
    };
    let arm_spatial = match (&file.arm, arm, arm_scene) {
        (Some(section), Some((planar, _, _)), Some((scene, _))) => {
            section.spatial_arm(planar, scene)?
        }
        _ => None,
    };
    if arm_spatial.is_some() && arm_taper.is_some() {
        return Err(invalid(
            "arm.taper",
            "tapered sections are optimized for planar arms only; remove arm.taper or \
             arm.spatial",
        ));
    }
    if arm_spatial.is_some() && file.sweep.is_some() {
        return Err(invalid(
            "arm.spatial",
            "a sweep runs planar arms only; remove [sweep] or arm.spatial",
        ));
    }
    Ok((arm_taper, arm_spatial))
}

fn read_problem_file(path: &Path) -> Result<String, ProblemError> {
    use std::io::Read;
    let fail = |message: String| ProblemError::Read {
        path: path.display().to_string(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, message),
    };
    let io = |source: std::io::Error| ProblemError::Read {
        path: path.display().to_string(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(fail(
            "is a directory; give a problem file (TOML), e.g. problems/cantilever_tip_load.toml"
                .into(),
        ));
    }
    if !meta.is_file() {
        return Err(fail(
            "is not a regular file (a device, FIFO or socket would be read without end); give a \
             problem file (TOML)"
                .into(),
        ));
    }
    if meta.len() > MAX_PROBLEM_BYTES {
        return Err(fail(format!(
            "is {} bytes, more than the {MAX_PROBLEM_BYTES} (1 MiB) a problem file may have; is \
             it the right file?",
            meta.len()
        )));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_PROBLEM_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_PROBLEM_BYTES {
        return Err(fail(format!(
            "grew beyond {MAX_PROBLEM_BYTES} bytes (1 MiB) while being read"
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        fail(format!(
            "is not UTF-8 text (byte {}); a problem file is TOML text",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// Point couples are carried by shooting and multiple shooting (the state
/// jumps at s_k, `RodEquations::jump`), on the planar, Kirchhoff and
/// quadratic Cosserat paths: refused by the key of the first couple
/// elsewhere, never dropped.
fn point_couples_carried(
    rod: &Rod,
    model: &ModelChoice,
    options: &SolverOptions,
) -> Result<(), ProblemError> {
    let Some(k) = rod
        .loads()
        .point_loads
        .iter()
        .position(|p| p.couple != nalgebra::Vector3::zeros())
    else {
        return Ok(());
    };
    let key = format!("loads.point[{k}].couple");
    if let Method::Collocation { .. } = options.method {
        return Err(invalid(
            key,
            "a point couple makes the bending moment jump, which collocation does not carry \
             yet; it needs solver.method = \"shooting\" or \"multiple-shooting\"",
        ));
    }
    let e = rod.energy();
    let general = model.level == ModelLevel::Cosserat
        && e.shear_stiffness(0.0).is_none()
        && e.strain_energy().is_some();
    if general {
        return Err(invalid(
            key,
            "a point couple is not carried on the general W(s, κ, ν) Cosserat path (the moment \
             there depends on the strain too); use an energy with shear stiffnesses \
             (energy.shear) or the Kirchhoff model",
        ));
    }
    Ok(())
}

/// The solver's guesses name unknowns the scene has: a reaction needs a
/// support that holds the tip's position, and κ(0) is no unknown beside
/// a hinge.
fn guesses_fit(rod: &Rod, options: &SolverOptions) -> Result<(), ProblemError> {
    if options.initial_reaction.is_some()
        && !rod.support().as_ref().is_some_and(|s| s.holds_position())
    {
        return Err(invalid(
            "solver.initial_reaction",
            "guesses the reaction of a tip support that holds the tip's position; this \
             scene has none ([support] translation = \"fixed\" or \"axial\")",
        ));
    }
    if options.initial_guess.is_some() && rod.clamp().hinge {
        // The planar solver took κ2 of the guess as the hinge's angle
        // (its unknown): [0, 3, 0] started Newton from a base turned
        // by 3 rad, which diverged.
        return Err(invalid(
            "solver.initial_curvature",
            "guesses κ(0), which a hinged base (clamp.hinge) does not have as an unknown \
             (M2(0) = 0 fixes it): the unknown is the base's angle, measured from the clamp \
             frame, so guess it by clamp.angle (rad), which turns that frame about the \
             hinge's axis",
        ));
    }
    Ok(())
}
