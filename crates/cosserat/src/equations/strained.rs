//! The balance of a Cosserat rod with a general energy W(s, κ, ν)
//! ([`StrainEnergy`]): the strain ν from the force, the rates κ', ν' from
//! the moment and force balances, and their linearization, using only ∇W,
//! the 6 × 6 Hessian H and its derivative along a direction.
//!
//! With z = (κ, ν), m = W_κ and N = W_ν (body components) the balance laws
//! m' = m × κ + N × ν and N' = N × κ − F (F = Rᵀf the distributed force in
//! body components; n' + f = 0 and d_i' = k × d_i give N_i' = −f·d_i +
//! (N × κ)_i) with d/ds ∇W(s, z) = H z' + ∂s∇W give
//!
//!   H z' = (m × κ + N × ν, N × κ − F) − ∂s∇W,
//!
//! the κ-rows of which are the Kirchhoff system with H_κκ replaced by the
//! Schur complement H_κκ − H_κν H_νν⁻¹ H_νκ once ν' is eliminated. The
//! strain itself is not a state: ν solves W_ν(s, κ, ν) = N at every
//! evaluation ([`shear_strain`]), so that the constitutive law holds
//! exactly along the rod. Linearized along (δκ, δN, δF) at fixed s:
//! δν = H_νν⁻¹ (δN − H_νκ δκ), δz = (δκ, δν), and
//!
//!   H δz' = δq − ∂s H δz − T[z'] δz,   T[v] = ∂(H v)/∂z (symmetric),
//!
//! δq = (δm × κ + m × δκ + δN × ν + N × δν, δN × κ + N × δκ − δF),
//! δm = (H δz)_κ.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::model::{shear_strain, stack, StrainEnergy, StrainError, StrainJet};

/// ∇W, H and the rates at one point of the rod, ν solved.
pub(super) struct Strained {
    /// The strain ν with W_ν = N.
    pub nu: Vector3<f64>,
    /// The jet at (s, κ, ν).
    jet: StrainJet,
    /// H⁻¹.
    h_inv: Matrix6<f64>,
    /// H_νν⁻¹.
    nn_inv: Matrix3<f64>,
    /// z' = (κ', ν').
    pub rate: Vector6<f64>,
    /// The body force N (the load, = W_ν).
    force: Vector3<f64>,
}

fn upper(v: &Vector6<f64>) -> Vector3<f64> {
    v.fixed_rows::<3>(0).into_owned()
}

impl Strained {
    /// The point (s, κ) under the body force N and distributed force F
    /// (body components): ν by Newton, then z' from H z' = q.
    pub fn at(
        energy: &dyn StrainEnergy,
        s: f64,
        kappa: &Vector3<f64>,
        force: &Vector3<f64>,
        distributed: &Vector3<f64>,
    ) -> Result<Strained, StrainError> {
        let (nu, jet) = shear_strain(energy, s, kappa, force, &Vector3::z())?;
        let indefinite = || StrainError::Indefinite {
            s,
            kappa: (*kappa).into(),
            nu: nu.into(),
            force: (*force).into(),
        };
        let h_inv = jet.hessian.cholesky().ok_or_else(indefinite)?.inverse();
        let nn_inv = jet.block(1, 1).cholesky().ok_or_else(indefinite)?.inverse();
        let m = jet.moment();
        let q = stack(
            &(m.cross(kappa) + force.cross(&nu)),
            &(force.cross(kappa) - distributed),
        ) - jet.gradient_rate;
        Ok(Strained {
            nu,
            jet,
            h_inv,
            nn_inv,
            rate: h_inv * q,
            force: *force,
        })
    }

    /// The moment m = W_κ(s, κ, ν).
    pub fn moment(&self) -> Vector3<f64> {
        self.jet.moment()
    }

    /// κ'.
    pub fn kappa_rate(&self) -> Vector3<f64> {
        upper(&self.rate)
    }

    /// ∂m/∂κ at fixed N: the Schur complement H_κκ − H_κν H_νν⁻¹ H_νκ.
    pub fn moment_stiffness(&self) -> Matrix3<f64> {
        let kn = self.jet.block(0, 1);
        self.jet.block(0, 0) - kn * self.nn_inv * kn.transpose()
    }

    /// ∂m/∂N at fixed κ: H_κν H_νν⁻¹.
    pub fn moment_compliance(&self) -> Matrix3<f64> {
        self.jet.block(0, 1) * self.nn_inv
    }

    /// T[z'] = ∂(H z')/∂z, once per point for every direction.
    pub fn third(&self, energy: &dyn StrainEnergy, s: f64, kappa: &Vector3<f64>) -> Matrix6<f64> {
        energy.strain_hessian_derivative(s, kappa, &self.nu, &self.rate)
    }

    /// (δκ', δν) along (δκ, δN, δF), with `third` = [`Strained::third`].
    pub fn linearized(
        &self,
        third: &Matrix6<f64>,
        kappa: &Vector3<f64>,
        dk: &Vector3<f64>,
        dn: &Vector3<f64>,
        df: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let h = &self.jet.hessian;
        let dnu = self.nn_inv * (dn - self.jet.block(1, 0) * dk);
        let dz = stack(dk, &dnu);
        let dm = upper(&(h * dz));
        let m = self.jet.moment();
        let n = self.force;
        let dq = stack(
            &(dm.cross(kappa) + m.cross(dk) + dn.cross(&self.nu) + n.cross(&dnu)),
            &(dn.cross(kappa) + n.cross(dk) - df),
        ) - self.jet.hessian_rate * dz;
        let dzr = self.h_inv * (dq - third * dz);
        (upper(&dzr), dnu)
    }
}
