//! The control path of a designed arm (paper Sec. 5, issue 6 item 5).
//!
//! The paper warns that an optimal arm, highly curved when unloaded, need
//! not reach its designed shape when the tip load is applied to it, and
//! proposes "applying curvature control in such a way, that intrinsic
//! curvature is increased as the load is applied". That is the path
//! followed here: κ⁰(s) = λ κ⁰_design(s) and the load λ F together, from
//! the straight unloaded rod (λ = 0) to the design (λ = 1). Raising κ⁰ with
//! the load held at F instead would start from a straight rod under the
//! full design load, which for a long arm (L̂ = √γ_crit beyond the Euler
//! and Timoshenko lengths) is itself far past its first instability; the
//! proportional path starts unloaded and stable, as a robot would.
//!
//! Along the path the equilibrium is not the design shape: at λ the
//! moment of the load λF is not compensated by λκ⁰ alone except at λ = 1,
//! where the design is an exact equilibrium (κ⁰ from (43)).

use super::{continue_to_design, designed_rod, ArmDesign, ArmProblem, ArmScene};
use crate::continuation::{ContinuationError, Diagram, Parameter};

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
    let rod = designed_rod(problem, scene, design, points);
    continue_to_design(problem, rod, Parameter::ControlScale)
}

/// The loading path ([`super::loading_path`]) of a design in a scene: κ⁰
/// held at the design, the scene's loads raised from λ = 10⁻³ to 1.
pub fn loading_path_in(
    problem: &ArmProblem,
    scene: &ArmScene,
    design: &ArmDesign,
    points: usize,
) -> Result<Diagram, ContinuationError> {
    let rod = designed_rod(problem, scene, design, points);
    continue_to_design(problem, rod, Parameter::LoadScale)
}
