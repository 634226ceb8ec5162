//! A dense LU factorization (partial pivoting, nalgebra) kept from a
//! Newton linearization to its solves: the linear solve of the small dense
//! systems (single shooting, Newton at a fixed continuation parameter).

use nalgebra::{DMatrix, DVector, Dyn, LU};

/// The LU factors of the last matrix factored, if any.
#[derive(Debug, Clone, Default)]
pub struct DenseLu {
    lu: Option<LU<f64, Dyn, Dyn>>,
}

impl DenseLu {
    /// Factors a copy of `a`, replacing the previous factors.
    pub fn factor(&mut self, a: &DMatrix<f64>) {
        self.lu = Some(a.clone().lu());
    }

    /// The Newton correction δ = −A⁻¹ f of the last factored A; false
    /// (δ untouched) where A is singular or nothing was factored.
    pub fn newton_step(&self, f: &[f64], delta: &mut [f64]) -> bool {
        let rhs = -DVector::from_column_slice(f);
        match self.lu.as_ref().and_then(|lu| lu.solve(&rhs)) {
            Some(d) => {
                delta.copy_from_slice(d.as_slice());
                true
            }
            None => false,
        }
    }
}
