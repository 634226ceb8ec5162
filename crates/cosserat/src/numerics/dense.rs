//! A dense LU factorization (partial pivoting, nalgebra) kept from a
//! Newton linearization to its solves: the linear solve of the small dense
//! systems (single shooting, Newton at a fixed continuation parameter).

use nalgebra::{DMatrix, DVectorViewMut, Dyn, LU};

/// The LU factors of the last matrix factored, if any.
#[derive(Debug, Clone, Default)]
pub struct DenseLu {
    lu: Option<LU<f64, Dyn, Dyn>>,
    /// The right-hand side solved in place, kept between solves: a
    /// Newton iteration's corrections allocate nothing.
    rhs: Vec<f64>,
}

impl DenseLu {
    /// Factors a copy of `a`, replacing the previous factors.
    pub fn factor(&mut self, a: &DMatrix<f64>) {
        self.lu = Some(a.clone().lu());
    }

    /// The Newton correction δ = −A⁻¹ f of the last factored A; false
    /// (δ untouched) where A is singular or nothing was factored.
    pub fn newton_step(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        let Some(lu) = self.lu.as_ref() else {
            return false;
        };
        self.rhs.clear();
        self.rhs.extend(f.iter().map(|v| -v));
        let n = self.rhs.len();
        if !lu.solve_mut(&mut DVectorViewMut::from_slice(&mut self.rhs, n)) {
            return false;
        }
        delta.copy_from_slice(&self.rhs);
        true
    }
}
