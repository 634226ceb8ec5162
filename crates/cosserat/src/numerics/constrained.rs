//! The pencil (K, G) restricted to the null space of a few linear
//! constraints C v = 0: the second variation of a rod whose tip is held
//! (a position held in some directions is ∫ R(ω × e3) ds = 0 along them, a
//! held frame is ω(L) = 0 in some directions) — and raised by a few
//! *springs*, K + U Uᵀ with U = (u_1 … u_k): a position held on a
//! shearable, extensible rod is not a constraint on ω but costs the strain
//! energy of the shear and extension that keep the tip in place
//! (`stability::second_variation`, "A held position on a Cosserat rod").
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
//!
//! Springs border the same way with −I in the corner: with
//! C = [C_h; Uᵀ] (hard rows, then the springs) and D̃ = diag(0, I),
//! In([A Cᵀ; C −D̃]) = In((A + UUᵀ)|null C_h) + (m_h, m_h, 0) + (0, k, 0)
//! (eliminate the springs' multipliers first), and by Haynsworth on A the
//! count below σ is neg(A) + pos(S + D̃) − m, m = m_h + k, S = C A⁻¹Cᵀ;
//! the bordered solve is (A⁻¹ − Z (S + D̃)⁻¹ Zᵀ) b, which is
//! ((A + UUᵀ)|null C_h)⁻¹ b (Sherman–Morrison–Woodbury on the springs).
//! Only the hard rows are projected out.

use nalgebra::{DMatrix, DVector};

use super::eigen::{
    count_below, dense_pencil, diagonal_ratio, lowest_eigenpairs_estimated, lowest_eigenpairs_near,
    shift_below, shift_invert_lanczos, verify_with, BoundedPairs, EigenError, Eigenpairs, Inertia,
    ShiftEstimate, UndecidedInertia, DENSE_LIMIT,
};
use crate::numerics::banded::{BandedLdlt, SymmetricBanded};

/// Linear constraints C v = 0 with orthonormal rows (m × n), and springs
/// that add vᵀUUᵀv to the form (U n × k).
#[derive(Debug, Clone, PartialEq)]
pub struct Constraints {
    rows: DMatrix<f64>,
    springs: DMatrix<f64>,
}

impl Constraints {
    /// No constraints on vectors of size n.
    pub fn none(n: usize) -> Self {
        Constraints {
            rows: DMatrix::zeros(0, n),
            springs: DMatrix::zeros(n, 0),
        }
    }

    /// The same constraints with the springs u_j added: the form becomes
    /// vᵀKv + Σ_j (u_j·v)².
    #[must_use]
    pub fn with_springs(self, springs: &[DVector<f64>]) -> Self {
        let n = self.rows.ncols();
        Constraints {
            springs: DMatrix::from_fn(n, springs.len(), |i, j| springs[j][i]),
            ..self
        }
    }

    /// Neither constraints nor springs.
    pub fn is_empty(&self) -> bool {
        self.rows.nrows() == 0 && self.springs.ncols() == 0
    }

    /// Σ_j (u_j·v)²: what the springs add to vᵀKv.
    pub fn spring_form(&self, v: &[f64]) -> f64 {
        (self.springs.transpose() * DVector::from_column_slice(v)).norm_squared()
    }

    /// The bordering rows [C_h; Uᵀ] and the corner's diagonal: 0 for a
    /// constraint, 1 for a spring (D̃ in the module documentation).
    fn bordering(&self) -> (DMatrix<f64>, Vec<f64>) {
        let (h, k, n) = (self.rows.nrows(), self.springs.ncols(), self.rows.ncols());
        let mut c = DMatrix::zeros(h + k, n);
        c.rows_mut(0, h).copy_from(&self.rows);
        c.rows_mut(h, k).copy_from(&self.springs.transpose());
        let corner = (0..h + k).map(|i| if i < h { 0.0 } else { 1.0 }).collect();
        (c, corner)
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
        Constraints {
            rows: m,
            springs: DMatrix::zeros(n, 0),
        }
    }

