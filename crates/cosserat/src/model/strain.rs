//! The stored energy of a Cosserat rod in all six strains, W(s, κ, ν):
//! κ the curvature-twist and ν = Rᵀr' the shear-extension strain
//! (ν = e3 unstrained), with any coupling between them and any
//! s-dependence.
//!
//! With z = (κ, ν) the constitutive laws are m = W_κ and N = W_ν (body
//! components), the tangent stiffness the 6 × 6 Hessian
//! H = [[W_κκ, W_κν], [W_νκ, W_νν]] (Antman, *Nonlinear Problems of
//! Elasticity*, 2nd ed., Ch. 8, §8.2: strong ellipticity is H positive
//! definite). With dead loads the body force N = Rᵀn is known from the
//! frame, so ν solves W_ν(s, κ, ν) = N ([`shear_strain`], a safeguarded
//! Newton); the equations need nothing else of W but ∇W, H, their
//! s-rates and H's derivative along a direction.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// ∇W, H = ∇²W and their explicit s-rates at one (s, κ, ν), over the
/// strains z = (κ1, κ2, κ3, ν1, ν2, ν3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrainJet {
    /// ∇W = (m, N).
    pub gradient: Vector6<f64>,
    /// H = ∇²W (symmetric).
    pub hessian: Matrix6<f64>,
    /// ∂s∇W at fixed strains.
    pub gradient_rate: Vector6<f64>,
    /// ∂sH at fixed strains.
    pub hessian_rate: Matrix6<f64>,
}

impl StrainJet {
    /// The moment m = W_κ.
    pub fn moment(&self) -> Vector3<f64> {
        self.gradient.fixed_rows::<3>(0).into_owned()
    }

    /// The force N = W_ν.
    pub fn force(&self) -> Vector3<f64> {
        self.gradient.fixed_rows::<3>(3).into_owned()
    }

    /// The block (row, column) of H: 0 for κ, 1 for ν.
    pub fn block(&self, row: usize, col: usize) -> Matrix3<f64> {
        self.hessian
            .fixed_view::<3, 3>(3 * row, 3 * col)
            .into_owned()
    }
}

/// A stored energy density W(s, κ, ν) ≥ 0 per unit reference length,
/// C³ in the strains, C¹ in s. Reached from a [`super::StoredEnergy`]
/// through [`super::StoredEnergy::strain_energy`]; that energy's own
/// κ-methods are this W at ν = e3 (the Kirchhoff restriction).
pub trait StrainEnergy: std::fmt::Debug + Send + Sync {
    /// W(s, κ, ν).
    fn strain_density(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> f64;
    /// ∇W, H and their s-rates.
    fn strain_jet(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> StrainJet;
    /// ∂(H(z) v)/∂z for a fixed v: the third derivative of W contracted
    /// with v (symmetric; the variational equations need it).
    fn strain_hessian_derivative(
        &self,
        s: f64,
        kappa: &Vector3<f64>,
        nu: &Vector3<f64>,
        v: &Vector6<f64>,
    ) -> Matrix6<f64>;
}

/// Why W_ν(s, κ, ν) = N has no computed solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StrainError {
    /// W_νν is not positive definite (or not finite) at an iterate: the
    /// material is unstable there (no unique strain carries the force).
    #[error(
        "W_νν is not positive definite at s = {s}, κ = {kappa:?}, ν = {nu:?}: no unique \
         shear-extension strain carries the force N = {force:?} (material instability)"
    )]
    Indefinite {
        /// Arc length.
        s: f64,
        /// Curvature (body components).
        kappa: [f64; 3],
        /// The iterate where W_νν failed.
        nu: [f64; 3],
        /// The force to carry.
        force: [f64; 3],
    },
    /// Newton spent its budget or its line search stalled.
    #[error(
        "Newton for W_ν(s, κ, ν) = N stalled at s = {s} after {iterations} iterations \
         (N = {force:?}, residual {residual:e}): the material cannot carry the force"
    )]
    Stalled {
        /// Arc length.
        s: f64,
        /// Iterations spent.
        iterations: usize,
        /// The force to carry.
        force: [f64; 3],
        /// |W_ν − N| at the last iterate.
        residual: f64,
    },
}

