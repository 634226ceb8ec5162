//! One step of the Gauss–Legendre Runge–Kutta method with its exact
//! derivative: the segment map of shooting on a collocation mesh.
//!
//! Gauss collocation with m points on a mesh is the m-stage Gauss RK method
//! stepped from node to node (Hairer, Nørsett & Wanner I, Thm. II.7.7), so
//! multiple shooting whose segments are single Gauss steps solves the
//! collocation equations of that mesh — order 2m at the nodes — with the
//! node states as unknowns. The stage equations K_i = f(s + c_i h,
//! y0 + h Σ_l a_il K_l) are solved by Newton; the sensitivity follows by
//! implicit differentiation, (I − h A ⊗ J) dK = (J_i Φ0)_i, Φ1 = Φ0 +
//! h Σ b_i dK_i, with J_i = ∂f/∂y at the stages. The method preserves the
//! quadratic invariants d_i·d_j exactly, so no projection is needed.

use nalgebra::{DMatrix, DVector};

use super::collocation::Tableau;
use crate::equations::RodEquations;
use crate::model::RodTangent;
use crate::numerics::integrator::IntegrationError;

/// The stage Jacobians J_i = ∂f/∂y (n × n each) at the stage states.
fn stage_jacobians(
    eq: &dyn RodEquations,
    tab: &Tableau,
    s: f64,
    h: f64,
    stages: &[Vec<f64>],
) -> Vec<DMatrix<f64>> {
    let n = eq.dim();
    let identity = DMatrix::<f64>::identity(n, n);
    let (mut dy, mut dphi) = (vec![0.0; n], vec![0.0; n * n]);
    (0..tab.m)
        .map(|i| {
            eq.rhs_linearized(
                s + tab.c[i] * h,
                &stages[i],
                n,
                identity.as_slice(),
                &mut dy,
                &mut dphi,
            );
            DMatrix::from_column_slice(n, n, &dphi)
        })
        .collect()
}

/// I − h A ⊗ J: the Newton matrix of the stage equations (m n × m n).
fn stage_matrix(tab: &Tableau, h: f64, jac: &[DMatrix<f64>]) -> DMatrix<f64> {
    let (m, n) = (tab.m, jac[0].nrows());
    let mut a = DMatrix::identity(m * n, m * n);
    for (i, ji) in jac.iter().enumerate() {
        for l in 0..m {
            let block = ji * (-h * tab.a(i, l));
            let mut view = a.view_mut((i * n, l * n), (n, n));
            view += block;
        }
    }
    a
}

/// The stage states y0 + h Σ_l a_il K_l.
fn stage_states(tab: &Tableau, h: f64, y0: &[f64], k: &[Vec<f64>]) -> Vec<Vec<f64>> {
    (0..tab.m)
        .map(|i| {
            let mut y = y0.to_vec();
            for (l, kl) in k.iter().enumerate() {
                let w = h * tab.a(i, l);
                y.iter_mut().zip(kl).for_each(|(a, b)| *a += w * b);
            }
            y
        })
        .collect()
}

