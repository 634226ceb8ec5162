//! Symmetric banded matrices and their LDLᵀ factorization.
//!
//! Finite elements couple only neighbouring elements, so a stiffness K and
//! mass matrix G assembled from them are banded with a half-bandwidth of a
//! few entries. LDLᵀ without pivoting costs O(n·b²); by Sylvester's law of
//! inertia the number of negative pivots of K − σG counts the eigenvalues of
//! the pencil (K, G) below σ (a Sturm count), and all pivots positive shows
//! K positive definite (a "try of Cholesky"; the stability stage's test of
//! the second variation).

use nalgebra::DMatrix;

/// A symmetric n×n matrix with Aᵢⱼ = 0 for |i − j| > bw, stored by its
/// lower band row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct SymmetricBanded {
    n: usize,
    bw: usize,
    data: Vec<f64>,
}

/// A factorization that met a zero pivot (σ is an eigenvalue to round-off).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("zero pivot at row {row} of LDLᵀ (the shift is an eigenvalue to round-off)")]
pub struct PivotBreakdown {
    /// The row of the zero pivot.
    pub row: usize,
}

impl SymmetricBanded {
    /// The zero matrix of size n with half-bandwidth bw.
    pub fn zeros(n: usize, bw: usize) -> Self {
        SymmetricBanded {
            n,
            bw,
            data: vec![0.0; n * (bw + 1)],
        }
    }

    /// Size.
    pub fn size(&self) -> usize {
        self.n
    }

    /// Half-bandwidth.
    pub fn bandwidth(&self) -> usize {
        self.bw
    }

    fn index(&self, i: usize, j: usize) -> usize {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        debug_assert!(i - j <= self.bw, "({i}, {j}) outside the band {}", self.bw);
        i * (self.bw + 1) + (i - j)
    }

    /// Aᵢⱼ (zero outside the band).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if i.abs_diff(j) > self.bw {
            0.0
        } else {
            self.data[self.index(i, j)]
        }
    }

    /// Aᵢⱼ += v (and so Aⱼᵢ); |i − j| ≤ bw.
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let k = self.index(i, j);
        self.data[k] += v;
    }

    /// y = A x: each stored row of the lower band gives y_i its lower part
    /// and scatters the mirrored upper part (slices, no per-entry index
    /// checks: the Lanczos loop's most frequent product).
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        assert!(x.len() == self.n && y.len() == self.n, "sizes differ");
        // Row i writes y_i before any row below scatters into it, so y
        // needs no clearing first.
        for (i, row) in self.data.chunks_exact(self.bw + 1).enumerate() {
            let reach = self.bw.min(i);
            let xi = x[i];
            let mut acc = row[0] * xi;
            let lower = row[1..=reach].iter();
            let (xs, ys) = (&x[i - reach..i], &mut y[i - reach..i]);
            for ((a, xj), yj) in lower.zip(xs.iter().rev()).zip(ys.iter_mut().rev()) {
                acc += a * xj;
                *yj += a * xi;
            }
            y[i] = acc;
        }
    }

    /// max_i Σ_j |A_ij|, the ∞-norm (rows of the band and their mirrored
    /// upper parts in one pass).
    pub fn row_sum_norm(&self) -> f64 {
        let mut sums = vec![0.0; self.n];
        for (i, row) in self.data.chunks_exact(self.bw + 1).enumerate() {
            let reach = self.bw.min(i);
            let lower = row[1..=reach]
                .iter()
                .zip(sums[i - reach..i].iter_mut().rev());
            let mut own = row[0].abs();
            for (a, upper) in lower {
                own += a.abs();
                *upper += a.abs();
            }
            sums[i] += own;
        }
        sums.into_iter().fold(0.0, f64::max)
    }

    /// xᵀ A y.
    pub fn inner(&self, x: &[f64], y: &[f64]) -> f64 {
        let mut ay = vec![0.0; self.n];
        self.matvec(y, &mut ay);
        x.iter().zip(&ay).map(|(a, b)| a * b).sum()
    }

    /// a·self + b·other (same size; the wider band is kept).
    #[must_use]
    pub fn combine(&self, a: f64, other: &SymmetricBanded, b: f64) -> SymmetricBanded {
        assert_eq!(self.n, other.n, "sizes differ");
        let bw = self.bw.max(other.bw);
        let mut out = SymmetricBanded::zeros(self.n, bw);
        for i in 0..self.n {
            for d in 0..=bw.min(i) {
                let v = a * self.get(i, i - d) + b * other.get(i, i - d);
                out.data[i * (bw + 1) + d] = v;
            }
        }
        out
    }

    /// The dense matrix (small meshes and tests).
    pub fn to_dense(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }

    /// LDLᵀ without pivoting, O(n·bw²).
    pub fn ldlt(&self) -> Result<BandedLdlt, PivotBreakdown> {
        let w = self.bw + 1;
        factored(self.n, self.bw, |i, d| self.data[i * w + d])
    }

    /// The LDLᵀ factors of self + b·other (K − σG for b = −σ) without
    /// forming the sum.
    pub fn shifted_ldlt(
        &self,
        b: f64,
        other: &SymmetricBanded,
    ) -> Result<BandedLdlt, PivotBreakdown> {
        assert_eq!(self.n, other.n, "sizes differ");
        let bw = self.bw.max(other.bw);
        if self.bw == other.bw {
            let w = bw + 1;
            factored(self.n, bw, |i, d| {
                self.data[i * w + d] + b * other.data[i * w + d]
            })
        } else {
            factored(self.n, bw, |i, d| {
                self.get(i, i - d) + b * other.get(i, i - d)
            })
        }
    }

    /// The number of negative pivots of the LDLᵀ factors of self + b·other
    /// (the inertia of K − σG for b = −σ), as [`Self::shifted_ldlt`]
    /// counts them and with the same zero-pivot test, without storing L:
    /// a Sturm count costs O(n·bw²) work in O(bw²) memory (at 4·10⁵
    /// unknowns the stored factors were 20 MB written and read for one
    /// number).
    pub fn shifted_negative_pivots(
        &self,
        b: f64,
        other: &SymmetricBanded,
    ) -> Result<usize, PivotBreakdown> {
        assert_eq!(self.n, other.n, "sizes differ");
        let bw = self.bw.max(other.bw);
        if self.bw == other.bw {
            let w = bw + 1;
            let entry = |i: usize, d: usize| self.data[i * w + d] + b * other.data[i * w + d];
            factor_rows(self.n, bw, entry)
        } else {
            let entry = |i: usize, d: usize| self.get(i, i - d) + b * other.get(i, i - d);
            factor_rows(self.n, bw, entry)
        }
    }
}

