//! The LU factorization with partial pivoting of a general banded matrix
//! (LAPACK's `dgbtf2`/`dgbtrs`, Golub & Van Loan 4th ed. §4.3.5).
//!
//! A matrix with kl subdiagonals and ku superdiagonals factors as P A = L U
//! with L unit lower banded (kl) and U upper banded with kl + ku
//! superdiagonals (the fill of the row interchanges), in O(n·kl·(kl + ku))
//! work and O(n·(2kl + ku + 1)) memory: the linear solves of multiple
//! shooting and collocation, whose Jacobians are almost block diagonal.

/// A banded n×n matrix, factored in place by [`BandLu::factor`].
///
/// Storage is LAPACK's: column j holds rows j − kl − ku ..= j + kl in a
/// column of 2kl + ku + 1 entries, the top kl of them for the fill of U.
#[derive(Debug, Clone, Default)]
pub struct BandLu {
    n: usize,
    kl: usize,
    ku: usize,
    data: Vec<f64>,
    pivots: Vec<usize>,
    /// The largest |aᵢⱼ| before factoring (the scale of a small pivot).
    magnitude: f64,
    factored: bool,
}

/// A pivot of U that is exactly zero: the matrix is singular.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("zero pivot in column {column} of the band LU (the matrix is singular)")]
pub struct SingularBand {
    /// The column whose pivot vanished.
    pub column: usize,
}

impl BandLu {
    /// Resets to the zero n×n matrix with kl sub- and ku superdiagonals,
    /// keeping the allocation when it is large enough.
    pub fn reset(&mut self, n: usize, kl: usize, ku: usize) {
        self.n = n;
        self.kl = kl;
        self.ku = ku;
        self.data.clear();
        self.data.resize(n * self.lead(), 0.0);
        self.pivots.clear();
        self.pivots.resize(n, 0);
        self.magnitude = 0.0;
        self.factored = false;
    }

    /// The zero matrix (see [`BandLu::reset`]).
    pub fn zeros(n: usize, kl: usize, ku: usize) -> Self {
        let mut lu = BandLu::default();
        lu.reset(n, kl, ku);
        lu
    }

    /// Size.
    pub fn size(&self) -> usize {
        self.n
    }

    fn lead(&self) -> usize {
        2 * self.kl + self.ku + 1
    }

    /// Storage index of (i, j), −(kl + ku) ≤ i − j ≤ kl.
    fn at(&self, i: usize, j: usize) -> usize {
        j * self.lead() + self.kl + self.ku + i - j
    }

