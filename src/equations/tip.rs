//! Tip conditions of the spatial levels for every [`TipSupport`], with
//! their exact Jacobians.
//!
//! All residuals are moments (N·m) so that one moment scale makes them
//! dimensionless: position errors are multiplied by M_s/L, frame errors by
//! M_s and force errors by L. The frame error of a tip frame (d_i) against
//! the prescribed (d̂_i) is e = ½ Σ d_i × d̂_i, which vanishes exactly when
//! the frames agree and is parallel to a when they differ by a rotation
//! about a (so that "free to spin about a" is e·b1 = e·b2 = 0 with b1, b2
//! across a).

use nalgebra::{DMatrix, Matrix3, Vector3};

use crate::model::{across, Freedom, TipSupport};

/// The tip quantities the conditions read.
pub struct TipState<'a> {
    /// Directors at s = L.
    pub d: [Vector3<f64>; 3],
    /// r(L).
    pub r: Vector3<f64>,
    /// Body moment M(L) and H(L) = ∂M/∂κ.
    pub m: Vector3<f64>,
    pub h: Matrix3<f64>,
    /// The reaction R (zero when the position is not held).
    pub reaction: Vector3<f64>,
    /// The applied tip couple C (global).
    pub couple: &'a Vector3<f64>,
}

/// Column offsets of the state layout (d1, d2, κ, r, R).
const D1: usize = 0;
const D2: usize = 3;
const KAPPA: usize = 6;
const R: usize = 9;
const REACTION: usize = 12;

/// One residual row and its gradient with respect to the state.
struct Row {
    value: f64,
    grad: Vec<(usize, Vector3<f64>)>,
}

/// The tip residuals (3 or 6) and their Jacobian (rows × dim) for a support,
/// with scales `moment_scale` and `length`.
pub fn conditions(
    support: &TipSupport,
    tip: &TipState,
    moment_scale: f64,
    length: f64,
    dim: usize,
) -> (Vec<f64>, DMatrix<f64>) {
    let mut rows = Vec::new();
    if support.holds_position() {
        translation_rows(support, tip, moment_scale / length, length, &mut rows);
    }
    rotation_rows(support, tip, moment_scale, &mut rows);
    let mut g = DMatrix::zeros(rows.len(), dim);
    let values = rows
        .iter()
        .enumerate()
        .map(|(i, row)| {
            for (col, v) in &row.grad {
                for j in 0..3 {
                    g[(i, col + j)] += v[j];
                }
            }
            row.value
        })
        .collect();
    (values, g)
}

fn translation_rows(
    support: &TipSupport,
    tip: &TipState,
    position_scale: f64,
    length: f64,
    rows: &mut Vec<Row>,
) {
    let dr = tip.r - support.position;
    let position_row = |b: Vector3<f64>| Row {
        value: position_scale * dr.dot(&b),
        grad: vec![(R, b * position_scale)],
    };
    match support.translation {
        Freedom::Free => {}
        Freedom::Fixed => rows.extend((0..3).map(|j| position_row(Vector3::ith(j, 1.0)))),
        Freedom::Axial(a) => {
            rows.extend(across(&a).map(position_row));
            rows.push(Row {
                value: length * tip.reaction.dot(&a),
                grad: vec![(REACTION, a * length)],
            });
        }
    }
}

fn rotation_rows(support: &TipSupport, tip: &TipState, moment_scale: f64, rows: &mut Vec<Row>) {
    match support.rotation {
        Freedom::Free => rows.extend(natural_rows(tip)),
        Freedom::Fixed => {
            rows.extend((0..3).map(|j| frame_row(support, tip, Vector3::ith(j, 1.0), moment_scale)))
        }
        Freedom::Axial(a) => {
            rows.extend(across(&a).map(|b| frame_row(support, tip, b, moment_scale)));
            rows.push(spin_row(tip, &a));
        }
    }
}

/// M_i(L) = C·d_i(L) (paper (22)).
fn natural_rows(tip: &TipState) -> Vec<Row> {
    let c = tip.couple;
    let [d1, d2, _] = tip.d;
    (0..3)
        .map(|i| {
            let mut grad = vec![(KAPPA, tip.h.row(i).transpose())];
            match i {
                0 => grad.push((D1, -c)),
                1 => grad.push((D2, -c)),
                // ∂(C·d3)/∂d1 = d2 × C, ∂(C·d3)/∂d2 = C × d1.
                _ => {
                    grad.push((D1, -d2.cross(c)));
                    grad.push((D2, -c.cross(&d1)));
                }
            }
            Row {
                value: tip.m[i] - c.dot(&tip.d[i]),
                grad,
            }
        })
        .collect()
}

/// b·e with e = ½ Σ d_i × d̂_i: ∂e/∂d1 = −½[d̂1]× + ½[d̂3]×[d2]×,
/// ∂e/∂d2 = −½[d̂2]× − ½[d̂3]×[d1]× (d3 = d1 × d2).
fn frame_row(support: &TipSupport, tip: &TipState, b: Vector3<f64>, scale: f64) -> Row {
    let hat: [Vector3<f64>; 3] = std::array::from_fn(|i| support.frame.column(i).into_owned());
    let e: Vector3<f64> = (0..3)
        .map(|i| tip.d[i].cross(&hat[i]))
        .sum::<Vector3<f64>>()
        * 0.5;
    let x = |v: &Vector3<f64>| v.cross_matrix();
    let de_d1 = (-x(&hat[0]) + x(&hat[2]) * x(&tip.d[1])) * 0.5;
    let de_d2 = (-x(&hat[1]) - x(&hat[2]) * x(&tip.d[0])) * 0.5;
    Row {
        value: scale * e.dot(&b),
        grad: vec![
            (D1, de_d1.transpose() * b * scale),
            (D2, de_d2.transpose() * b * scale),
        ],
    }
}

/// m(L)·a = C·a with m = Σ M_i d_i: the couple about the spin axis.
fn spin_row(tip: &TipState, a: &Vector3<f64>) -> Row {
    let [d1, d2, d3] = tip.d;
    let m = tip.m;
    let da = Vector3::new(d1.dot(a), d2.dot(a), d3.dot(a));
    Row {
        value: m.dot(&da) - tip.couple.dot(a),
        grad: vec![
            (KAPPA, tip.h.transpose() * da),
            (D1, a * m[0] + d2.cross(a) * m[2]),
            (D2, a * m[1] + a.cross(&d1) * m[2]),
        ],
    }
}
