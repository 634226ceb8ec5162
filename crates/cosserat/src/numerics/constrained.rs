//! The pencil (K, G) restricted to the null space of a few linear
//! constraints C v = 0: the second variation of a rod whose tip is held
//! (a position held in some directions is ∫ R(ω × e3) ds = 0 along them, a
//! held frame is ω(L) = 0 in some directions).
//!
//! With m ≪ n constraints nothing dense of size n is formed. For a shift σ
//! and A = K − σG (banded LDLᵀ), Z = A⁻¹Cᵀ and S = C Z (m × m):
//!
//! * inertia: by Haynsworth's formula on the bordered matrix
//!   [A Cᵀ; C 0] and In([A Cᵀ; C 0]) = In(A|null C) + (m, m, 0)
//!   (Gould, Math. Prog. 32 (1985)), the number of eigenvalues of the
//!   constrained pencil below σ is neg(A) + pos(S) − m;
//! * shift-invert: T = (A⁻¹ − Z S⁻¹ Zᵀ) G solves the bordered system; it
//!   is G-self-adjoint, maps into null C, and on null C its eigenvalues are
//!   1/(λ − σ), so the Lanczos of [`super::eigen`] applies unchanged.
//!
//! Each solve costs m + 1 banded solves: still O(n) per eigenvalue.

use nalgebra::{DMatrix, DVector};

use super::eigen::{
    count_below, dense_pencil, diagonal_ratio, lowest_eigenpairs_near, shift_below,
    shift_invert_lanczos, verify_with, EigenError, Eigenpairs, Inertia, UndecidedInertia,
    DENSE_LIMIT,
};
use crate::numerics::banded::{BandedLdlt, SymmetricBanded};

/// Linear constraints C v = 0 with orthonormal rows (m × n).
#[derive(Debug, Clone, PartialEq)]
pub struct Constraints {
    rows: DMatrix<f64>,
}

impl Constraints {
    /// No constraints on vectors of size n.
    pub fn none(n: usize) -> Self {
        Constraints {
            rows: DMatrix::zeros(0, n),
        }
    }

    /// From rows that may be dependent or zero: Gram–Schmidt keeps an
    /// orthonormal basis of their span (rows below 1e-10 of the largest
    /// are dropped).
    pub fn from_rows(rows: &[DVector<f64>], n: usize) -> Self {
        let scale = rows.iter().map(nalgebra::Matrix::norm).fold(0.0, f64::max);
        let mut basis: Vec<DVector<f64>> = Vec::new();
        for r in rows {
            let mut v = r.clone();
            for _ in 0..2 {
                for b in &basis {
                    v -= b * b.dot(&v);
                }
            }
            let norm = v.norm();
            if norm > 1e-10 * scale {
                basis.push(v / norm);
            }
        }
        let mut m = DMatrix::zeros(basis.len(), n);
        for (i, b) in basis.iter().enumerate() {
            m.set_row(i, &b.transpose());
        }
        Constraints { rows: m }
    }

    /// The number of independent constraints.
    pub fn count(&self) -> usize {
        self.rows.nrows()
    }

    /// C v.
    fn apply(&self, v: &[f64]) -> DVector<f64> {
        &self.rows * DVector::from_column_slice(v)
    }

    /// v ← (v − Cᵀ C v) / ‖·‖_G: the orthogonal projection onto null C
    /// (the rows are orthonormal), normalized again in the metric `g`.
    fn project(&self, v: &mut [f64], g: &SymmetricBanded) {
        let off = self.rows.transpose() * self.apply(v);
        v.iter_mut().zip(off.iter()).for_each(|(a, b)| *a -= b);
        let norm = g.inner(v, v).sqrt();
        if norm > 0.0 && norm.is_finite() {
            for a in v.iter_mut() {
                *a /= norm;
            }
        }
    }
}

/// A = K − σG factored, with Z = A⁻¹Cᵀ and S = C Z.
struct Bordered {
    a: BandedLdlt,
    z: DMatrix<f64>,
    s: DMatrix<f64>,
}

