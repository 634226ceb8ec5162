//! Branches of symmetric copies: where every equilibrium of a branch comes
//! with a continuum of copies (the buckled shapes of an isotropic rod
//! turned about its axis, Greenhill's shaft, a twisted rod), F_x keeps a
//! null vector along the whole branch — the direction of the copies — and
//! [F_x F_p; τᵀ] is singular: the plain corrector either fails or drifts
//! along the copies at a constant load. The slice corrector fixes the copy
//! with a phase condition (the freezing / slice method; Beyn & Thümmler,
//! SIAM J. Appl. Dyn. Syst. 3, 2004; Govaerts 2000, Sec. 4.4):
//!
//!   F(x, p) + μ w = 0,   vᵀ(x − x₀) = 0,   τᵀ(z − z_pred) = 0,
//!
//! in (x, p, μ), with v and w the right and left null vectors of F_x at
//! the last point: the first rows are solvable exactly because F = 0 has
//! solutions (μ = 0 at convergence, checked), the phase keeps the point on
//! the slice through x₀ transverse to the copies, and the new system is
//! regular. Dense: used on systems of up to
//! [`super::corrector::DENSE_UP_TO`] unknowns, where F_x's singular values
//! are at hand.

use nalgebra::{DMatrix, DVector};

use super::{PointError, Run};

/// σ_min/σ_max of F_x below which its null vector is taken as persistent
/// (the integration's noise, not a nearby branch point: a regular branch
/// passing near one is this close to it only by accident).
const PERSISTENT_KERNEL: f64 = 1e-9;

/// The right and left null vectors of a singular F_x (unit), or None when
/// F_x is regular or too large to decompose densely.
pub(super) fn persistent_kernel(fx: &DMatrix<f64>) -> Option<(DVector<f64>, DVector<f64>)> {
    let (v, w, ratio) = smallest_pair(fx)?;
    (ratio <= PERSISTENT_KERNEL).then_some((v, w))
}

/// The right and left singular vectors of F_x's smallest singular value,
/// and that value over the largest (dense systems only).
fn smallest_pair(fx: &DMatrix<f64>) -> Option<(DVector<f64>, DVector<f64>, f64)> {
    if fx.nrows() > super::corrector::DENSE_UP_TO {
        return None;
    }
    let svd = fx.clone().svd(true, true);
    let (k, smallest) = svd.singular_values.argmin();
    let ratio = smallest / svd.singular_values.max().max(f64::MIN_POSITIVE);
    let v = svd.v_t.as_ref()?.row(k).transpose();
    let w = svd.u.as_ref()?.column(k).into_owned();
    Some((v, w, ratio))
}