/// The stored factors of the band matrix with entries `entry(i, d)` =
/// A[i, i − d], column by column: D_j = A_jj − Σ_k L_jk² D_k, then
/// L_ij = (A_ij − Σ_k L_ik L_jk D_k)/D_j below it, with the zero-pivot
/// test of [`factor_rows`].
fn factored(
    n: usize,
    bw: usize,
    entry: impl Fn(usize, usize) -> f64,
) -> Result<BandedLdlt, PivotBreakdown> {
    let w = bw + 1;
    let mut l = vec![0.0; n * w];
    let mut d = vec![0.0; n];
    let scale = pivot_scale(n, &entry);
    for j in 0..n {
        let mut djj = entry(j, 0);
        for k in j.saturating_sub(bw)..j {
            let ljk = l[j * w + (j - k)];
            djj -= ljk * ljk * d[k];
        }
        if djj.abs() <= 1e3 * f64::EPSILON * scale || !djj.is_finite() {
            return Err(PivotBreakdown { row: j });
        }
        d[j] = djj;
        for i in j + 1..n.min(j + bw + 1) {
            let mut v = entry(i, i - j);
            for k in i.saturating_sub(bw)..j {
                v -= l[i * w + (i - k)] * l[j * w + (j - k)] * d[k];
            }
            l[i * w + (i - j)] = v / djj;
        }
    }
    Ok(BandedLdlt {
        n,
        bw,
        l,
        negative: d.iter().filter(|&&v| v < 0.0).count(),
        inverse_pivots: d.iter().map(|v| 1.0 / v).collect(),
    })
}

/// max |A_ii|, the scale of the zero-pivot test.
fn pivot_scale(n: usize, entry: &impl Fn(usize, usize) -> f64) -> f64 {
    (0..n)
        .map(|i| entry(i, 0).abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE)
}