    /// The number of independent constraints (springs not counted: they
    /// do not reduce the space).
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

/// A = K − σG factored, with Z = A⁻¹Cᵀ and S = C Z + D̃ (C the bordering
/// rows, D̃ the springs' identity in the corner).
struct Bordered {
    a: BandedLdlt,
    z: DMatrix<f64>,
    s: DMatrix<f64>,
}

impl Bordered {
    fn new(k: &SymmetricBanded, g: &SymmetricBanded, c: &Constraints, sigma: f64) -> Option<Self> {
        let a = k.shifted_ldlt(-sigma, g).ok()?;
        let (rows, corner) = c.bordering();
        let (m, n) = (rows.nrows(), k.size());
        let mut z = DMatrix::zeros(n, m);
        for j in 0..m {
            let mut col: Vec<f64> = rows.row(j).iter().copied().collect();
            a.solve_in_place(&mut col);
            z.set_column(j, &DVector::from_vec(col));
        }
        let s = &rows * &z;
        Some(Bordered {
            s: (&s + s.transpose()) * 0.5 + DMatrix::from_diagonal(&DVector::from_vec(corner)),
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
    fn solve(&self, s_inv: &DMatrix<f64>, b: &[f64], y: &mut [f64]) {
        let zt_b = self.z.transpose() * DVector::from_column_slice(b);
        self.a.solve(b, y);
        let corr = &self.z * (s_inv * zt_b);
        y.iter_mut().zip(corr.iter()).for_each(|(y, c)| *y -= c);
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
    if c.is_empty() {
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
    if c.is_empty() {
        return lowest_eigenpairs_near(k, g, count, previous);
    }
    constrained_lanczos(k, g, c, count, None).map(|b| b.pairs)
}

/// [`lowest_eigenpairs_constrained`] with the shift placed by `estimate`
/// where the constrained count certifies it (no eigenvalue below: see
/// [`ShiftEstimate`]), else by the Sturm bisection, and that shift
/// returned as a lower bound of the constrained spectrum.
pub fn lowest_eigenpairs_constrained_estimated(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    count: usize,
    estimate: Option<ShiftEstimate>,
) -> Result<BoundedPairs, EigenError> {
    if c.is_empty() {
        return lowest_eigenpairs_estimated(k, g, count, estimate);
    }
    constrained_lanczos(k, g, c, count, estimate)
}

/// The constrained pencil's lowest pairs by the bordered shift-invert
/// Lanczos (the dense pencil on null C for small problems).
fn constrained_lanczos(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    count: usize,
    estimate: Option<ShiftEstimate>,
) -> Result<BoundedPairs, EigenError> {
    let count = count.min(k.size().saturating_sub(c.count()));
    if k.size() <= DENSE_LIMIT {
        return Ok(BoundedPairs {
            pairs: dense_constrained(k, g, c, count)?,
            lower_bound: f64::NEG_INFINITY,
        });
    }
    let none_below = |b: &Bordered| b.count_below() == Inertia::Below(0);
    let guessed = estimate
        .map(|e| e.shift(diagonal_ratio(k, g)))
        .and_then(|s| Bordered::new(k, g, c, s).filter(none_below).map(|b| (s, b)));
    // A guessed shift whose Lanczos run fails falls back to the bisection:
    // the pairs pass the same checks either way.
    if let Some((sigma, bordered)) = guessed {
        if let Ok(pairs) = bordered_lanczos(k, g, c, count, sigma, &bordered) {
            return Ok(BoundedPairs {
                pairs,
                lower_bound: sigma,
            });
        }
    }
    let sigma = shift_below_constrained(k, g, c, count);
    let bordered = Bordered::new(k, g, c, sigma)
        .ok_or_else(|| EigenError::NotDefinite(format!("K − σG is singular at σ = {sigma}")))?;
    let lower_bound = if none_below(&bordered) {
        sigma
    } else {
        f64::NEG_INFINITY
    };
    let pairs = bordered_lanczos(k, g, c, count, sigma, &bordered)?;
    Ok(BoundedPairs { pairs, lower_bound })
}

/// The lowest `count` constrained pairs by shift-invert Lanczos from σ,
/// with `bordered` the factors of the bordered K − σG.
fn bordered_lanczos(
    k: &SymmetricBanded,
    g: &SymmetricBanded,
    c: &Constraints,
    count: usize,
    sigma: f64,
    bordered: &Bordered,
) -> Result<Eigenpairs, EigenError> {
    let s_inv = bordered
        .s
        .clone()
        .try_inverse()
        .ok_or_else(|| EigenError::NotDefinite("the constraints are degenerate".into()))?;
    // The bordered solve of G x, which the Lanczos recurrence holds.
    let apply = |_: &[f64], gx: &[f64], y: &mut [f64]| bordered.solve(&s_inv, gx, y);
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

/// Backward error of (K + UUᵀ) v − λ G v projected off the constraint
/// normals, and C v = 0, both to 1e-8, after each vector is put back on
/// null C ([`Constraints::project`]).
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
        |r, v| {
            *r += &c.springs * (c.springs.transpose() * DVector::from_column_slice(v));
            let off = c.rows.transpose() * (&c.rows * &*r);
            *r -= off;
        },
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
    let raised = k.to_dense() + &c.springs * c.springs.transpose();
    let kr = basis.transpose() * raised * &basis;
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

    /// Springs: K + uuᵀ (G = I here) against the eigenvalues of the dense
    /// matrix, with and without a hard row beside them, and the counts
    /// against those eigenvalues; a stiffening spring tends to the
    /// constraint u·v = 0 (interlacing from below).
    #[test]
    fn springs_raise_the_form_by_their_squares() {
        let n = 120;
        let (k, g, hard) = pencil(n);
        let u = DVector::from_fn(n, |i, _| (1.0 + i as f64 / n as f64).ln() * 40.0);
        let springs = Constraints::none(n).with_springs(std::slice::from_ref(&u));
        let dense = (k.to_dense() + &u * u.transpose()).symmetric_eigen();
        let mut exact: Vec<f64> = dense.eigenvalues.iter().copied().collect();
        exact.sort_by(f64::total_cmp);
        let pairs = lowest_eigenpairs_constrained(&k, &g, &springs, 4, None).unwrap();
        for (a, b) in pairs.values.iter().zip(&exact) {
            assert!((a - b).abs() < 1e-8 * b.abs(), "{a} vs {b}");
        }
        for v in &pairs.vectors {
            let lambda = (DVector::from_column_slice(v).transpose()
                * (k.to_dense() + &u * u.transpose())
                * DVector::from_column_slice(v))[0]
                / DVector::from_column_slice(v).norm_squared();
            assert!(pairs
                .values
                .iter()
                .any(|l| (l - lambda).abs() < 1e-8 * l.abs()));
        }
        let sigma = 0.5 * (exact[1] + exact[2]);
        assert_eq!(
            count_below_constrained(&k, &g, &springs, sigma),
            Inertia::Below(2)
        );
        // Beside hard rows: against the projected dense pencil of K + uuᵀ.
        let both = hard.clone().with_springs(std::slice::from_ref(&u));
        let sparse = lowest_eigenpairs_constrained(&k, &g, &both, 3, None).unwrap();
        let reference = dense_constrained(&k, &g, &both, 3).unwrap();
        for (a, b) in sparse.values.iter().zip(&reference.values) {
            assert!((a - b).abs() < 1e-8 * b.abs(), "{a} vs {b}");
        }
        let sigma = 0.5 * (reference.values[1] + reference.values[2]);
        assert_eq!(
            count_below_constrained(&k, &g, &both, sigma),
            Inertia::Below(2)
        );
        // A spring 10⁴ times stiffer approaches the constraint u·v = 0.
        let stiff = Constraints::none(n).with_springs(&[&u * 1e4]);
        let held = Constraints::from_rows(std::slice::from_ref(&u), n);
        let (a, b) = (
            lowest_eigenpairs_constrained(&k, &g, &stiff, 1, None)
                .unwrap()
                .values[0],
            lowest_eigenpairs_constrained(&k, &g, &held, 1, None)
                .unwrap()
                .values[0],
        );
        assert!(a < b && (b - a) < 1e-4 * b, "{a} vs {b}");
    }
}