impl Run<'_> {
    /// F and the dense F_x at (x, p).
    pub(super) fn dense_jacobian(
        &self,
        x: &[f64],
        p: f64,
    ) -> Result<(DVector<f64>, DMatrix<f64>), PointError> {
        let n = x.len();
        let (mut r, mut fx) = (DVector::zeros(n), DMatrix::zeros(n, n));
        self.family.residual(x, p, &mut r, &mut fx)?;
        Ok((r, fx))
    }

    /// The smallest singular pair of F_x near a multiple branch point, off
    /// it along one kernel direction (the switch's predictor): there it
    /// approximates the direction of the copies of the branch being
    /// entered, which the slice through the predictor then excludes.
    pub(super) fn nearest_kernel(&self, x: &[f64], p: f64) -> Option<(DVector<f64>, DVector<f64>)> {
        // Dense only: never the N² matrix of a large system (memory
        // linear in the mesh), which has no slice.
        if x.len() > super::corrector::DENSE_UP_TO {
            return None;
        }
        let (_, fx) = self.dense_jacobian(x, p).ok()?;
        smallest_pair(&fx).map(|(v, w, _)| (v, w))
    }

    /// The kernel of F_x at (x, p) when it is persistent.
    pub(super) fn symmetric_kernel(
        &self,
        x: &[f64],
        p: f64,
    ) -> Option<(DVector<f64>, DVector<f64>)> {
        if x.len() > super::corrector::DENSE_UP_TO {
            return None;
        }
        let (_, fx) = self.dense_jacobian(x, p).ok()?;
        persistent_kernel(&fx)
    }

    /// Newton on the slice system from `pred` (z = (x, p), τ the step's
    /// direction, the phase through `anchor`): the corrected z and the
    /// iterations, or None when it does not converge in 9 steps or μ does
    /// not vanish.
    pub(super) fn correct_sliced(
        &self,
        anchor: &[f64],
        pred: &[f64],
        tau: &[f64],
        kernel: &(DVector<f64>, DVector<f64>),
    ) -> Result<Option<(Vec<f64>, usize)>, PointError> {
        let n = anchor.len();
        let (v, w) = kernel;
        let fp = self.family.parameter_derivative(&pred[..n], pred[n])?;
        let mut y: Vec<f64> = pred.to_vec();
        y.push(0.0);
        let tol = self.opts.tolerance;
        for iteration in 1..=9 {
            let (mut r, fx) = self.dense_jacobian(&y[..n], y[n])?;
            r += w * y[n + 1];
            let mut a = DMatrix::zeros(n + 2, n + 2);
            a.view_mut((0, 0), (n, n)).copy_from(&fx);
            a.view_mut((0, n), (n, 1)).copy_from(&fp);
            a.view_mut((0, n + 1), (n, 1)).copy_from(w);
            let mut rhs = DVector::zeros(n + 2);
            rhs.rows_mut(0, n).copy_from(&r);
            for j in 0..n {
                a[(n, j)] = v[j];
                rhs[n] += v[j] * (y[j] - anchor[j]);
            }
            for j in 0..=n {
                a[(n + 1, j)] = tau[j];
                rhs[n + 1] += tau[j] * (y[j] - pred[j]);
            }
            let Some(d) = a
                .lu()
                .solve(&rhs)
                .filter(|d| d.iter().all(|v| v.is_finite()))
            else {
                return Ok(None);
            };
            for (yi, di) in y.iter_mut().zip(d.iter()) {
                *yi -= di;
            }
            let size = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            if r.amax() <= tol && d.amax() <= tol.sqrt() * size {
                if y[n + 1].abs() > tol.sqrt() {
                    return Ok(None);
                }
                y.truncate(n + 1);
                return Ok(Some((y, iteration)));
            }
        }
        Ok(None)
    }

    /// A step of a sliced branch pulled back onto the bound p = `bound`
    /// from the interpolated `guess`: the slice system with the parameter
    /// fixed in place of the arclength row (plain Newton at fixed p meets
    /// the singular F_x of the copies).
    pub(super) fn land_sliced(
        &self,
        last: &super::Point,
        guess: Vec<f64>,
        bound: f64,
        tangent: &[f64],
    ) -> Option<(Vec<f64>, f64, Vec<f64>)> {
        let n = guess.len();
        let kernel = self.symmetric_kernel(&last.unknowns, last.parameter)?;
        let mut pred = guess;
        pred.push(bound);
        let mut fix = vec![0.0; n + 1];
        fix[n] = 1.0;
        let (z, _) = self
            .correct_sliced(&last.unknowns, &pred, &fix, &kernel)
            .ok()??;
        let t = self.sliced_tangent(&z[..n], z[n], &kernel, tangent).ok()?;
        Some((z[..n].to_vec(), z[n], t))
    }

    /// The tangent at the first point of a branch: within the slice where
    /// F_x has a persistent null vector there (the start is one of a
    /// continuum of symmetric copies, e.g. a closed isotropic ring turned
    /// about its clamp's tangent), else the plain tangent. The plain one
    /// would be the copies' direction itself, along which no parameter
    /// moves and which the slice then forbids, so the first step failed.
    pub(super) fn start_tangent(
        &self,
        x: &[f64],
        p: f64,
        forward: &[f64],
    ) -> Result<Vec<f64>, PointError> {
        match self.symmetric_kernel(x, p) {
            Some(kernel) => self.sliced_tangent(x, p, &kernel, forward),
            None => self.tangent(x, p, forward),
        }
    }

    /// The unit tangent within the slice at (x, p): the null vector of
    /// [F_x F_p w; vᵀ 0 0] without its μ part, oriented along `previous`.
    pub(super) fn sliced_tangent(
        &self,
        x: &[f64],
        p: f64,
        kernel: &(DVector<f64>, DVector<f64>),
        previous: &[f64],
    ) -> Result<Vec<f64>, PointError> {
        let n = x.len();
        let (v, w) = kernel;
        let (_, fx) = self.dense_jacobian(x, p)?;
        let fp = self.family.parameter_derivative(x, p)?;
        let mut a = DMatrix::zeros(n + 2, n + 2);
        a.view_mut((0, 0), (n, n)).copy_from(&fx);
        a.view_mut((0, n), (n, 1)).copy_from(&fp);
        a.view_mut((0, n + 1), (n, 1)).copy_from(w);
        for j in 0..n {
            a[(n, j)] = v[j];
        }
        for j in 0..=n {
            a[(n + 1, j)] = previous[j];
        }
        let mut rhs = DVector::zeros(n + 2);
        rhs[n + 1] = 1.0;
        let t = a
            .lu()
            .solve(&rhs)
            .filter(|t| t.iter().all(|v| v.is_finite()))
            .ok_or(PointError::SingularTangent(p))?;
        let t = t.rows(0, n + 1).into_owned();
        if t.norm() == 0.0 {
            return Err(PointError::SingularTangent(p));
        }
        Ok(t.normalize().as_slice().to_vec())
    }
}