impl Bordered {
    fn new(k: &SymmetricBanded, g: &SymmetricBanded, c: &Constraints, sigma: f64) -> Option<Self> {
        let a = k.combine(1.0, g, -sigma).ldlt().ok()?;
        let (m, n) = (c.count(), k.size());
        let mut z = DMatrix::zeros(n, m);
        for j in 0..m {
            let mut col: Vec<f64> = c.rows.row(j).iter().copied().collect();
            a.solve_in_place(&mut col);
            z.set_column(j, &DVector::from_vec(col));
        }
        let s = &c.rows * &z;
        Some(Bordered {
            s: (&s + s.transpose()) * 0.5,
            a,
            z,
        })
    }

    /// neg(A) + pos(S) − m, undecided when round-off made it negative (the
    /// count cannot be trusted; it used to saturate to 0, "stable").
    fn count_below(&self) -> Inertia {
        let pos = self
            .s
            .symmetric_eigenvalues()
            .iter()
            .filter(|&&v| v > 0.0)
            .count();
        (self.a.negative_pivots() + pos)
            .checked_sub(self.s.nrows())
            .ok_or(UndecidedInertia::RoundOff)
            .into()
    }

    /// y = (A⁻¹ − Z S⁻¹ Zᵀ) b.
    fn solve(&self, s_inv: &DMatrix<f64>, b: &mut [f64]) {
        let zt_b = self.z.transpose() * DVector::from_column_slice(b);
        self.a.solve_in_place(b);
        let corr = &self.z * (s_inv * zt_b);
        b.iter_mut().zip(corr.iter()).for_each(|(y, c)| *y -= c);
    }
}

/// The number of eigenvalues below σ of (K, G) on null C, or
/// [`Inertia::Undecided`] when it cannot be counted (K − σG has zero pivots
/// at σ and at every nudge, or round-off spoilt the count), never a default
/// count.
pub fn count_below_constrained(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    sigma: f64,
) -> Inertia {
    if c.count() == 0 {
        return count_below(k, g, sigma);
    }
    try_count_below_constrained(k, g, c, sigma)
}

/// The count, or undecided (persistent zero pivots, round-off).
fn try_count_below_constrained(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    sigma: f64,
) -> Inertia {
    let nudge = 1e-10 * diagonal_ratio(k, g);
    let mut s = sigma;
    for _ in 0..8 {
        if let Some(b) = Bordered::new(k, g, c, s) {
            return b.count_below();
        }
        s += nudge;
    }
    Inertia::Undecided(UndecidedInertia::ZeroPivots { size: k.size() })
}

/// The `count` lowest eigenpairs of (K, G) on null C; `previous` as in
/// [`lowest_eigenpairs_near`].
pub fn lowest_eigenpairs_constrained(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    count: usize,
    previous: Option<(f64, f64)>,
) -> Result<Eigenpairs, EigenError> {
    if c.count() == 0 {
        return lowest_eigenpairs_near(k, g, count, previous);
    }
    let count = count.min(k.size().saturating_sub(c.count()));
    if k.size() <= DENSE_LIMIT {
        return dense_constrained(k, g, c, count);
    }
    let sigma = shift_below_constrained(k, g, c, count);
    let bordered = Bordered::new(k, g, c, sigma)
        .ok_or_else(|| EigenError::NotDefinite(format!("K − σG is singular at σ = {sigma}")))?;
    let s_inv = bordered
        .s
        .clone()
        .try_inverse()
        .ok_or_else(|| EigenError::NotDefinite("the constraints are degenerate".into()))?;
    let apply = |x: &[f64], y: &mut [f64]| {
        g.matvec(x, y);
        bordered.solve(&s_inv, y);
    };
    let below = |s: f64| count_below_constrained(k, g, c, s);
    shift_invert_lanczos(
        k.size(),
        count,
        sigma,
        apply,
        g,
        |ritz| verify(k, g, c, ritz),
        below,
    )
}

/// A shift below the constrained spectrum: [`shift_below`] on the
/// constrained Sturm count.
fn shift_below_constrained(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    wanted: usize,
) -> f64 {
    shift_below(diagonal_ratio(k, g), wanted, |s| {
        try_count_below_constrained(k, g, c, s).below()
    })
}

