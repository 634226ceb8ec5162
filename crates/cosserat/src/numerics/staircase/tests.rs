//! The staircase solves against dense LU of the same matrices: plain,
//! bordered, bordered at a fold (A singular, M regular), and the
//! least-squares fallback at a singular M.

use nalgebra::{DMatrix, DVector};

use super::*;

/// A deterministic pseudo-random number in (−½, ½).
fn generator(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }
}

/// A staircase of multiple-shooting shape: blocks near a flow map (identity
/// plus noise), couplings −w.
fn sample(first: usize, dim: usize, segments: usize, seed: u64) -> Staircase {
    let mut next = generator(seed);
    let mut a = Staircase::zeros(first, dim, segments);
    for j in 0..segments {
        let block = a.block_mut(j);
        for v in block.iter_mut() {
            *v = next();
        }
        for i in 0..block.nrows().min(block.ncols()) {
            block[(i, i)] += 1.0;
        }
        if j + 1 < segments {
            for v in a.coupling_mut(j) {
                *v = -1.0 - next();
            }
        }
    }
    a
}

fn vector(n: usize, seed: u64) -> Vec<f64> {
    let mut next = generator(seed);
    (0..n).map(|_| next()).collect()
}

fn bordered_dense(a: &Staircase, border: &Border) -> DMatrix<f64> {
    let n = a.size();
    let mut m = DMatrix::zeros(n + 1, n + 1);
    m.view_mut((0, 0), (n, n)).copy_from(&a.to_dense());
    for i in 0..n {
        m[(i, n)] = border.column[i];
        m[(n, i)] = border.row[i];
    }
    m[(n, n)] = border.corner;
    m
}

fn assert_close(z: &[f64], dense: &DVector<f64>, tol: f64) {
    let err = z
        .iter()
        .zip(dense.iter())
        .fold(0.0, |m: f64, (a, b)| m.max((a - b).abs()));
    assert!(
        err <= tol * dense.amax(),
        "error {err:e} against {:e}",
        dense.amax()
    );
}

#[test]
fn the_plain_solve_equals_dense_lu() {
    for (first, dim, k) in [(3, 12, 1), (3, 12, 2), (1, 4, 9), (6, 15, 5)] {
        let a = sample(first, dim, k, 7);
        let b = vector(a.size(), 8);
        let mut lu = StaircaseLu::default();
        lu.factor(&a, None).unwrap();
        let mut x = b.clone();
        assert!(lu.solve(&mut x));
        let dense = a.to_dense().lu().solve(&DVector::from_vec(b)).unwrap();
        assert_close(&x, &dense, 1e-10);
        let (sign, log) = lu.log_determinant().unwrap();
        let det = a.to_dense().determinant();
        assert_eq!(sign, det.signum());
        assert!((log - det.abs().ln()).abs() <= 1e-10 * log.abs().max(1.0));
    }
}

#[test]
fn the_bordered_solve_equals_dense_lu() {
    for (first, dim, k) in [(3, 12, 1), (3, 12, 2), (1, 4, 9), (6, 15, 5)] {
        let a = sample(first, dim, k, 11);
        let n = a.size();
        let (column, row) = (vector(n, 12), vector(n, 13));
        let border = Border {
            column: &column,
            row: &row,
            corner: 0.3,
        };
        let rhs = vector(n + 1, 14);
        let mut lu = StaircaseLu::default();
        lu.factor(&a, Some(&border)).unwrap();
        let mut z = vec![0.0; n + 1];
        assert!(lu.solve_bordered(&a, &border, &rhs, &mut z));
        let m = bordered_dense(&a, &border);
        let dense = m
            .clone()
            .lu()
            .solve(&DVector::from_vec(rhs.clone()))
            .unwrap();
        assert_close(&z, &dense, 1e-10);
        let mut w = vec![0.0; n + 1];
        assert!(lu.solve_bordered_transposed(&a, &border, &rhs, &mut w));
        let dense = m.transpose().lu().solve(&DVector::from_vec(rhs)).unwrap();
        assert_close(&w, &dense, 1e-10);
    }
}

#[test]
fn the_transposed_product_is_the_dense_one() {
    let a = sample(3, 12, 5, 17);
    let x = vector(a.size(), 18);
    let mut y = vec![0.0; a.size()];
    a.mul_transposed(&x, &mut y);
    let dense = a.to_dense().transpose() * DVector::from_column_slice(&x);
    assert_close(&y, &dense, 1e-14);
}

/// A fold: A with a zero column (x₁[0] enters no equation) and a zero row
/// is singular, and the border makes M = [A b; cᵀ d] regular (b reaches
/// the zero row, c the null vector). Block elimination through A would
/// divide by zero; the embedding solves it as dense LU of M does.
#[test]
fn the_bordered_solve_is_exact_at_a_fold() {
    let (first, dim, k) = (3, 12, 6);
    let mut a = sample(first, dim, k, 21);
    a.coupling_mut(0)[0] = 0.0;
    a.block_mut(1).column_mut(0).fill(0.0);
    a.block_mut(3).row_mut(4).fill(0.0);
    a.coupling_mut(3)[4] = 0.0;
    let n = a.size();
    assert!(a.to_dense().lu().solve(&DVector::zeros(n)).is_none());
    let (column, row) = (vector(n, 22), vector(n, 23));
    let border = Border {
        column: &column,
        row: &row,
        corner: 0.0,
    };
    let rhs = vector(n + 1, 24);
    let mut lu = StaircaseLu::default();
    lu.factor(&a, Some(&border)).unwrap();
    let mut z = vec![0.0; n + 1];
    assert!(lu.solve_bordered(&a, &border, &rhs, &mut z));
    let m = bordered_dense(&a, &border);
    let dense = m
        .clone()
        .lu()
        .solve(&DVector::from_vec(rhs.clone()))
        .unwrap();
    assert_close(&z, &dense, 1e-10);
    let mut w = vec![0.0; n + 1];
    assert!(lu.solve_bordered_transposed(&a, &border, &rhs, &mut w));
    let dense = m.transpose().lu().solve(&DVector::from_vec(rhs)).unwrap();
    assert_close(&w, &dense, 1e-10);
}

/// An exact branch point: M itself singular (a zero row of A that the
/// border column misses), the right-hand side in its range. The
/// least-squares fallback returns a solution of M z = rhs.
#[test]
fn a_singular_bordered_system_falls_back_to_least_squares() {
    let (first, dim, k) = (3, 12, 6);
    let mut a = sample(first, dim, k, 31);
    a.block_mut(2).row_mut(5).fill(0.0);
    a.coupling_mut(2)[5] = 0.0;
    let n = a.size();
    let mut column = vector(n, 32);
    column[2 * dim + 5] = 0.0;
    let row = vector(n, 33);
    let border = Border {
        column: &column,
        row: &row,
        corner: 0.1,
    };
    let m = bordered_dense(&a, &border);
    let z0 = DVector::from_vec(vector(n + 1, 34));
    let rhs = &m * &z0;
    let mut lu = StaircaseLu::default();
    let z = match lu.factor(&a, Some(&border)) {
        Ok(()) => {
            let mut z = vec![0.0; n + 1];
            assert!(lu.solve_bordered(&a, &border, rhs.as_slice(), &mut z));
            z
        }
        Err(_) => least_squares(&a, &border, rhs.as_slice()).unwrap(),
    };
    let residual = &m * DVector::from_vec(z) - &rhs;
    assert!(
        residual.amax() <= 1e-8 * rhs.amax(),
        "residual {:e}",
        residual.amax()
    );
}