/// The number of negative pivots of LDLᵀ without pivoting of the
/// symmetric band matrix with entries `entry(i, d)` = A[i, i − d]
/// (d ≤ bw), or the row of a zero pivot (|D_i| ≤ 1e3 ε max|A_jj|, or not
/// finite), row by row: row i needs only the rows i − bw … i − 1 of L,
/// kept in a ring of bw + 1 rows, and u_d = L[i, i − d]·D_{i−d} is formed
/// first so that each entry of L costs one product per term: O(n·bw²)
/// work in O(bw²) memory.
fn factor_rows(
    n: usize,
    bw: usize,
    entry: impl Fn(usize, usize) -> f64,
) -> Result<usize, PivotBreakdown> {
    let scale = pivot_scale(n, &entry);
    let rows = bw + 1;
    let width = bw.max(1);
    // ring[(r % rows) * width + (d − 1)] = L[r, r − d]; pivots[r % rows] = D_r.
    let mut ring = vec![0.0; rows * width];
    let mut pivots = vec![0.0; rows];
    // u[d − 1] = L[i, i − d]·D_{i−d} of the current row.
    let mut u = vec![0.0; width];
    let mut negative = 0;
    for i in 0..n {
        let reach = bw.min(i);
        for d in (1..=reach).rev() {
            let row_j = ((i - d) % rows) * width;
            let mut v = entry(i, d);
            // k = i − e for e = d + 1 ..= reach (columns left of j = i − d).
            for e in d + 1..=reach {
                v -= u[e - 1] * ring[row_j + (e - d - 1)];
            }
            u[d - 1] = v;
        }
        let row_i = (i % rows) * width;
        let mut pivot = entry(i, 0);
        for d in 1..=reach {
            let lik = u[d - 1] / pivots[(i - d) % rows];
            pivot -= u[d - 1] * lik;
            ring[row_i + d - 1] = lik;
        }
        if pivot.abs() <= 1e3 * f64::EPSILON * scale || !pivot.is_finite() {
            return Err(PivotBreakdown { row: i });
        }
        pivots[i % rows] = pivot;
        negative += usize::from(pivot < 0.0);
    }
    Ok(negative)
}

/// A = L D Lᵀ with L unit lower banded, stored by rows of its lower band
/// (L[i, i − d] at d, the unit diagonal not read), and D by its inverse.
#[derive(Debug, Clone)]
pub struct BandedLdlt {
    n: usize,
    bw: usize,
    l: Vec<f64>,
    inverse_pivots: Vec<f64>,
    negative: usize,
}

impl BandedLdlt {
    /// The number of negative pivots: by Sylvester's law of inertia, the
    /// number of negative eigenvalues of A.
    pub fn negative_pivots(&self) -> usize {
        self.negative
    }

    /// Solves A x = b in place: L y = b, then Lᵀ x = D⁻¹ y. Both
    /// triangular sweeps gather each unknown from its neighbours (the
    /// column of Lᵀ read at a stride of bw + 2 in the rows of L), the far
    /// terms summed first and the nearest unknown, carried in a register,
    /// last: consecutive unknowns then wait on each other through one
    /// multiply-add and no store (the sweeps are a chain along the rod, and
    /// one solve is made per Lanczos step; this halved it at bandwidth 5).
    pub fn solve_in_place(&self, b: &mut [f64]) {
        self.sweeps(None, b);
    }

    /// Solves A x = b into `x` (b unchanged): [`Self::solve_in_place`]
    /// without first copying b.
    pub fn solve(&self, b: &[f64], x: &mut [f64]) {
        assert_eq!(b.len(), self.n, "sizes differ");
        self.sweeps(Some(b), x);
    }

