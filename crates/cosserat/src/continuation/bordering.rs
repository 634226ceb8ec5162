//! The linear algebra of the minimally augmented systems (`fold.rs`,
//! `branch_point.rs`) in the shape of F_x ([`Linearization`]): dense for
//! single shooting and small systems, O(N) for the almost block diagonal
//! F_x of multiple shooting and collocation — so that a fold or a branch
//! point is located on its augmented system on any mesh, not only below a
//! dense limit.
//!
//! Near a simple singular point F_x is bordered by approximate null
//! vectors, K = [F_x b; cᵀ 0] (c right, b left: Govaerts, *Numerical
//! Methods for Bifurcations of Dynamical Equilibria*, SIAM 2000, §3.2),
//! which is regular there while F_x is not. K and Kᵀ are solved through
//! the banded embedding of the staircase ([`StaircaseLu`]), and every
//! Newton matrix of an augmented system differs from K (extended by an
//! identity) by a few rows and columns, so it is solved by the
//! Sherman–Morrison–Woodbury formula on K's factors
//! ([`low_rank_solve`]): never a dense (N + 1)² matrix.

use nalgebra::{DMatrix, DVector, Dyn, LU};

use super::corrector::Linearization;
use super::kernel::BandedJacobian;
use super::{PointError, Run};
use crate::numerics::staircase::{Border, StaircaseLu};

/// Approximate right and left null vectors of a nearly singular dense F_x,
/// by two steps of inverse iteration on F_x and F_xᵀ from a fixed start
/// (one LU each; an SVD costs seconds at a thousand unknowns): the borders
/// need only complement the kernel and the range, and at a bracketed
/// singular point F_x's smallest singular value is far below the next, so
/// one step already isolates the null vectors. An F_x singular in floating
/// point (a point located to round-off) is shifted by ε max|F_x| before
/// it is factored, as inverse iteration's zero pivots are floored
/// ([`crate::numerics::band_lu::BandLu::factor_for_inverse_iteration`]).
pub(super) fn dense_null_vectors(fx: &DMatrix<f64>) -> Option<(DVector<f64>, DVector<f64>)> {
    let n = fx.nrows();
    let start = DVector::from_fn(n, |i, _| 1.0 + (0.618_033_988_75 * i as f64).fract());
    let factored = |m: DMatrix<f64>| {
        let lu = m.clone().lu();
        if lu.is_invertible() {
            return lu;
        }
        let shift = f64::EPSILON * m.amax();
        (m + DMatrix::identity(n, n) * shift).lu()
    };
    let (lu, lu_t) = (factored(fx.clone()), factored(fx.transpose()));
    let (mut right, mut left) = (start.clone(), start);
    for _ in 0..2 {
        right = lu.solve(&right)?.normalize();
        left = lu_t.solve(&left)?.normalize();
    }
    (finite(&right) && finite(&left)).then_some((right, left))
}

/// The approximate right and left null vectors of F_x near a simple
/// singular point: inverse iteration on the dense matrix, or the smallest
/// singular pair of the band copy of a staircase
/// ([`BandedJacobian::smallest`], O(N)).
pub(super) fn null_vectors(fx: &Linearization) -> Option<(DVector<f64>, DVector<f64>)> {
    match fx {
        Linearization::Dense(m) => dense_null_vectors(m),
        Linearization::Staircase(a) => {
            let smallest = BandedJacobian::of(a)?.smallest(1)?;
            let right = smallest.right.column(0).into_owned();
            let left = smallest.left.column(0).into_owned();
            (finite(&right) && finite(&left)).then_some((right, left))
        }
    }
}

fn finite(v: &DVector<f64>) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// K = [F_x b; cᵀ 0] factored in F_x's shape, with its transposed solves.
pub(super) struct BorderedJacobian {
    fx: Linearization,
    column: DVector<f64>,
    row: DVector<f64>,
    factors: Factors,
}

/// A dense LU.
type DenseLu = LU<f64, Dyn, Dyn>;

enum Factors {
    /// LU of K and of Kᵀ (nalgebra's LU has no transposed solve).
    Dense { k: DenseLu, transposed: DenseLu },
    /// The banded embedding of K, solved either way.
    Staircase(Box<StaircaseLu>),
}

