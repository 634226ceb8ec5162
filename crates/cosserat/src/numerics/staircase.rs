//! The almost block diagonal ("staircase") Jacobian of multiple shooting
//! and fixed-mesh collocation, and its O(N) solves, plain or bordered by
//! one row and column (pseudo-arclength continuation).
//!
//! Unknowns x₀ (`first` free values at the left end) and node states
//! x₁ … x_{K−1} (`dim` each); rows: K − 1 matching blocks
//! r_j = A_j x_j + D_j x_{j+1} (A_j dense, D_j diagonal) and the right-end
//! block r_{K−1} = A_{K−1} x_{K−1} (`first` rows). The matrix is square,
//! banded with half-bandwidths below 2·dim.
//!
//! The bordered matrix M = [A b; cᵀ d] is not banded (b and c are dense),
//! and block elimination through A alone fails at a fold, where A is
//! singular and M is not (Govaerts 2000, §3.3). Instead M is embedded in a
//! banded system of size N + 2K with the same solution: copies π_j of the
//! border unknown, linked by π_j − π_{j+1} = 0, carry b into each block,
//! and running sums σ_j = σ_{j−1} + c_jᵀ x_j carry the border row to the
//! last block, σ_{K−1} + d π_{K−1} = g. Eliminating the added unknowns
//! gives back M, so the embedding is regular exactly when M is, and band
//! LU with partial pivoting solves it at folds as dense LU would; one step
//! of iterative refinement on M follows. Where M itself is singular (an
//! exact branch point) the solve falls back to the regularized least
//! squares of the embedding (banded normal equations), never to a dense
//! matrix.

use nalgebra::DMatrix;

use super::band_lu::{BandLu, SingularBand};
use super::banded::SymmetricBanded;

/// The staircase matrix of K segments (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Staircase {
    first: usize,
    dim: usize,
    blocks: Vec<DMatrix<f64>>,
    coupling: Vec<f64>,
}

/// One border of a square matrix: M = [A column; rowᵀ corner].
#[derive(Debug, Clone, Copy)]
pub struct Border<'a> {
    /// The last column b (length N).
    pub column: &'a [f64],
    /// The last row c (length N).
    pub row: &'a [f64],
    /// The corner d.
    pub corner: f64,
}

impl Staircase {
    /// The zero staircase of `segments` ≥ 1 segments with `first` free
    /// values (1 ≤ first ≤ dim) and node states of size `dim`.
    pub fn zeros(first: usize, dim: usize, segments: usize) -> Self {
        assert!(
            segments >= 1 && (1..=dim).contains(&first),
            "a staircase needs segments ≥ 1 and 1 ≤ first ≤ dim"
        );
        let blocks = (0..segments)
            .map(|j| {
                let rows = if j + 1 < segments { dim } else { first };
                let cols = if j == 0 { first } else { dim };
                DMatrix::zeros(rows, cols)
            })
            .collect();
        Staircase {
            first,
            dim,
            blocks,
            coupling: vec![0.0; dim * (segments - 1)],
        }
    }

    /// Number of segments K.
    pub fn segments(&self) -> usize {
        self.blocks.len()
    }

    /// Size N = first + dim (K − 1).
    pub fn size(&self) -> usize {
        self.first + self.dim * (self.segments() - 1)
    }

    /// The first column of the unknowns x_j.
    fn column_of(&self, j: usize) -> usize {
        if j == 0 {
            0
        } else {
            self.first + self.dim * (j - 1)
        }
    }

    /// A_j = ∂r_j/∂x_j (dim × cols, the last block first × cols).
    pub fn block_mut(&mut self, j: usize) -> &mut DMatrix<f64> {
        &mut self.blocks[j]
    }

    /// The diagonal of D_j = ∂r_j/∂x_{j+1}, j < K − 1.
    pub fn coupling_mut(&mut self, j: usize) -> &mut [f64] {
        &mut self.coupling[self.dim * j..self.dim * (j + 1)]
    }

    /// A ← A diag(w): the unknowns measured in units w.
    pub fn scale_columns(&mut self, w: &[f64]) {
        for j in 0..self.segments() {
            let c0 = self.column_of(j);
            for (c, mut col) in self.blocks[j].column_iter_mut().enumerate() {
                col *= w[c0 + c];
            }
        }
        let (first, dim) = (self.first, self.dim);
        for (k, v) in self.coupling.iter_mut().enumerate() {
            *v *= w[first + k];
        }
        debug_assert_eq!(dim * (self.blocks.len() - 1), self.coupling.len());
    }

