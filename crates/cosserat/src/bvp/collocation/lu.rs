//! The small dense and the banded LU factorizations of collocation.
//!
//! Dense LU with row partial pivoting of the mn × mn stage matrices
//! (compiled for the planar and spatial sizes), and the banded LU of the
//! condensed node system in LAPACK's `gbtrf` layout: Gaussian elimination
//! with row partial pivoting, stable where the forward recursion of
//! compactification is not (AMR §7.2.2).

/// A row interchange of a dense LU: `usize`, or `u8` where the factors are
/// kept for every mesh interval (a stage matrix has at most m·n = 45 rows,
/// so an eighth of the storage).
pub(in crate::bvp) trait Pivot: Copy {
    /// The row it names.
    fn row(self) -> usize;
    /// The interchange with row `i`.
    fn of(i: usize) -> Self;
}

impl Pivot for usize {
    fn row(self) -> usize {
        self
    }

    fn of(i: usize) -> Self {
        i
    }
}

impl Pivot for u8 {
    fn row(self) -> usize {
        usize::from(self)
    }

    fn of(i: usize) -> Self {
        u8::try_from(i).expect("a dense LU of at most 256 rows")
    }
}

/// In-place LU with row partial pivoting (as nalgebra's `LU`) of the d × d
/// row-major matrix `a`, interchanges in `piv`; false at a zero or
/// non-finite pivot. The stage sizes of the planar (n = 4, 2 components
/// coupled) and spatial (n = 12, 9 coupled) models are compiled for their
/// size.
pub(in crate::bvp) fn dense_lu<P: Pivot>(a: &mut [f64], d: usize, piv: &mut [P]) -> bool {
    match d {
        4 => lu_sized::<4, P>(a, piv),
        6 => lu_sized::<6, P>(a, piv),
        8 => lu_sized::<8, P>(a, piv),
        12 => lu_sized::<12, P>(a, piv),
        18 => lu_sized::<18, P>(a, piv),
        24 => lu_sized::<24, P>(a, piv),
        27 => lu_sized::<27, P>(a, piv),
        36 => lu_sized::<36, P>(a, piv),
        _ => lu_any(a, d, piv),
    }
}

/// Solves A x = b in place with the factors of [`dense_lu`].
pub(in crate::bvp) fn dense_solve<P: Pivot>(a: &[f64], d: usize, piv: &[P], b: &mut [f64]) {
    match d {
        4 => solve_sized::<4, P>(a, piv, b),
        6 => solve_sized::<6, P>(a, piv, b),
        8 => solve_sized::<8, P>(a, piv, b),
        12 => solve_sized::<12, P>(a, piv, b),
        18 => solve_sized::<18, P>(a, piv, b),
        24 => solve_sized::<24, P>(a, piv, b),
        27 => solve_sized::<27, P>(a, piv, b),
        36 => solve_sized::<36, P>(a, piv, b),
        _ => solve_any(a, d, piv, b),
    }
}

/// Solves A X = B in place with the factors of [`dense_lu`] for the
/// `cols` right-hand sides of B (d × cols, row-major). Substitution by
/// whole rows of B: each update is an axpy over the columns, which
/// vectorizes, where a column at a time is a chain of ordered dot-product
/// sums (measured: [`dense_solve`] per column was 41 % of a collocation
/// continuation run, three times the factorization).
pub(in crate::bvp) fn dense_solve_rows<P: Pivot>(
    a: &[f64],
    d: usize,
    piv: &[P],
    b: &mut [f64],
    cols: usize,
) {
    match d {
        6 => rows_sized::<6, P>(a, piv, b, cols),
        24 => rows_sized::<24, P>(a, piv, b, cols),
        27 => rows_sized::<27, P>(a, piv, b, cols),
        36 => rows_sized::<36, P>(a, piv, b, cols),
        _ => rows_any(a, d, piv, b, cols),
    }
}

/// [`dense_solve_rows`] for a dimension known at compile time.
fn rows_sized<const D: usize, P: Pivot>(a: &[f64], piv: &[P], b: &mut [f64], cols: usize) {
    rows_any(&a[..D * D], D, &piv[..D], &mut b[..D * cols], cols);
}

/// [`dense_solve_rows`] for any dimension.
// Forced so rows_sized::<D> sees a constant D (as `lu_any`).
#[allow(clippy::inline_always)]
#[inline(always)]
fn rows_any<P: Pivot>(a: &[f64], d: usize, piv: &[P], b: &mut [f64], cols: usize) {
    for (k, p) in piv.iter().map(|p| p.row()).enumerate() {
        if p != k {
            for c in 0..cols {
                b.swap(k * cols + c, p * cols + c);
            }
        }
    }
    for i in 1..d {
        let (done, rest) = b.split_at_mut(i * cols);
        let row = &mut rest[..cols];
        for (k, &l) in a[i * d..i * d + i].iter().enumerate() {
            if l != 0.0 {
                let src = &done[k * cols..(k + 1) * cols];
                row.iter_mut().zip(src).for_each(|(x, y)| *x -= l * y);
            }
        }
    }
    for i in (0..d).rev() {
        let (head, tail) = b.split_at_mut((i + 1) * cols);
        let row = &mut head[i * cols..];
        for (k, &u) in a[i * d + i + 1..(i + 1) * d].iter().enumerate() {
            if u != 0.0 {
                let src = &tail[k * cols..(k + 1) * cols];
                row.iter_mut().zip(src).for_each(|(x, y)| *x -= u * y);
            }
        }
        let pivot = a[i * d + i];
        for x in row.iter_mut() {
            *x /= pivot;
        }
    }
}