impl BorderedJacobian {
    /// Factors K = [fx column; rowᵀ 0]; None where a band pivot is exactly
    /// zero (K singular: b, c do not complement F_x's range and kernel).
    pub fn new(fx: Linearization, column: DVector<f64>, row: DVector<f64>) -> Option<Self> {
        let factors = match &fx {
            Linearization::Dense(m) => {
                let n = m.nrows();
                let mut k = DMatrix::zeros(n + 1, n + 1);
                k.view_mut((0, 0), (n, n)).copy_from(m);
                k.view_mut((0, n), (n, 1)).copy_from(&column);
                k.view_mut((n, 0), (1, n)).copy_from(&row.transpose());
                let transposed = k.transpose();
                Factors::Dense {
                    k: k.lu(),
                    transposed: transposed.lu(),
                }
            }
            Linearization::Staircase(a) => {
                let mut lu = StaircaseLu::default();
                let border = Border {
                    column: column.as_slice(),
                    row: row.as_slice(),
                    corner: 0.0,
                };
                lu.factor(a, Some(&border)).ok()?;
                Factors::Staircase(Box::new(lu))
            }
        };
        Some(BorderedJacobian {
            fx,
            column,
            row,
            factors,
        })
    }

    /// K's border column b.
    pub fn column(&self) -> &DVector<f64> {
        &self.column
    }

    /// K's border row c.
    pub fn row(&self) -> &DVector<f64> {
        &self.row
    }

    /// K⁻¹ rhs (length N + 1); None where it is not finite.
    pub fn solve(&mut self, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        self.solve_either(rhs, false)
    }

    /// K⁻ᵀ rhs (length N + 1); None where it is not finite.
    pub fn solve_transposed(&mut self, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        self.solve_either(rhs, true)
    }

    fn solve_either(&mut self, rhs: &DVector<f64>, transposed: bool) -> Option<DVector<f64>> {
        let z = match &mut self.factors {
            Factors::Dense { k, transposed: t } => {
                let lu = if transposed { t } else { k };
                lu.solve(rhs)?
            }
            Factors::Staircase(lu) => {
                let Linearization::Staircase(a) = &self.fx else {
                    return None;
                };
                let border = Border {
                    column: self.column.as_slice(),
                    row: self.row.as_slice(),
                    corner: 0.0,
                };
                let mut z = DVector::zeros(rhs.len());
                let solved = if transposed {
                    lu.solve_bordered_transposed(a, &border, rhs.as_slice(), z.as_mut_slice())
                } else {
                    lu.solve_bordered(a, &border, rhs.as_slice(), z.as_mut_slice())
                };
                solved.then_some(z)?
            }
        };
        finite(&z).then_some(z)
    }
}

/// What K = [F_x b; cᵀ 0] says of F_x's singularity: K[v; g] = e and
/// Kᵀ[w; ·] = e (e the last unit vector) — g vanishes exactly where F_x is
/// singular, with v, w its right and left null vectors there.
pub(super) struct Singularity {
    pub g: f64,
    pub v: DVector<f64>,
    pub w: DVector<f64>,
}

impl BorderedJacobian {
    /// g, v and w (see [`Singularity`]); None where a solve fails.
    pub fn singularity(&mut self) -> Option<Singularity> {
        let n = self.column.len();
        let mut e = DVector::zeros(n + 1);
        e[n] = 1.0;
        let vg = self.solve(&e)?;
        let w = self.solve_transposed(&e)?.rows(0, n).into_owned();
        Some(Singularity {
            g: vg[n],
            v: vg.rows(0, n).into_owned(),
            w,
        })
    }
}