    /// The sweeps of [`Self::solve_in_place`] on `b`, reading the
    /// right-hand side from `rhs` where given.
    fn sweeps(&self, rhs: Option<&[f64]>, b: &mut [f64]) {
        assert_eq!(b.len(), self.n, "sizes differ");
        let (n, bw, w) = (self.n, self.bw, self.bw + 1);
        let mut previous = 0.0;
        for (i, row) in self.l.chunks_exact(w).enumerate() {
            let reach = bw.min(i);
            let mut far = 0.0;
            if reach >= 2 {
                let terms = row[2..=reach].iter().zip(b[i - reach..i - 1].iter().rev());
                for (l, bk) in terms {
                    far += l * bk;
                }
            }
            let near = if reach >= 1 { row[1] * previous } else { 0.0 };
            previous = (rhs.map_or(b[i], |r| r[i]) - far) - near;
            b[i] = previous;
        }
        // x_i = z_i − Σ_d L[i + d, i] x_{i+d} with z_i = y_i / D_i formed
        // as it is read: L[i + d, i] is d places into row i + d.
        let inverse = &self.inverse_pivots;
        let Some(last) = n.checked_sub(1) else {
            return;
        };
        if bw == 0 {
            b.iter_mut().zip(inverse).for_each(|(x, d)| *x *= d);
            return;
        }
        b[last] *= inverse[last];
        let mut previous = b[last];
        for i in (0..last).rev() {
            let high = bw.min(last - i);
            let mut far = 0.0;
            for d in 2..=high {
                far += self.l[(i + d) * w + d] * b[i + d];
            }
            previous = (b[i] * inverse[i] - far) - self.l[(i + 1) * w + 1] * previous;
            b[i] = previous;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: usize, bw: usize, shift: f64) -> SymmetricBanded {
        let mut a = SymmetricBanded::zeros(n, bw);
        for i in 0..n {
            a.add(i, i, 2.0 + shift + (i as f64 * 0.37).sin());
            for d in 1..=bw.min(i) {
                a.add(i, i - d, -0.4 / d as f64 + 0.1 * ((i * d) as f64).cos());
            }
        }
        a
    }

    #[test]
    fn solve_matches_dense() {
        let a = sample(40, 3, 0.5);
        let x: Vec<f64> = (0..40).map(|i| f64::from(i).cos()).collect();
        let mut b = vec![0.0; 40];
        a.matvec(&x, &mut b);
        let dense = a.to_dense() * nalgebra::DVector::from_vec(x.clone());
        assert!(b
            .iter()
            .zip(dense.iter())
            .all(|(p, q)| (p - q).abs() < 1e-13));
        let dense_norm = (0..40)
            .map(|i| a.to_dense().row(i).iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        assert!((a.row_sum_norm() - dense_norm).abs() < 1e-13 * dense_norm);
        a.ldlt().unwrap().solve_in_place(&mut b);
        assert!(b.iter().zip(&x).all(|(p, q)| (p - q).abs() < 1e-11));
    }

    /// The gathered sweeps at every bandwidth (0 has no sweep, 1 no far
    /// terms), from a right-hand side in place and into another vector,
    /// and the factors of K + bG formed without the sum.
    #[test]
    fn solves_and_shifted_factors_at_every_bandwidth() {
        for bw in 0..=4 {
            let a = sample(37, bw, 0.5);
            let x: Vec<f64> = (0..37).map(|i| f64::from(i).sin() + 0.3).collect();
            let mut b = vec![0.0; 37];
            a.matvec(&x, &mut b);
            let f = a.ldlt().unwrap();
            let mut y = vec![0.0; 37];
            f.solve(&b, &mut y);
            f.solve_in_place(&mut b);
            assert_eq!(b, y, "bw {bw}: in place and into another vector");
            assert!(
                b.iter().zip(&x).all(|(p, q)| (p - q).abs() < 1e-11),
                "bw {bw}"
            );
            let other = sample(37, bw.saturating_sub(1), 1.0);
            let sum = a.combine(1.0, &other, -0.7);
            let shifted = a.shifted_ldlt(-0.7, &other).unwrap();
            assert_eq!(
                shifted.negative_pivots(),
                sum.ldlt().unwrap().negative_pivots()
            );
            let (mut p, mut q) = (x.clone(), x.clone());
            shifted.solve_in_place(&mut p);
            sum.ldlt().unwrap().solve_in_place(&mut q);
            assert!(p
                .iter()
                .zip(&q)
                .all(|(u, v)| (u - v).abs() < 1e-12 * (1.0 + v.abs())));
        }
    }

    #[test]
    fn negative_pivots_count_negative_eigenvalues() {
        for shift in [-2.5, -1.3, -0.2, 0.4] {
            let a = sample(30, 2, shift);
            let eig = a.to_dense().symmetric_eigenvalues();
            let negative = eig.iter().filter(|&&v| v < 0.0).count();
            assert_eq!(
                a.ldlt().unwrap().negative_pivots(),
                negative,
                "shift {shift}"
            );
            // The same shift as a pencil with the identity (bandwidth 0).
            let mut unit = SymmetricBanded::zeros(30, 0);
            for i in 0..30 {
                unit.add(i, i, 1.0);
            }
            assert_eq!(
                sample(30, 2, 0.0).shifted_negative_pivots(shift, &unit),
                Ok(negative),
                "count-only, shift {shift}"
            );
        }
    }
}