    /// y = A x.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        for (j, block) in self.blocks.iter().enumerate() {
            let c0 = self.column_of(j);
            for i in 0..block.nrows() {
                let row = self.dim * j + i;
                let mut s: f64 = (0..block.ncols()).map(|c| block[(i, c)] * x[c0 + c]).sum();
                if j + 1 < self.segments() {
                    s += self.coupling[self.dim * j + i] * x[self.first + self.dim * j + i];
                }
                y[row] = s;
            }
        }
    }

    /// y = Aᵀ x.
    pub fn mul_transposed(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for (j, block) in self.blocks.iter().enumerate() {
            let c0 = self.column_of(j);
            for i in 0..block.nrows() {
                let row = self.dim * j + i;
                let xi = x[row];
                for c in 0..block.ncols() {
                    y[c0 + c] += block[(i, c)] * xi;
                }
                if j + 1 < self.segments() {
                    y[self.first + self.dim * j + i] += self.coupling[row] * xi;
                }
            }
        }
    }

    /// The dense matrix (for the few dense users: determinants at special
    /// points, small systems, tests).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let n = self.size();
        let mut a = DMatrix::zeros(n, n);
        self.write_dense(&mut a);
        a
    }

    /// The dense matrix into `out` (N × N), without another N × N copy.
    pub fn write_dense(&self, out: &mut DMatrix<f64>) {
        out.fill(0.0);
        self.entries(|i, j, v| out[(i, j)] += v);
    }

    /// Every stored entry (i, j, Aᵢⱼ), row by row.
    fn entries(&self, mut put: impl FnMut(usize, usize, f64)) {
        for (j, block) in self.blocks.iter().enumerate() {
            let c0 = self.column_of(j);
            for i in 0..block.nrows() {
                let row = self.dim * j + i;
                for c in 0..block.ncols() {
                    put(row, c0 + c, block[(i, c)]);
                }
                if j + 1 < self.segments() {
                    put(row, self.first + self.dim * j + i, self.coupling[row]);
                }
            }
        }
    }

    /// Every entry of the banded embedding of M = [A b; cᵀ d] (see the
    /// module documentation), row by row, and the map of its rows and
    /// unknowns.
    fn embedded_entries(&self, border: &Border, mut put: impl FnMut(usize, usize, f64)) {
        let (k, dim) = (self.segments(), self.dim);
        let layout = Embedding::new(self);
        for j in 0..k {
            let (u, e) = (layout.unknown[j], layout.equation[j]);
            let cols = self.blocks[j].ncols();
            let (c0, pi, sigma) = (self.column_of(j), u + cols, u + cols + 1);
            // σ_j − σ_{j−1} − c_jᵀ x_j = 0
            if j > 0 {
                put(e, u - 1, -1.0);
            }
            for c in 0..cols {
                put(e, u + c, -border.row[c0 + c]);
            }
            put(e, sigma, 1.0);
            // A_j x_j + b_j π_j + D_j x_{j+1} = f_j
            let block = &self.blocks[j];
            for i in 0..block.nrows() {
                let row = e + 1 + i;
                for c in 0..cols {
                    put(row, u + c, block[(i, c)]);
                }
                put(row, pi, border.column[dim * j + i]);
                if j + 1 < k {
                    put(row, layout.unknown[j + 1] + i, self.coupling[dim * j + i]);
                }
            }
            let last = e + 1 + block.nrows();
            if j + 1 < k {
                // π_j − π_{j+1} = 0
                put(last, pi, 1.0);
                put(last, layout.unknown[j + 1] + self.dim, -1.0);
            } else {
                // σ_{K−1} + d π_{K−1} = g
                put(last, pi, border.corner);
                put(last, sigma, 1.0);
            }
        }
    }
}

/// Where block j's unknowns and equations start in the embedding.
#[derive(Debug, Clone, Default)]
struct Embedding {
    unknown: Vec<usize>,
    equation: Vec<usize>,
}