/// wᵀF_xx[d, ·] at x, as a column: the central difference of the
/// transposed products F_x(x ± εd)ᵀw with ε = 10⁻⁶ max(1, ‖x‖∞)/‖d‖∞
/// (F_xx is symmetric in its two arguments, so one difference along d
/// gives the whole row; zero along a zero direction). `linearize` gives
/// F_x at a point, the parameters held.
pub(super) fn curvature_row<E>(
    linearize: impl Fn(&[f64]) -> Result<Linearization, E>,
    x: &[f64],
    d: &DVector<f64>,
    w: &DVector<f64>,
) -> Result<DVector<f64>, E> {
    if d.amax() == 0.0 {
        return Ok(DVector::zeros(x.len()));
    }
    let eps = 1e-6 * x.iter().fold(1.0f64, |m, v| m.max(v.abs())) / d.amax();
    let shifted = |sign: f64| -> Vec<f64> {
        x.iter()
            .zip(d.iter())
            .map(|(a, e)| a + sign * eps * e)
            .collect()
    };
    let up = linearize(&shifted(1.0))?.mul_transposed(w);
    let down = linearize(&shifted(-1.0))?.mul_transposed(w);
    Ok((up - down) / (2.0 * eps))
}

/// The solution of (K + U Vᵀ) z = r by the Sherman–Morrison–Woodbury
/// formula (Golub & Van Loan, *Matrix Computations*, 4th ed., §2.1.4):
/// z = y − Z C⁻¹ Vᵀ y with K y = r, K Z = U and the small capacitance
/// matrix C = I + Vᵀ Z. `solve_k` applies K⁻¹; `u`, `v` are the columns
/// of U and V. Where K is well conditioned (a bordered F_x near its
/// singular point) C is regular exactly when K + U Vᵀ is. None where a
/// solve fails or C is singular.
pub(super) fn low_rank_solve(
    mut solve_k: impl FnMut(&DVector<f64>) -> Option<DVector<f64>>,
    u: &[DVector<f64>],
    v: &[DVector<f64>],
    r: &DVector<f64>,
) -> Option<DVector<f64>> {
    let y = solve_k(r)?;
    let z: Vec<DVector<f64>> = u.iter().map(&mut solve_k).collect::<Option<_>>()?;
    let m = u.len();
    let capacitance = DMatrix::from_fn(m, m, |i, j| f64::from(u8::from(i == j)) + v[i].dot(&z[j]));
    let vy = DVector::from_fn(m, |i, _| v[i].dot(&y));
    let coefficients = capacitance.lu().solve(&vy)?;
    let mut out = y;
    for (zj, cj) in z.iter().zip(coefficients.iter()) {
        out.axpy(-cj, zj, 1.0);
    }
    finite(&out).then_some(out)
}

impl Run<'_> {
    /// F(x, p) and F_x at (x, p) in the shape the corrector uses
    /// ([`Linearization`]).
    pub(super) fn linearization(
        &self,
        x: &[f64],
        p: f64,
    ) -> Result<(DVector<f64>, Linearization), PointError> {
        let mut fx = Linearization::of(self.family);
        let mut r = DVector::zeros(x.len());
        fx.evaluate(self.family, x, p, &mut r)?;
        Ok((r, fx))
    }

    /// F_x at (x, p) times d.
    pub(super) fn product(
        &self,
        x: &[f64],
        p: f64,
        d: &DVector<f64>,
    ) -> Result<DVector<f64>, PointError> {
        Ok(self.linearization(x, p)?.1.mul(d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Woodbury against the dense solve of K + U Vᵀ.
    #[test]
    fn low_rank_solve_is_the_dense_solve() {
        let n = 7;
        let k = DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                3.0 + i as f64
            } else {
                ((i * 7 + j * 3) % 5) as f64 / 5.0 - 0.4
            }
        });
        let u = vec![
            DVector::from_fn(n, |i, _| (i as f64).sin()),
            DVector::from_fn(n, |i, _| if i == n - 1 { 1.0 } else { 0.0 }),
        ];
        let v = vec![
            DVector::from_fn(n, |i, _| (i as f64 * 0.7).cos()),
            DVector::from_fn(n, |i, _| 0.3 * i as f64 - 1.0),
        ];
        let r = DVector::from_fn(n, |i, _| 1.0 + i as f64);
        let lu = k.clone().lu();
        let z = low_rank_solve(|b| lu.solve(b), &u, &v, &r).unwrap();
        let full = &k + &u[0] * v[0].transpose() + &u[1] * v[1].transpose();
        let dense = full.lu().solve(&r).unwrap();
        assert!((z - &dense).amax() <= 1e-12 * dense.amax());
    }
}