/// Backward error of K v − λ G v projected off the constraint normals, and
/// C v = 0, both to 1e-8, after each vector is put back on null C
/// ([`Constraints::project`]).
///
/// A Ritz vector leaves null C by the round-off of the bordered solves
/// (Z S⁻¹ Zᵀ, S = C A⁻¹Cᵀ as ill-conditioned as the pencil's scaling
/// makes it): with 16 or 28 elements of a held rod this was above 1e-8 of
/// ‖v‖ for pairs whose backward error was 3e-12, and Lanczos failed
/// (issue 16). The projection is exact, so C v = 0 holds to round-off of
/// the projection itself, and the backward error of the projected pair is
/// what decides: a pair that needed its off-null part fails it, so nothing
/// wrong is accepted.
fn verify(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    mut pairs: Eigenpairs,
) -> Result<Eigenpairs, EigenError> {
    for v in &mut pairs.vectors {
        c.project(v, g);
    }
    verify_with(
        k,
        g,
        pairs,
        |r| &r - c.rows.transpose() * (&c.rows * &r),
        |v| c.apply(v).norm() <= 1e-8 * DVector::from_column_slice(v).norm(),
    )
}

/// Small problems: an orthonormal basis N of null C (Gram–Schmidt on the
/// columns of I − CᵀC, C having orthonormal rows), the dense pencil
/// (NᵀKN, NᵀGN), and v = N u.
fn dense_constrained(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    count: usize,
) -> Result<Eigenpairs, EigenError> {
    let n = k.size();
    let dim = n - c.count();
    let projector = DMatrix::identity(n, n) - c.rows.transpose() * &c.rows;
    let mut basis = DMatrix::zeros(n, dim);
    let mut found = 0;
    for j in 0..n {
        if found == dim {
            break;
        }
        let mut v = projector.column(j).into_owned();
        for _ in 0..2 {
            for i in 0..found {
                let b = basis.column(i).into_owned();
                v -= &b * b.dot(&v);
            }
        }
        let norm = v.norm();
        if norm > 1e-8 {
            basis.set_column(found, &(v / norm));
            found += 1;
        }
    }
    let kr = basis.transpose() * k.to_dense() * &basis;
    let gr = basis.transpose() * g.to_dense() * &basis;
    let pairs = dense_pencil(&kr, &gr, count)?;
    Ok(Eigenpairs {
        values: pairs.values,
        vectors: pairs
            .vectors
            .iter()
            .map(|u| (&basis * DVector::from_column_slice(u)).as_slice().to_vec())
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// −u'' on (0, 1), u(0) = 0, u'(1) = 0 (central differences), and two
    /// dense constraints: the mean of u and a sine moment vanish.
    fn pencil(n: usize) -> (SymmetricBanded, SymmetricBanded, Constraints) {
        let h = 1.0 / n as f64;
        let mut k = SymmetricBanded::zeros(n, 1);
        let mut g = SymmetricBanded::zeros(n, 1);
        for i in 0..n {
            k.add(i, i, if i + 1 == n { 1.0 } else { 2.0 } / (h * h));
            if i > 0 {
                k.add(i, i - 1, -1.0 / (h * h));
            }
            g.add(i, i, 1.0);
        }
        let mean = DVector::from_element(n, 1.0);
        let sine = DVector::from_fn(n, |i, _| (3.0 * i as f64 * h).sin());
        (k, g, Constraints::from_rows(&[mean, sine], n))
    }

    /// Lanczos on the bordered operator against the dense pencil projected
    /// on an explicit null-space basis, and the inertia formula against the
    /// projected eigenvalues.
    #[test]
    fn bordered_lanczos_matches_the_projected_pencil() {
        let (k, g, c) = pencil(120);
        let sparse = lowest_eigenpairs_constrained(&k, &g, &c, 4, None).unwrap();
        let dense = dense_constrained(&k, &g, &c, 6).unwrap();
        for (a, b) in sparse.values.iter().zip(&dense.values) {
            assert!((a - b).abs() < 1e-8 * b.abs(), "{a} vs {b}");
        }
        for v in &sparse.vectors {
            assert!(c.apply(v).norm() < 1e-10);
        }
        let sigma = 0.5 * (dense.values[2] + dense.values[3]);
        assert_eq!(
            count_below_constrained(&k, &g, &c, sigma),
            Inertia::Below(3)
        );
        // The constraints raise the spectrum (interlacing).
        let free = lowest_eigenpairs_near(&k, &g, 1, None).unwrap();
        assert!(sparse.values[0] > free.values[0]);
    }
}