impl Embedding {
    fn new(a: &Staircase) -> Self {
        let (mut unknown, mut equation) = (vec![0], vec![0]);
        for block in &a.blocks {
            unknown.push(unknown.last().unwrap() + block.ncols() + 2);
            equation.push(equation.last().unwrap() + block.nrows() + 2);
        }
        Embedding { unknown, equation }
    }
}

/// The half-bandwidths (kl, ku) of a set of entries.
fn bandwidths(entries: impl FnOnce(&mut dyn FnMut(usize, usize, f64))) -> (usize, usize) {
    let (mut kl, mut ku) = (0, 0);
    entries(&mut |i, j, _| {
        kl = kl.max(i.saturating_sub(j));
        ku = ku.max(j.saturating_sub(i));
    });
    (kl, ku)
}

/// The factors of a staircase, plain or bordered, kept from a Newton
/// linearization to its solves. Memory and work are linear in K.
#[derive(Debug, Clone, Default)]
pub struct StaircaseLu {
    lu: BandLu,
    bordered: bool,
    factored: bool,
    /// The embedding's right-hand side and solution (bordered solves).
    work: Vec<f64>,
    /// The residual and the correction of the refinement step.
    residual: Vec<f64>,
    correction: Vec<f64>,
    /// Where the blocks start in the embedding.
    layout: Embedding,
}

impl StaircaseLu {
    /// Factors A, or the banded embedding of [A b; cᵀ d] when a border is
    /// given. A zero pivot names the column; a bordered solve then falls
    /// back to least squares.
    pub fn factor(&mut self, a: &Staircase, border: Option<&Border>) -> Result<(), SingularBand> {
        self.bordered = border.is_some();
        self.factored = false;
        let lu = &mut self.lu;
        match border {
            None => {
                let (kl, ku) = bandwidths(|put| a.entries(put));
                lu.reset(a.size(), kl, ku);
                a.entries(|i, j, v| lu.add(i, j, v));
            }
            Some(border) => {
                self.layout = Embedding::new(a);
                let (kl, ku) = bandwidths(|put| a.embedded_entries(border, put));
                lu.reset(a.size() + 2 * a.segments(), kl, ku);
                a.embedded_entries(border, |i, j, v| lu.add(i, j, v));
            }
        }
        lu.factor()?;
        self.factored = true;
        Ok(())
    }

    /// min |uⱼⱼ| / max |aᵢⱼ| of the last factorization (0 if it failed).
    pub fn pivot_ratio(&self) -> f64 {
        if self.factored {
            self.lu.pivot_ratio()
        } else {
            0.0
        }
    }

    /// det A of the plain factors as (sign, ln |det A|) (see
    /// [`BandLu::log_determinant`]): the O(N) determinant a branch-point
    /// test needs. None after a bordered or failed factorization.
    pub fn log_determinant(&self) -> Option<(f64, f64)> {
        if self.factored && !self.bordered {
            self.lu.log_determinant()
        } else {
            None
        }
    }

    /// b ← A⁻¹ b with the plain factors; false where A was singular.
    pub fn solve(&mut self, b: &mut [f64]) -> bool {
        if !self.factored || self.bordered {
            return false;
        }
        self.lu.solve(b);
        b.iter().all(|v| v.is_finite())
    }

    /// z = M⁻¹ (f, g) for M = [A b; cᵀ d] with the bordered factors of the
    /// same A and border, refined once on M, into `z` (length N + 1);
    /// where M is singular (a zero pivot or a solution 10¹² times the
    /// data), the regularized least-squares solution instead
    /// ([`least_squares`]). False where neither is finite.
    pub fn solve_bordered(
        &mut self,
        a: &Staircase,
        border: &Border,
        rhs: &[f64],
        z: &mut [f64],
    ) -> bool {
        let finite = |z: &[f64]| z.iter().all(|v| v.is_finite());
        let scale = rhs.iter().fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
        if self.factored && self.bordered {
            self.embedded_solve(a, rhs, z);
            let mut r = std::mem::take(&mut self.residual);
            let mut dz = std::mem::take(&mut self.correction);
            dz.resize(z.len(), 0.0);
            bordered_residual(a, border, z, rhs, &mut r);
            self.embedded_solve(a, &r, &mut dz);
            z.iter_mut().zip(&dz).for_each(|(a, b)| *a += b);
            (self.residual, self.correction) = (r, dz);
            let size = z.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
            if finite(z) && size * self.lu.magnitude() < 1e12 * scale {
                return true;
            }
        }
        match least_squares(a, border, rhs).filter(|y| finite(y)) {
            Some(y) => {
                z.copy_from_slice(&y);
                true
            }
            None => false,
        }
    }