/// [`dense_lu`] for a dimension known at compile time (unrolled loops).
fn lu_sized<const D: usize, P: Pivot>(a: &mut [f64], piv: &mut [P]) -> bool {
    // Inlined with a constant dimension, so the loops unroll.
    lu_any(&mut a[..D * D], D, &mut piv[..D])
}

/// [`dense_solve`] for a dimension known at compile time.
fn solve_sized<const D: usize, P: Pivot>(a: &[f64], piv: &[P], b: &mut [f64]) {
    solve_any(&a[..D * D], D, &piv[..D], &mut b[..D]);
}

/// [`dense_lu`] for any dimension.
// Forced so lu_sized::<D> unrolls: #[inline] ran 12-16% slower in `cargo bench --bench newton_step`.
#[allow(clippy::inline_always)]
#[inline(always)]
fn lu_any<P: Pivot>(a: &mut [f64], d: usize, piv: &mut [P]) -> bool {
    for k in 0..d {
        let (mut p, mut best) = (k, a[k * d + k].abs());
        for i in k + 1..d {
            let v = a[i * d + k].abs();
            if v > best {
                (p, best) = (i, v);
            }
        }
        piv[k] = P::of(p);
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if p != k {
            for c in 0..d {
                a.swap(k * d + c, p * d + c);
            }
        }
        let (upper, lower) = a.split_at_mut((k + 1) * d);
        let row_k = &upper[k * d..];
        let pivot = row_k[k];
        for row in lower.chunks_exact_mut(d) {
            let l = row[k] / pivot;
            row[k] = l;
            if l != 0.0 {
                row[k + 1..]
                    .iter_mut()
                    .zip(&row_k[k + 1..])
                    .for_each(|(v, u)| *v -= l * u);
            }
        }
    }
    true
}

/// [`dense_solve`] for any dimension: column-oriented substitution (each
/// solved unknown updates the ones after it), whose updates are
/// independent, where row-oriented dot products are a chain of ordered
/// additions.
// Forced so solve_sized::<D> unrolls for a constant D (measured: see `lu_any`).
#[allow(clippy::inline_always)]
#[inline(always)]
fn solve_any<P: Pivot>(a: &[f64], d: usize, piv: &[P], b: &mut [f64]) {
    for (k, p) in piv.iter().enumerate() {
        b.swap(k, p.row());
    }
    for k in 0..d {
        let x = b[k];
        if x != 0.0 {
            for (i, v) in b.iter_mut().enumerate().skip(k + 1) {
                *v -= a[i * d + k] * x;
            }
        }
    }
    for k in (0..d).rev() {
        b[k] /= a[k * d + k];
        let x = b[k];
        if x != 0.0 {
            for (i, v) in b[..k].iter_mut().enumerate() {
                *v -= a[i * d + k] * x;
            }
        }
    }
}

/// A banded matrix factored by Gaussian elimination with row partial
/// pivoting in LAPACK's `gbtrf` layout: column-major band storage with kl
/// extra rows above for the fill-in of row interchanges. Work
/// O(size · kl · (kl + ku)), storage O(size · (2kl + ku + 1)).
pub(super) struct BandLu {
    size: usize,
    kl: usize,
    ku: usize,
    ld: usize,
    data: Vec<f64>,
    piv: Vec<usize>,
}

impl BandLu {
    pub(super) fn zeros(size: usize, kl: usize, ku: usize) -> Self {
        let ld = 2 * kl + ku + 1;
        BandLu {
            size,
            kl,
            ku,
            ld,
            data: vec![0.0; ld * size],
            piv: vec![0; size],
        }
    }

    /// Storage index of (i, j), for j − i ≤ kl + ku and i − j ≤ kl.
    fn idx(&self, i: usize, j: usize) -> usize {
        debug_assert!(
            i <= j + self.kl && j <= i + self.kl + self.ku,
            "({i}, {j}) outside the band"
        );
        j * self.ld + self.kl + self.ku + i - j
    }

    /// Zeros the matrix for a new factorization.
    pub(super) fn clear(&mut self) {
        self.data.fill(0.0);
    }

