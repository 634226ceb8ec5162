//! The curvature after a point couple.
//!
//! A dead couple C_k at s_k makes the internal moment jump,
//! m(s_k⁺) = m(s_k⁻) − C_k ([`crate::model::DeadLoads::moment_jump`]),
//! while the directors and the internal force stay continuous. The planar
//! and spatial states carry the curvature κ, not the moment, so κ⁺ solves
//! ∇W(s_k, κ⁺) = M⁻ + J, with M⁻ = ∇W(s_k⁻, κ⁻) and J the jump in body
//! components (J_i = −C_k·d_i). W is convex in κ (H positive definite,
//! checked on every energy the solver is given), so Newton from κ⁻ finds
//! the one root; a Newton that fails is an error with its reason, never
//! a value. Its linearization, for the sensitivities Φ:
//! dκ⁺ = H(s_k, κ⁺)⁻¹ (H(s_k⁻, κ⁻) dκ⁻ + dJ).

use nalgebra::{Matrix3, Vector3};

use crate::model::StoredEnergy;

/// Newton steps before the curvature after a jump is given up.
const MAX_STEPS: usize = 50;

/// A Newton correction this small against the curvature (or the jump's
/// first step) ends the iteration: round-off of the solve.
const CONVERGED: f64 = 1e-14;

/// Below this relative size a correction that no longer halves is
/// round-off: the iteration stops there too.
const ROUND_OFF_FLOOR: f64 = 1e-9;

/// κ⁺ with ∇W(s, κ⁺) = `target`, by Newton from `start` (κ⁻), and
/// H(s, κ⁺).
pub(super) fn curvature_for_moment(
    energy: &dyn StoredEnergy,
    s: f64,
    start: &Vector3<f64>,
    target: &Vector3<f64>,
) -> Result<(Vector3<f64>, Matrix3<f64>), &'static str> {
    let mut kappa = *start;
    let mut stop = Stop::default();
    for _ in 0..MAX_STEPS {
        let h = energy.stiffness(s, &kappa);
        let residual = energy.moment(s, &kappa) - target;
        let Some(delta) = h.lu().solve(&residual) else {
            return Err("the energy's Hessian is singular there");
        };
        kappa -= delta;
        if !kappa.iter().all(|x| x.is_finite()) {
            return Err("Newton for the curvature left the finite numbers");
        }
        if stop.reached(delta.amax(), kappa.amax()) {
            return Ok((kappa, energy.stiffness(s, &kappa)));
        }
    }
    Err("Newton for the curvature did not converge in 50 steps")
}

/// The stopping test both Newton iterations share: a correction at the
/// round-off of the solve ([`CONVERGED`]) against the curvature or the
/// first correction, or one that no longer halves below
/// [`ROUND_OFF_FLOOR`].
struct Stop {
    first: Option<f64>,
    previous: f64,
}

impl Default for Stop {
    fn default() -> Self {
        Stop {
            first: None,
            previous: f64::INFINITY,
        }
    }
}

impl Stop {
    /// Whether the correction of max-norm `size`, giving a curvature of
    /// max-norm `kappa`, ends the iteration.
    fn reached(&mut self, size: f64, kappa: f64) -> bool {
        let reference = kappa.max(*self.first.get_or_insert(size));
        let done = size <= CONVERGED * reference
            || (size > 0.5 * self.previous && size <= ROUND_OFF_FLOOR * reference);
        self.previous = size;
        done
    }
}

/// κ2⁺ of a planar state, bending about e2 alone: ∂W/∂κ2(s, (0, κ2⁺, 0))
/// = `target`, by Newton from `start`; with H22 there.
pub(super) fn bending_for_moment(
    energy: &dyn StoredEnergy,
    s: f64,
    start: f64,
    target: f64,
) -> Result<(f64, f64), &'static str> {
    let at = |k2: f64| Vector3::new(0.0, k2, 0.0);
    let mut k2 = start;
    let mut stop = Stop::default();
    for _ in 0..MAX_STEPS {
        let h22 = energy.stiffness(s, &at(k2))[(1, 1)];
        if h22 <= 0.0 || !h22.is_finite() {
            return Err("the bending stiffness H22 is not positive there");
        }
        let delta = (energy.moment(s, &at(k2))[1] - target) / h22;
        k2 -= delta;
        if !k2.is_finite() {
            return Err("Newton for the curvature left the finite numbers");
        }
        if stop.reached(delta.abs(), k2.abs()) {
            return Ok((k2, energy.stiffness(s, &at(k2))[(1, 1)]));
        }
    }
    Err("Newton for the curvature did not converge in 50 steps")
}