    /// w = M⁻ᵀ (f, g) for M = [A b; cᵀ d], with the bordered factors of
    /// the same A and border, refined once on Mᵀ, into `w` (length N + 1).
    /// The embedding E gives M⁻¹ = G E⁻¹ S (S scatters (f, g) onto E's
    /// rows, G gathers (x, π) from its unknowns), so M⁻ᵀ = Sᵀ E⁻ᵀ Gᵀ: the
    /// same factors solved transposed, with the two maps exchanged. False
    /// without bordered factors or where the solution is not finite (no
    /// least-squares fallback: the callers border with approximate null
    /// vectors, which keep M regular).
    pub fn solve_bordered_transposed(
        &mut self,
        a: &Staircase,
        border: &Border,
        rhs: &[f64],
        w: &mut [f64],
    ) -> bool {
        if !(self.factored && self.bordered) {
            return false;
        }
        self.embedded_solve_transposed(a, rhs, w);
        let n = a.size();
        let mut r = std::mem::take(&mut self.residual);
        let mut dw = std::mem::take(&mut self.correction);
        r.clear();
        r.resize(n + 1, 0.0);
        dw.resize(n + 1, 0.0);
        // r = (f, g) − Mᵀ w, Mᵀ = [Aᵀ c; bᵀ d].
        a.mul_transposed(&w[..n], &mut r[..n]);
        for i in 0..n {
            r[i] = rhs[i] - r[i] - border.row[i] * w[n];
        }
        let dot: f64 = border.column.iter().zip(&w[..n]).map(|(b, x)| b * x).sum();
        r[n] = rhs[n] - dot - border.corner * w[n];
        self.embedded_solve_transposed(a, &r, &mut dw);
        w.iter_mut().zip(&dw).for_each(|(a, b)| *a += b);
        (self.residual, self.correction) = (r, dw);
        w.iter().all(|v| v.is_finite())
    }

    /// M⁻ᵀ (f, g) = Sᵀ E⁻ᵀ Gᵀ (f, g) into `w`, without refinement.
    fn embedded_solve_transposed(&mut self, a: &Staircase, rhs: &[f64], w: &mut [f64]) {
        self.work.clear();
        self.work.resize(self.lu.size(), 0.0);
        let layout = &self.layout;
        for (j, block) in a.blocks.iter().enumerate() {
            let (u, c0, cols) = (layout.unknown[j], a.column_of(j), block.ncols());
            self.work[u..u + cols].copy_from_slice(&rhs[c0..c0 + cols]);
        }
        let k = a.segments() - 1;
        self.work[layout.unknown[k] + a.blocks[k].ncols()] = rhs[a.size()];
        self.lu.solve_transposed(&mut self.work);
        for (j, block) in a.blocks.iter().enumerate() {
            let e = layout.equation[j];
            let rows = block.nrows();
            w[a.dim * j..a.dim * j + rows].copy_from_slice(&self.work[e + 1..e + 1 + rows]);
        }
        w[a.size()] = self.work[self.work.len() - 1];
    }

    /// M⁻¹ (f, g) through the embedding into `z`, without refinement.
    fn embedded_solve(&mut self, a: &Staircase, rhs: &[f64], z: &mut [f64]) {
        self.work.clear();
        self.work.resize(self.lu.size(), 0.0);
        scatter(a, &self.layout, rhs, &mut self.work);
        self.lu.solve(&mut self.work);
        gather(a, &self.layout, &self.work, z);
    }
}

/// The embedding's right-hand side of (f, g): f_j on block j's F rows, g
/// on the last row, zeros on the added rows.
fn scatter(a: &Staircase, layout: &Embedding, rhs: &[f64], work: &mut [f64]) {
    let n = a.size();
    for (j, block) in a.blocks.iter().enumerate() {
        let e = layout.equation[j];
        let rows = block.nrows();
        work[e + 1..e + 1 + rows].copy_from_slice(&rhs[a.dim * j..a.dim * j + rows]);
    }
    let last = work.len() - 1;
    work[last] = rhs[n];
}