/// Newton's iteration budget: quadratic convergence needs a handful from
/// ν = e3 for any force a rod carries; the rest is the damped phase.
const MAX_ITERATIONS: usize = 60;

/// Line-search halvings before a step counts as stalled.
const MAX_HALVINGS: usize = 40;

/// ν with W_ν(s, κ, ν) = N, by Newton on r(ν) = W_ν − N with Jacobian
/// W_νν (Cholesky: refused unless positive definite), damped by halving
/// until |r| decreases (Armijo with slope ¼), from `start` (ν = e3 where
/// nothing better is known). Converged when the next full step is below
/// 1e-14 max(|ν|, 1): ν is then exact to a few ulps of the strain, and is
/// returned with its jet (the one that step was computed from, so the
/// caller evaluates W no more). Deterministic: the same arguments give the
/// same bits.
pub fn shear_strain(
    energy: &dyn StrainEnergy,
    s: f64,
    kappa: &Vector3<f64>,
    force: &Vector3<f64>,
    start: &Vector3<f64>,
) -> Result<(Vector3<f64>, StrainJet), StrainError> {
    let residual_at = |nu: &Vector3<f64>| {
        let jet = energy.strain_jet(s, kappa, nu);
        (jet.force() - force, jet)
    };
    let indefinite = |nu: &Vector3<f64>| StrainError::Indefinite {
        s,
        kappa: (*kappa).into(),
        nu: (*nu).into(),
        force: (*force).into(),
    };
    let mut nu = *start;
    let (mut r, mut j) = residual_at(&nu);
    for iteration in 0..MAX_ITERATIONS {
        if !r.iter().all(|v| v.is_finite()) {
            return Err(indefinite(&nu));
        }
        let Some(chol) = j.block(1, 1).cholesky() else {
            return Err(indefinite(&nu));
        };
        let step = -chol.solve(&r);
        if step.norm() <= 1e-14 * nu.norm().max(1.0) {
            return Ok((nu, j));
        }
        let norm = r.norm();
        let mut lambda = 1.0;
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            let trial = nu + step * lambda;
            let (rt, jt) = residual_at(&trial);
            if rt.iter().all(|v| v.is_finite()) && rt.norm() <= (1.0 - 0.25 * lambda) * norm {
                accepted = Some((trial, rt, jt));
                break;
            }
            lambda *= 0.5;
        }
        let Some((trial, rt, jt)) = accepted else {
            return Err(StrainError::Stalled {
                s,
                iterations: iteration + 1,
                force: (*force).into(),
                residual: norm,
            });
        };
        (nu, r, j) = (trial, rt, jt);
    }
    Err(StrainError::Stalled {
        s,
        iterations: MAX_ITERATIONS,
        force: (*force).into(),
        residual: r.norm(),
    })
}

/// H's block structure from its three 3 × 3 blocks (H_νκ = H_κνᵀ).
pub fn assemble_blocks(kk: &Matrix3<f64>, kn: &Matrix3<f64>, nn: &Matrix3<f64>) -> Matrix6<f64> {
    let mut h = Matrix6::zeros();
    h.fixed_view_mut::<3, 3>(0, 0).copy_from(kk);
    h.fixed_view_mut::<3, 3>(0, 3).copy_from(kn);
    h.fixed_view_mut::<3, 3>(3, 0).copy_from(&kn.transpose());
    h.fixed_view_mut::<3, 3>(3, 3).copy_from(nn);
    h
}

/// The pair (a, b) as one 6-vector.
pub fn stack(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector6<f64> {
    Vector6::new(a[0], a[1], a[2], b[0], b[1], b[2])
}