    /// Aᵢⱼ += v; panics outside the band of the matrix (kl below, ku
    /// above: a caller's error in the bandwidths).
    pub(super) fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(
            i <= j + self.kl && j <= i + self.ku,
            "({i}, {j}) outside the band (kl {}, ku {})",
            self.kl,
            self.ku
        );
        let k = self.idx(i, j);
        self.data[k] += v;
    }

    fn get(&self, i: usize, j: usize) -> f64 {
        self.data[self.idx(i, j)]
    }

    /// In-place LU with partial pivoting; Err(column) at a zero pivot.
    pub(super) fn factor(&mut self) -> Result<(), usize> {
        let (kl, ku) = (self.kl, self.ku);
        for k in 0..self.size {
            let last = (k + kl).min(self.size - 1);
            let right = (k + kl + ku).min(self.size - 1);
            let p = (k..=last).fold(k, |b, i| {
                if self.get(i, k).abs() > self.get(b, k).abs() {
                    i
                } else {
                    b
                }
            });
            let pivot = self.get(p, k);
            if pivot == 0.0 || !pivot.is_finite() {
                return Err(k);
            }
            self.piv[k] = p;
            if p != k {
                for c in k..=right {
                    let (a, b) = (self.idx(k, c), self.idx(p, c));
                    self.data.swap(a, b);
                }
            }
            // Multipliers below the pivot, then the rank-one update column
            // by column (contiguous in the column-major band storage),
            // skipping the zero columns of the pivot row.
            let (lo, hi) = (self.idx(k + 1, k), self.idx(last, k) + 1);
            for v in &mut self.data[lo..hi] {
                *v /= pivot;
            }
            for c in k + 1..=right {
                let v = self.get(k, c);
                if v == 0.0 {
                    continue;
                }
                let start = self.idx(k + 1, c);
                for (off, i) in (k + 1..=last).enumerate() {
                    let l = self.data[lo + i - (k + 1)];
                    self.data[start + off] -= l * v;
                }
            }
        }
        Ok(())
    }

    /// Solves A x = b in place with the factors.
    pub(super) fn solve(&self, b: &mut [f64]) {
        let (kl, ku, n) = (self.kl, self.ku, self.size);
        for k in 0..n {
            b.swap(k, self.piv[k]);
            for i in k + 1..=(k + kl).min(n - 1) {
                b[i] -= self.get(i, k) * b[k];
            }
        }
        for k in (0..n).rev() {
            let right = (k + kl + ku).min(n - 1);
            let acc: f64 = (k + 1..=right).map(|c| self.get(k, c) * b[c]).sum();
            b[k] = (b[k] - acc) / self.get(k, k);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// The band LU against nalgebra's dense LU on a random banded matrix
    /// that needs pivoting (zero diagonal).
    #[test]
    fn band_lu_matches_dense_lu() {
        let (size, kl, ku) = (23, 4, 3);
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut dense = DMatrix::zeros(size, size);
        let mut band = BandLu::zeros(size, kl, ku);
        for i in 0..size {
            for j in i.saturating_sub(kl)..=(i + ku).min(size - 1) {
                let v = if i == j { 0.0 } else { rnd() };
                dense[(i, j)] = v;
                band.add(i, j, v);
            }
        }
        let b: Vec<f64> = (0..size).map(|_| rnd()).collect();
        let exact = dense
            .clone()
            .lu()
            .solve(&DVector::from_column_slice(&b))
            .unwrap();
        band.factor().unwrap();
        let mut x = b.clone();
        band.solve(&mut x);
        let err = x
            .iter()
            .zip(exact.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-10, "{err}");
    }

    /// The dense LU (compiled sizes and the general one) against nalgebra's.
    #[test]
    fn dense_lu_matches_nalgebra() {
        let mut seed = 987u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for d in [7, 12, 36] {
            let a: Vec<f64> = (0..d * d).map(|_| rnd()).collect();
            let b: Vec<f64> = (0..d).map(|_| rnd()).collect();
            let exact = DMatrix::from_row_slice(d, d, &a)
                .lu()
                .solve(&DVector::from_column_slice(&b))
                .unwrap();
            let (mut f, mut piv, mut x) = (a.clone(), vec![0usize; d], b.clone());
            assert!(dense_lu(&mut f, d, &mut piv));
            dense_solve(&f, d, &piv, &mut x);
            let err = x
                .iter()
                .zip(exact.iter())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-10, "d {d}: {err}");
        }
    }

    /// The many-column solve against nalgebra's, column by column.
    #[test]
    fn row_solve_matches_nalgebra() {
        let mut seed = 4321u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for (d, cols) in [(7, 3), (24, 13), (36, 12)] {
            let a: Vec<f64> = (0..d * d).map(|_| rnd()).collect();
            let b: Vec<f64> = (0..d * cols).map(|_| rnd()).collect();
            let exact = DMatrix::from_row_slice(d, d, &a)
                .lu()
                .solve(&DMatrix::from_row_slice(d, cols, &b))
                .unwrap();
            let (mut f, mut piv, mut x) = (a.clone(), vec![0usize; d], b.clone());
            assert!(dense_lu(&mut f, d, &mut piv));
            dense_solve_rows(&f, d, &piv, &mut x, cols);
            let err = DMatrix::from_row_slice(d, cols, &x) - exact;
            assert!(err.amax() < 1e-10, "d {d}: {}", err.amax());
        }
    }
}