/// (x, π_{K−1}) of the embedding's solution into z.
fn gather(a: &Staircase, layout: &Embedding, work: &[f64], z: &mut [f64]) {
    for (j, block) in a.blocks.iter().enumerate() {
        let (u, c0, cols) = (layout.unknown[j], a.column_of(j), block.ncols());
        z[c0..c0 + cols].copy_from_slice(&work[u..u + cols]);
    }
    let k = a.segments() - 1;
    z[a.size()] = work[layout.unknown[k] + a.blocks[k].ncols()];
}

/// r = (f, g) − M z.
fn bordered_residual(a: &Staircase, border: &Border, z: &[f64], rhs: &[f64], r: &mut Vec<f64>) {
    let n = a.size();
    r.clear();
    r.resize(n + 1, 0.0);
    a.mul(&z[..n], &mut r[..n]);
    let p = z[n];
    for i in 0..n {
        r[i] = rhs[i] - r[i] - border.column[i] * p;
    }
    let dot: f64 = border.row.iter().zip(&z[..n]).map(|(c, x)| c * x).sum();
    r[n] = rhs[n] - dot - border.corner * p;
}

/// The regularized least-squares solution of M z = (f, g) through the
/// embedding E: min ‖E y − e‖² + μ‖y‖² with μ = 10⁻¹⁰ max diag EᵀE (the
/// singular values of E below 10⁻⁵ of its largest are damped: the LDLᵀ
/// without pivoting of the normal equations needs pivots well above
/// round-off), from the banded normal equations (EᵀE + μI) y = Eᵀe
/// (half-bandwidth kl + ku) with one step of refinement. On a consistent singular system
/// (an exact branch point) it is a solution of M z = (f, g) (the
/// components along the null space damped to the smallest norm of the
/// embedding's unknowns), as the truncated SVD of the dense solve was.
pub fn least_squares(a: &Staircase, border: &Border, rhs: &[f64]) -> Option<Vec<f64>> {
    let layout = Embedding::new(a);
    let size = a.size() + 2 * a.segments();
    let (kl, ku) = bandwidths(|put| a.embedded_entries(border, put));
    // Rows of E, each as its entries (rows are emitted contiguously).
    let mut rows: Vec<(usize, usize, f64)> = Vec::new();
    a.embedded_entries(border, |i, j, v| rows.push((i, j, v)));
    let mut normal = SymmetricBanded::zeros(size, kl + ku);
    for row in rows.chunk_by(|p, q| p.0 == q.0) {
        for (x, &(_, ja, va)) in row.iter().enumerate() {
            for &(_, jb, vb) in &row[..=x] {
                normal.add(ja, jb, va * vb);
            }
        }
    }
    let largest = (0..size)
        .map(|i| normal.get(i, i))
        .fold(f64::MIN_POSITIVE, f64::max);
    let mu = 1e-10 * largest;
    for i in 0..size {
        normal.add(i, i, mu);
    }
    let ldlt = normal.ldlt().ok()?;
    let mut e = vec![0.0; size];
    scatter(a, &layout, rhs, &mut e);
    // Eᵀ v.
    let transpose = |v: &[f64]| {
        let mut out = vec![0.0; size];
        for &(i, j, val) in &rows {
            out[j] += val * v[i];
        }
        out
    };
    let mut y = transpose(&e);
    ldlt.solve_in_place(&mut y);
    // One refinement: Eᵀ(e − E y) − μ y.
    let mut ey = vec![0.0; size];
    for &(i, j, val) in &rows {
        ey[i] += val * y[j];
    }
    let diff: Vec<f64> = e.iter().zip(&ey).map(|(a, b)| a - b).collect();
    let mut dy = transpose(&diff);
    dy.iter_mut().zip(&y).for_each(|(d, v)| *d -= mu * v);
    ldlt.solve_in_place(&mut dy);
    y.iter_mut().zip(&dy).for_each(|(a, b)| *a += b);
    let mut z = vec![0.0; a.size() + 1];
    gather(a, &layout, &y, &mut z);
    Some(z)
}

#[cfg(test)]
mod tests;
