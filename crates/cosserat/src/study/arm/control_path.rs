//! The control path of a designed arm (Sipos & Várkonyi 2019, Sec. 5).
//!
//! The paper warns that an optimal arm, highly curved when unloaded, need
//! not reach its designed shape when the tip load is applied to it, and
//! proposes "applying curvature control in such a way, that intrinsic
//! curvature is increased as the load is applied". That is the path
//! followed here: κ⁰(s) = λ κ⁰_design(s) and the load λ F together, from
//! the straight unloaded rod (λ = 0) to the design (λ = 1). Raising κ⁰ with
//! the load held at F instead is not what the paper proposes ("increased as
//! the load is applied"), and it would start with the whole design load on
//! a straight arm longer (L̂ = √γ_crit: 2.11 for the circular Fig. 5 arm,
//! 4.38 for Sec. 4.4) than the best straight arm reaches stably
//! (R̂0 = 1.82); the proportional path starts unloaded and stable, as a
//! robot would. A third control, [`shape_holding_path`], moves κ⁰ so that
//! the arm keeps its designed shape at every load.
//!
//! Along the path the equilibrium is not the design shape: at λ the
//! moment of the load λF is not compensated by λκ⁰ alone except at λ = 1,
//! where the design is an exact equilibrium (κ⁰ from (43)).

use std::sync::Arc;

use super::{continue_refining, continue_to_design, derivative, designed_rod, polynomial};
use super::{ArmDesign, ArmProblem, ArmScene};
use crate::continuation::{ContinuationError, Diagram, Family, Parameter};
use crate::model::{LinearElastic, ModelLevel, Profile};

/// The arm continued along κ⁰ = λ κ⁰_design, loads λ × design loads, from
/// λ = 10⁻³ to 1 with the Hessian eigenvalues tracked (both blocks, the
/// design's own mesh, so that λ = 1 is marginal: the design load is
/// γ_crit). κ⁰ is the natural cubic spline through `points` nodes.
pub fn control_path(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
) -> Result<Diagram, ContinuationError> {
    control_path_until(problem, scene, design, points, &|| false)
}

/// [`control_path`], stopping at the next point once `stop()` turns true:
/// the diagram then holds the points computed, its `stop_reason`
/// "interrupted".
pub fn control_path_until(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
    stop: &dyn Fn() -> bool,
) -> Result<Diagram, ContinuationError> {
    let rod = designed_rod(problem, scene, design, points).map_err(|e| not_built(&e))?;
    continue_to_design(problem, &rod, Parameter::ControlScale, stop)
}

/// The loading path ([`super::loading_path`]) of a design in a scene: κ⁰
/// held at the design, the scene's loads raised from λ = 10⁻³ to 1.
pub fn loading_path_in(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
) -> Result<Diagram, ContinuationError> {
    loading_path_until(problem, scene, design, points, &|| false)
}

/// [`loading_path_in`], stopping at the next point once `stop()` turns
/// true (the diagram's `stop_reason` then "interrupted").
pub fn loading_path_until(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
    stop: &dyn Fn() -> bool,
) -> Result<Diagram, ContinuationError> {
    let rod = designed_rod(problem, scene, design, points).map_err(|e| not_built(&e))?;
    continue_to_design(problem, &rod, Parameter::LoadScale, stop)
}

/// The shape-holding control: the loads raised from 0 to the design's
/// while κ⁰ moves from φ' (the designed shape, unloaded) to the design's
/// κ⁰ = φ' − γ m̄2 (43), κ⁰(λ) = φ' − λ γ m̄2. The designed shape is then an
/// equilibrium at every λ, and its second variation is K0 + λK1 — the
/// fixed-shape pencil whose smallest positive root is λ_crit = 1 — so the
/// path stays on the design, stable for λ < 1, whatever the arm. The
/// continuation checks that; κ⁰ is the natural spline through `points`
/// nodes (the same nodes for both ends, so that κ⁰(λ) blends exactly).
pub fn shape_holding_path(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
) -> Result<Diagram, ContinuationError> {
    shape_holding_path_until(problem, scene, design, points, &|| false)
}

/// [`shape_holding_path`], stopping at the next point once `stop()` turns
/// true (the diagram's `stop_reason` then "interrupted").
pub fn shape_holding_path_until(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
    stop: &dyn Fn() -> bool,
) -> Result<Diagram, ContinuationError> {
    let target = designed_rod(problem, scene, design, points).map_err(|e| not_built(&e))?;
    let s: Vec<f64> = (0..points)
        .map(|i| i as f64 / (points - 1) as f64)
        .collect();
    let dphi = derivative(&design.shape_coefficients);
    let unloaded: Vec<f64> = s.iter().map(|t| polynomial(&dphi, *t)).collect();
    let unloaded = LinearElastic::new(
        [problem.b1, 1.0, problem.b3].map(Profile::Constant),
        [
            Profile::Constant(0.0),
            Profile::spline(s, unloaded).map_err(|e| not_built(&e))?,
            Profile::Constant(0.0),
        ],
    )
    .map_err(|e| not_built(&e))?;
    let base = target.clone().with_energy(Arc::new(unloaded));
    continue_refining(
        problem,
        |segments| {
            Family::towards(
                base.clone(),
                target.energy().clone(),
                ModelLevel::Planar,
                segments,
                crate::numerics::integrator::Tolerances::default(),
            )
        },
        stop,
    )
}

/// A designed rod that cannot be built: continuation cannot start.
fn not_built(e: &crate::model::ModelError) -> ContinuationError {
    ContinuationError::Start {
        p: 0.0,
        message: format!("the designed rod cannot be built: {e}"),
    }
}