    /// Aᵢⱼ += v before factoring; panics outside the band (a caller's
    /// error in the bandwidths).
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(
            !self.factored && i <= j + self.kl && j <= i + self.ku,
            "({i}, {j}) outside the band (kl {}, ku {})",
            self.kl,
            self.ku
        );
        let k = self.at(i, j);
        self.data[k] += v;
    }

    /// P A = L U in place by partial pivoting; on a zero pivot the
    /// factors are unusable and the column is named.
    pub fn factor(&mut self) -> Result<(), SingularBand> {
        self.factor_floored(None)
    }

    /// The factors of a matrix inverse iteration will be run on: a pivot
    /// that is exactly zero (A singular in floating point — at a located
    /// fold the ideal case for inverse iteration, not a failure) is
    /// replaced by `floor` times the largest entry, as LAPACK's inverse
    /// iteration (dstein) perturbs its pivots; the solves then grow the
    /// null direction by ≈ 1/floor. Err only on a non-finite pivot.
    pub fn factor_for_inverse_iteration(&mut self, floor: f64) -> Result<(), SingularBand> {
        self.factor_floored(Some(floor))
    }

    fn factor_floored(&mut self, floor: Option<f64>) -> Result<(), SingularBand> {
        let (n, kl, kv) = (self.n, self.kl, self.kl + self.ku);
        let ld = self.lead();
        self.magnitude = self.data.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
        // The last column reached by the row interchanges so far.
        let mut last = 0;
        for j in 0..n {
            let km = kl.min(n - 1 - j);
            let col = j * ld + kv;
            let jp = (0..=km)
                .max_by(|&a, &b| {
                    self.data[col + a]
                        .abs()
                        .total_cmp(&self.data[col + b].abs())
                })
                .unwrap_or(0);
            self.pivots[j] = j + jp;
            let mut pivot = self.data[col + jp];
            if let (0.0, Some(floor)) = (pivot, floor) {
                pivot = floor * self.magnitude;
                self.data[col + jp] = pivot;
            }
            if pivot == 0.0 || !pivot.is_finite() {
                return Err(SingularBand { column: j });
            }
            last = last.max((j + self.ku + jp).min(n - 1));
            if jp != 0 {
                for c in j..=last {
                    let (a, b) = (self.at(j, c), self.at(j + jp, c));
                    self.data.swap(a, b);
                }
            }
            for i in 1..=km {
                self.data[col + i] /= pivot;
            }
            // Column c's rows j+1 ..= j+km lie after column j's multipliers
            // in the storage, so one split gives both as slices: the update
            // is an axpy without bounds checks, which vectorizes.
            for c in j + 1..=last {
                let base = self.at(j, c);
                let (done, rest) = self.data.split_at_mut(base + 1);
                let u = done[base];
                if u != 0.0 {
                    let l = &done[col + 1..=col + km];
                    rest[..km].iter_mut().zip(l).for_each(|(v, l)| *v -= l * u);
                }
            }
        }
        self.factored = true;
        Ok(())
    }

    /// min |uⱼⱼ| / max |aᵢⱼ|: how close the factored matrix is to singular
    /// (0 before a successful factorization).
    pub fn pivot_ratio(&self) -> f64 {
        if !self.factored || self.magnitude == 0.0 {
            return 0.0;
        }
        (0..self.n)
            .map(|j| self.data[self.at(j, j)].abs())
            .fold(f64::INFINITY, f64::min)
            / self.magnitude
    }

    /// det A of the last successful factorization as (sign, ln |det A|):
    /// the product of the pivots of U and the parity of the row
    /// interchanges, kept as a logarithm because the determinant of a fine
    /// mesh overflows. None before a successful factorization.
    pub fn log_determinant(&self) -> Option<(f64, f64)> {
        if !self.factored {
            return None;
        }
        let mut sign = 1.0;
        let mut log = 0.0;
        for j in 0..self.n {
            let u = self.data[self.at(j, j)];
            if u < 0.0 {
                sign = -sign;
            }
            if self.pivots[j] != j {
                sign = -sign;
            }
            log += u.abs().ln();
        }
        Some((sign, log))
    }

    /// The largest |aᵢⱼ| of the matrix factored.
    pub fn magnitude(&self) -> f64 {
        self.magnitude
    }

    /// b ← A⁻¹ b with the factors of the last successful
    /// [`BandLu::factor`].
    pub fn solve(&self, b: &mut [f64]) {
        assert!(self.factored, "solve before a successful factor");
        let (n, kl, kv) = (self.n, self.kl, self.kl + self.ku);
        let ld = self.lead();
        for j in 0..n {
            let p = self.pivots[j];
            if p != j {
                b.swap(p, j);
            }
            let bj = b[j];
            if bj != 0.0 {
                let col = j * ld + kv;
                for i in 1..=kl.min(n - 1 - j) {
                    b[j + i] -= self.data[col + i] * bj;
                }
            }
        }
        for j in (0..n).rev() {
            b[j] /= self.data[self.at(j, j)];
            let bj = b[j];
            if bj != 0.0 {
                let top = j.saturating_sub(kv);
                for (i, bi) in b[top..j].iter_mut().enumerate() {
                    *bi -= self.data[self.at(top + i, j)] * bj;
                }
            }
        }
    }

    /// b ← A⁻ᵀ b with the same factors (LAPACK's `dgbtrs` with 'T'):
    /// Aᵀ = Uᵀ Lᵀ P, so Uᵀ y = b forward, then Lᵀ with the row interchanges
    /// undone backward. The left null vector and the transposed bordered
    /// solves of the minimally augmented systems need it.
    pub fn solve_transposed(&self, b: &mut [f64]) {
        assert!(self.factored, "solve before a successful factor");
        let (n, kl, kv) = (self.n, self.kl, self.kl + self.ku);
        let ld = self.lead();
        for j in 0..n {
            let top = j.saturating_sub(kv);
            let dot: f64 = b[top..j]
                .iter()
                .enumerate()
                .map(|(i, bi)| self.data[self.at(top + i, j)] * bi)
                .sum();
            b[j] = (b[j] - dot) / self.data[self.at(j, j)];
        }
        for j in (0..n.saturating_sub(1)).rev() {
            let col = j * ld + kv;
            let dot: f64 = (1..=kl.min(n - 1 - j))
                .map(|i| self.data[col + i] * b[j + i])
                .sum();
            b[j] -= dot;
            let p = self.pivots[j];
            if p != j {
                b.swap(p, j);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;

    /// A deterministic pseudo-random banded matrix that needs pivoting
    /// (small diagonal).
    fn sample(n: usize, kl: usize, ku: usize) -> DMatrix<f64> {
        let mut seed = 12345_u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        DMatrix::from_fn(n, n, |i, j| {
            if i > j + kl || j > i + ku {
                0.0
            } else if i == j {
                1e-3 * next()
            } else {
                next()
            }
        })
    }

    #[test]
    fn solves_as_the_dense_lu() {
        for (n, kl, ku) in [(1, 0, 0), (7, 2, 1), (30, 3, 5), (40, 6, 0), (25, 0, 4)] {
            let a = sample(n, kl, ku);
            let mut lu = BandLu::zeros(n, kl, ku);
            for i in 0..n {
                for j in 0..n {
                    if a[(i, j)] != 0.0 {
                        lu.add(i, j, a[(i, j)]);
                    }
                }
            }
            lu.factor().unwrap();
            let b = DVector::from_fn(n, |i, _| (i as f64).sin() + 1.0);
            let mut x = b.as_slice().to_vec();
            lu.solve(&mut x);
            // Backward error: LU with partial pivoting solves a nearby
            // system (a triangular matrix with a small diagonal is too ill
            // conditioned for a forward comparison).
            let x = DVector::from_vec(x);
            let residual = (&a * &x - &b).amax();
            let bound = 1e-13 * a.amax() * x.amax() * n as f64;
            assert!(residual <= bound, "{n} {kl} {ku}: {residual:e} > {bound:e}");
            let mut y = b.as_slice().to_vec();
            lu.solve_transposed(&mut y);
            let y = DVector::from_vec(y);
            let residual = (a.transpose() * &y - &b).amax();
            let bound = 1e-13 * a.amax() * y.amax() * n as f64;
            assert!(
                residual <= bound,
                "ᵀ {n} {kl} {ku}: {residual:e} > {bound:e}"
            );
            if kl > 0 && ku > 0 {
                let dense = a.clone().lu().solve(&b).unwrap();
                let err = (&x - &dense).amax();
                assert!(err <= 1e-9 * dense.amax(), "{n} {kl} {ku}: {err:e}");
            }
        }
    }

    /// A = L U from a unit lower banded L and an upper banded U with a
    /// chosen diagonal: det A = Π uᵢᵢ exactly, whatever pivots the band
    /// LU then chooses.
    #[test]
    fn the_determinant_is_the_product_of_known_pivots() {
        let (n, kl, ku) = (30, 3, 2);
        let noise = sample(n, kl, ku);
        let l = DMatrix::from_fn(n, n, |i, j| match i.cmp(&j) {
            std::cmp::Ordering::Equal => 1.0,
            std::cmp::Ordering::Greater => noise[(i, j)] / kl as f64,
            std::cmp::Ordering::Less => 0.0,
        });
        let diagonal: Vec<f64> = (0..n)
            .map(|i| {
                if i % 3 == 0 {
                    -1.5
                } else {
                    1.0 + 0.1 * i as f64
                }
            })
            .collect();
        let u = DMatrix::from_fn(n, n, |i, j| match i.cmp(&j) {
            std::cmp::Ordering::Equal => diagonal[i],
            std::cmp::Ordering::Less => noise[(i, j)],
            std::cmp::Ordering::Greater => 0.0,
        });
        let a = l * u;
        let mut lu = BandLu::zeros(n, kl, ku);
        for i in 0..n {
            for j in i.saturating_sub(kl)..(i + ku + 1).min(n) {
                lu.add(i, j, a[(i, j)]);
            }
        }
        lu.factor().unwrap();
        let (sign, log) = lu.log_determinant().unwrap();
        let exact_sign: f64 = diagonal.iter().map(|v| v.signum()).product();
        let exact_log: f64 = diagonal.iter().map(|v| v.abs().ln()).sum();
        assert_eq!(sign, exact_sign);
        assert!(
            (log - exact_log).abs() <= 1e-12 * exact_log.abs(),
            "{log} against {exact_log}"
        );
    }

    /// [[1, 2, 0], [2, 4, 0], [0, 0, 1]]: singular, its second pivot
    /// exactly zero, its null vector (2, −1, 0).
    fn singular_band() -> BandLu {
        let mut lu = BandLu::zeros(3, 1, 1);
        lu.add(0, 0, 1.0);
        lu.add(0, 1, 2.0);
        lu.add(1, 0, 2.0);
        lu.add(1, 1, 4.0);
        lu.add(2, 2, 1.0);
        lu
    }

    #[test]
    fn names_a_zero_pivot() {
        let mut lu = singular_band();
        assert_eq!(lu.factor(), Err(SingularBand { column: 1 }));
    }

    /// The same exactly singular matrix factored for inverse iteration:
    /// the zero pivot is floored, and one solve from any start returns
    /// the null vector (2, −1, 0)/√5 to round-off.
    #[test]
    fn inverse_iteration_on_an_exactly_singular_band() {
        let mut lu = singular_band();
        lu.factor_for_inverse_iteration(f64::EPSILON).unwrap();
        let mut v = [0.3, 0.5, 0.7];
        lu.solve(&mut v);
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let null = [2.0 / 5f64.sqrt(), -1.0 / 5f64.sqrt(), 0.0];
        let sign = v[0].signum();
        for (got, want) in v.iter().zip(null) {
            assert!((sign * got / norm - want).abs() < 1e-12, "{v:?}");
        }
    }
}