/// y(s + h) and Φ(s + h) = ∂y(s + h)/∂(unknowns) from y0 and Φ0 (n × cols,
/// cols may be 0) by one Gauss step.
///
/// With `forcing`, the last column of Φ is the parameter sensitivity
/// z = ∂y/∂p at fixed σ = s/L: its stage equations gain the explicit
/// ∂f/∂p ([`RodEquations::rhs_parameter`]), (I − h A ⊗ J) dK =
/// (J_i z0 + ∂f/∂p(s_i, Y_i))_i. A Gauss step on s = Lσ with h = L/K is
/// the same step on σ with 1/K, so this is the exact p-derivative of the
/// discrete step, a length rate included.
pub(crate) fn gauss_step(
    eq: &dyn RodEquations,
    tab: &Tableau,
    s: f64,
    h: f64,
    y0: &[f64],
    phi0: &DMatrix<f64>,
    forcing: Option<&RodTangent>,
) -> Result<(Vec<f64>, DMatrix<f64>), IntegrationError> {
    let (m, n) = (tab.m, eq.dim());
    let mut f0 = vec![0.0; n];
    eq.rhs(s, y0, &mut f0);
    let mut k: Vec<Vec<f64>> = vec![f0; m];
    let scale = y0.iter().map(|v| v.abs()).fold(1.0, f64::max);
    // Simplified Newton: the stage matrix of the first iterate is factored
    // once and kept while the corrections contract at least twofold (its
    // error is O(h) in the stages, so the rate is O(h²)); it is refreshed
    // only where they do not. The fixed point is the same as Newton's.
    let mut lu = None;
    let mut previous = f64::INFINITY;
    let mut converged = false;
    for _ in 0..30 {
        let stages = stage_states(tab, h, y0, &k);
        let mut r = DVector::zeros(m * n);
        let mut f = vec![0.0; n];
        for i in 0..m {
            eq.rhs(s + tab.c[i] * h, &stages[i], &mut f);
            for j in 0..n {
                r[i * n + j] = k[i][j] - f[j];
            }
        }
        if r.iter().any(|v| !v.is_finite()) {
            return Err(IntegrationError::NotFinite { s });
        }
        let factors = match lu.take() {
            Some(factors) => factors,
            None => stage_matrix(tab, h, &stage_jacobians(eq, tab, s, h, &stages)).lu(),
        };
        let Some(dk) = factors.solve(&r) else {
            return Err(IntegrationError::StepSizeUnderflow { s });
        };
        for i in 0..m {
            for j in 0..n {
                k[i][j] -= dk[i * n + j];
            }
        }
        let size = h * dk.amax();
        if size <= 1e-15 * scale {
            converged = true;
            break;
        }
        if size <= 0.5 * previous {
            lu = Some(factors);
        }
        previous = size;
    }
    if !converged {
        return Err(IntegrationError::StepSizeUnderflow { s });
    }
    let mut y1 = y0.to_vec();
    for (i, ki) in k.iter().enumerate() {
        let w = h * tab.b[i];
        y1.iter_mut().zip(ki).for_each(|(a, b)| *a += w * b);
    }
    let cols = phi0.ncols();
    if cols == 0 {
        return Ok((y1, DMatrix::zeros(n, 0)));
    }
    let stages = stage_states(tab, h, y0, &k);
    let jac = stage_jacobians(eq, tab, s, h, &stages);
    let mut rhs = DMatrix::zeros(m * n, cols);
    let mut fp = vec![0.0; n];
    for (i, ji) in jac.iter().enumerate() {
        rhs.view_mut((i * n, 0), (n, cols)).copy_from(&(ji * phi0));
        if let Some(t) = forcing {
            // K_i = f(s_i, Y_i) to the stage Newton's 1e-15.
            eq.rhs_parameter(s + tab.c[i] * h, &stages[i], &k[i], t, &mut fp);
            for (r, v) in fp.iter().enumerate() {
                rhs[(i * n + r, cols - 1)] += v;
            }
        }
    }
    let Some(dk) = stage_matrix(tab, h, &jac).lu().solve(&rhs) else {
        return Err(IntegrationError::StepSizeUnderflow { s });
    };
    let mut phi1 = phi0.clone();
    for i in 0..m {
        phi1 += dk.view((i * n, 0), (n, cols)) * (h * tab.b[i]);
    }
    Ok((y1, phi1))
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::Vector3;

    use super::*;
    use crate::equations::KirchhoffEquations;
    use crate::model::{Clamp, DeadLoads, LinearElastic, Rod};

    /// Φ of one Gauss step against central differences of the step in y0,
    /// on the spatial equations of a loaded, intrinsically curved rod.
    #[test]
    fn sensitivity_matches_central_differences() {
        let rod = Rod::new(
            1.0,
            Arc::new(LinearElastic::uniform([2.0, 1.0, 1.5], [0.3, -0.4, 0.7]).unwrap()),
            Clamp::paper(),
            DeadLoads {
                tip_force: Vector3::new(1.5, 0.4, -0.3),
                ..Default::default()
            },
            None,
        )
        .unwrap();
        let eq = KirchhoffEquations::new(rod);
        let tab = Tableau::gauss(3).unwrap();
        let mut y0 = vec![0.0; 12];
        eq.initial_state(&[0.2, -0.5, 0.1], &mut y0);
        let (h, s) = (0.125, 0.25);
        let (_, phi) = gauss_step(&eq, &tab, s, h, &y0, &DMatrix::identity(12, 12), None).unwrap();
        let none = DMatrix::zeros(12, 0);
        for j in 0..12 {
            let (mut a, mut b) = (y0.clone(), y0.clone());
            a[j] += 1e-6;
            b[j] -= 1e-6;
            let ya = gauss_step(&eq, &tab, s, h, &a, &none, None).unwrap().0;
            let yb = gauss_step(&eq, &tab, s, h, &b, &none, None).unwrap().0;
            for i in 0..12 {
                let fd = (ya[i] - yb[i]) / 2e-6;
                assert!(
                    (fd - phi[(i, j)]).abs() < 1e-7,
                    "({i}, {j}): {fd} vs {}",
                    phi[(i, j)]
                );
            }
        }
    }
}
