//! Right-hand sides of the equilibrium equations and their linearizations,
//! one implementation per model level.
//!
//! Every level is written as a first-order system y' = f(s, y) on [0, L]
//! whose initial state is fixed by the clamp up to `unknowns()` free values
//! (the curvature at the clamp) and whose tip conditions are as many
//! residuals (the natural boundary condition M(L) = tip couple, paper (22)).
//! Shooting and the other BVP methods see only this interface.

mod kirchhoff;
mod moment_jump;
mod planar;
mod strained;
mod tip;

pub use kirchhoff::KirchhoffEquations;
pub use planar::{PlanarEquations, PlanarKernel};

use nalgebra::{DMatrix, Vector3};

use crate::model::RodTangent;
use crate::numerics::integrator::IntegrationError;

/// The rod's state at one arc length, in the quantities users read.
#[derive(Debug, Clone, PartialEq)]
pub struct RodSample {
    /// Reference arc length s.
    pub s: f64,
    /// Centreline position r(s), global.
    pub position: Vector3<f64>,
    /// Directors d1, d2, d3, global components.
    pub directors: [Vector3<f64>; 3],
    /// Curvature κ, body components.
    pub curvature: Vector3<f64>,
    /// Internal moment M = ∂W/∂κ, body components.
    pub moment: Vector3<f64>,
    /// Internal force n(s), global components.
    pub force: Vector3<f64>,
}

/// A two-point boundary value problem of a clamped rod in shooting form.
pub trait RodEquations: Send + Sync {
    /// Dimension of the state y.
    fn dim(&self) -> usize;
    /// Number of free initial values, equal to the number of tip conditions.
    fn unknowns(&self) -> usize;
    /// The rod length L (the interval is [0, L]).
    fn length(&self) -> f64;
    /// The interior points where the right-hand side jumps or is kinked
    /// (point forces, kinked profiles: [`crate::model::Rod::breaks`]), sorted. Every solver stops its
    /// integration there, puts a mesh node there, and never evaluates the
    /// right-hand side of one side at the other's s (the right-hand side
    /// at s = s_k is the right limit).
    fn jumps(&self) -> Vec<f64>;
    /// Whether the state itself jumps at some point of [`Self::jumps`]
    /// (a point couple makes the moment, and so the curvature, jump): the
    /// solvers that do not call [`Self::jump`] refuse such equations.
    fn state_jumps(&self) -> bool {
        false
    }
    /// Carries the state across the interior point s (one of
    /// [`Self::jumps`]): `y` holds the left limit y(s⁻) on entry and the
    /// right limit y(s⁺) on return, and the `cols` tangent vectors in
    /// `phi` (dim × cols, column-major) are mapped by the jump's
    /// linearization ∂y⁺/∂y⁻. The identity where the state is continuous
    /// (the default, and every point without a couple); an error with the
    /// reason where the state after the jump has no value.
    fn jump(
        &self,
        _s: f64,
        _y: &mut [f64],
        _cols: usize,
        _phi: &mut [f64],
    ) -> Result<(), IntegrationError> {
        Ok(())
    }
    /// y(0) for the free initial values u.
    fn initial_state(&self, u: &[f64], y0: &mut [f64]);
    /// ∂y(0)/∂u (dim × unknowns); y(0) is affine in u.
    fn initial_sensitivity(&self) -> DMatrix<f64>;
    /// y' = f(s, y).
    fn rhs(&self, s: f64, y: &[f64], dy: &mut [f64]);
    /// f together with its linearization applied to `cols` tangent vectors
    /// stored column-major in `phi` (dim × cols): dphi = ∂f/∂y · phi.
    fn rhs_linearized(
        &self,
        s: f64,
        y: &[f64],
        cols: usize,
        phi: &[f64],
        dy: &mut [f64],
        dphi: &mut [f64],
    );
    /// The tip residuals g(y(L)), each dimensionless in its own unit
    /// ([`crate::model::Rod::residual_scales`]), so that a max-norm test
    /// measures every condition on its own scale.
    fn tip_residual(&self, y: &[f64], r: &mut [f64]);
    /// ∂g/∂y at y(L) (unknowns × dim).
    fn tip_residual_jacobian(&self, y: &[f64]) -> DMatrix<f64>;
    /// Restores invariants of y after an integration step (orthonormal
    /// directors); the identity where there are none.
    fn project(&self, y: &mut [f64]);
    /// The right-hand side as a [`PlanarKernel`] where it is one (the
    /// planar level with a constant H22, no point forces and a free tip):
    /// then [`RodEquations::rhs_linearized`] is exactly
    /// [`PlanarKernel::rates`], which shooting inlines on fixed-size
    /// arrays. None by default.
    fn planar_kernel(&self) -> Option<PlanarKernel> {
        None
    }
    /// A starting guess of the free values: the curvature at the clamp that
    /// balances the loads on the unloaded, straight rod.
    fn initial_guess(&self) -> Vec<f64>;
    /// Sets the reaction unknowns of `u` to the global force `r` (the
    /// force the tip support exerts on the rod); false, `u` untouched, when
    /// the support holds no position (no reaction unknowns).
    fn set_reaction(&self, _u: &mut [f64], _r: &nalgebra::Vector3<f64>) -> bool {
        false
    }
    /// Why an evaluation had no value (the shear-extension strain of a
    /// general energy without a solution of W_ν = N): the rates there were
    /// NaN, and the solver names this failure where it stops. None when
    /// every evaluation had a value.
    fn failure(&self) -> Option<String> {
        None
    }
    /// The free values read back from a state at s = 0.
    fn unknowns_of(&self, y0: &[f64]) -> Vec<f64>;
    /// The state in user quantities.
    fn sample(&self, s: f64, y: &[f64]) -> RodSample;
    /// The curvature κ of [`Self::sample`] alone: for scans along the
    /// rod that read nothing else (the stability's mesh resolution).
    fn curvature(&self, s: f64, y: &[f64]) -> Vector3<f64> {
        self.sample(s, y).curvature
    }
    /// A state of the unloaded, straight rod at s: used where no better guess
    /// is available (multiple-shooting nodes after a blow-up).
    fn straight_state(&self, s: f64) -> Vec<f64>;
    /// A typical magnitude of each state component, to make matching and
    /// collocation residuals dimensionless: lengths L, curvatures 1/L,
    /// angles and directors 1.
    fn state_scales(&self) -> Vec<f64>;
    /// The state components the right-hand side never depends on
    /// (∂f/∂y_k ≡ 0 for k in the range): the centreline position, found by
    /// quadrature (r' = ν_i d_i) since dead loads make the equations
    /// translation invariant. Collocation factors its stage matrices
    /// without their columns (a dense block of m·(n − 2) rows planar,
    /// m·9 spatial, instead of m·n). Empty by default: no structure
    /// claimed.
    fn quadrature_components(&self) -> std::ops::Range<usize> {
        0..0
    }

    /// Whether the four `*_parameter` methods below give the exact
    /// p-derivatives for the rod moving along `t` (false by default: the
    /// caller then differentiates by differences and says so).
    fn differentiates(&self, _t: &RodTangent) -> bool {
        false
    }
    /// ∂f/∂p at (s, y), given f = f(s, y) there: the explicit dependence
    /// of the right-hand side on p at a fixed fraction σ = s/L, so that
    /// z = ∂y/∂p|σ obeys the sensitivity equation z' = f_y z + ∂f/∂p. With
    /// s = Lσ a length rate L' contributes (L'/L) (f + s ∂sf) + L' ∂Lf.
    /// Only called where [`RodEquations::differentiates`] `t`; NaN
    /// otherwise.
    fn rhs_parameter(&self, _s: f64, _y: &[f64], _f: &[f64], _t: &RodTangent, out: &mut [f64]) {
        out.fill(f64::NAN);
    }
    /// ∂y(0)/∂p at fixed free values u (the clamp's spin turns the
    /// initial directors). NaN where not [`RodEquations::differentiates`].
    fn initial_state_parameter(&self, _u: &[f64], _t: &RodTangent, out: &mut [f64]) {
        out.fill(f64::NAN);
    }
    /// ∂g/∂p of the tip residuals at a fixed tip state y(L), their units'
    /// rates included. NaN where not [`RodEquations::differentiates`].
    fn tip_residual_parameter(&self, _y: &[f64], _t: &RodTangent, out: &mut [f64]) {
        out.fill(f64::NAN);
    }
    /// d/dp of [`RodEquations::state_scales`]. NaN where not
    /// [`RodEquations::differentiates`].
    fn state_scales_parameter(&self, _t: &RodTangent) -> Vec<f64> {
        vec![f64::NAN; self.dim()]
    }
}

impl RodSample {
    /// max |d_i·d_j − δ_ij|: how far the directors are from orthonormal.
    pub fn director_drift(&self) -> f64 {
        let mut worst: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                let delta = if i == j { 1.0 } else { 0.0 };
                worst = worst.max((self.directors[i].dot(&self.directors[j]) - delta).abs());
            }
        }
        worst
    }
}
