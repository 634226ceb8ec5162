//! Tip conditions of the spatial levels for every [`TipSupport`], with
//! their exact Jacobians.
//!
//! Every residual is dimensionless in its own unit
//! ([`crate::model::Rod::residual_scales`]): position errors over L, turns
//! of the frame as rotation vectors (radians), forces over the force scale,
//! moments about d_i over that axis's moment scale — so that no stiffness
//! ratio makes one condition look met because another is large. A held
//! frame is enforced up to the identity only (not up to a turn by π): see
//! [`Turn`].

use nalgebra::{DMatrix, Matrix3, Vector3};

use crate::model::{across, Freedom, ResidualScales, TipSupport};

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
/// each row dimensionless in its own unit (`scales`): positions over L,
/// rotations as angles, forces over the force scale, moments about d_i over
/// the moment scale of that axis.
pub fn conditions(
    support: &TipSupport,
    tip: &TipState,
    scales: &ResidualScales,
    dim: usize,
) -> (Vec<f64>, DMatrix<f64>) {
    let mut rows = Vec::new();
    if support.holds_position() {
        translation_rows(support, tip, scales, &mut rows);
    }
    rotation_rows(support, tip, scales, &mut rows);
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
    scales: &ResidualScales,
    rows: &mut Vec<Row>,
) {
    let dr = tip.r - support.position;
    let per_length = 1.0 / scales.length;
    let position_row = |b: Vector3<f64>| Row {
        value: per_length * dr.dot(&b),
        grad: vec![(R, b * per_length)],
    };
    match support.translation {
        Freedom::Free => {}
        Freedom::Fixed => rows.extend((0..3).map(|j| position_row(Vector3::ith(j, 1.0)))),
        Freedom::Axial(a) => {
            rows.extend(across(&a).map(position_row));
            rows.push(Row {
                value: tip.reaction.dot(&a) / scales.force,
                grad: vec![(REACTION, a / scales.force)],
            });
        }
    }
}

fn rotation_rows(
    support: &TipSupport,
    tip: &TipState,
    scales: &ResidualScales,
    rows: &mut Vec<Row>,
) {
    match support.rotation {
        Freedom::Free => rows.extend(natural_rows(tip, &scales.moment)),
        Freedom::Fixed => {
            let turn = Turn::frame(support, tip);
            rows.extend((0..3).map(|j| turn.row(Vector3::ith(j, 1.0))));
        }
        Freedom::Axial(a) => {
            let turn = Turn::swing(support, tip, &a);
            rows.extend(across(&a).map(|b| turn.row(b)));
            rows.push(spin_row(tip, &a, scales.moment.min()));
        }
    }
}

/// (M_i(L) − C·d_i(L)) / M_s,i (paper (22)).
fn natural_rows(tip: &TipState, unit: &Vector3<f64>) -> Vec<Row> {
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
            let scale = 1.0 / unit[i];
            Row {
                value: scale * (tip.m[i] - c.dot(&tip.d[i])),
                grad: grad.into_iter().map(|(col, v)| (col, v * scale)).collect(),
            }
        })
        .collect()
}

/// How far the tip frame is turned from where the support holds it, as a
/// rotation vector ω = f(θ) v with v = sin θ · axis and f = θ / sin θ, so
/// that |ω| = θ ∈ [0, π] and ω vanishes only when the held directions
/// agree. (v alone also vanishes at a turn by π, which Newton could
/// converge to: a flipped frame taken for the prescribed one.)
///
/// - A held frame ([`Turn::frame`]): Q = R(L)R̂ᵀ, v = e = ½ Σ d_i × d̂_i
///   = −sin θ n, cos θ = (tr Q − 1)/2 with tr Q = Σ d̂_i·d_i.
/// - A frame free to spin about a ([`Turn::swing`]): only the axis is held,
///   Qa = Σ c_i d_i with c_i = d̂_i·a must equal a: v = a × Qa, cos β = a·Qa.
///
/// Derivatives: df = f′ dθ = −g d(cos θ) with g = f′/sin θ
/// = (sin θ − θ cos θ)/sin³ θ (→ 1/3 as θ → 0). With d3 = d1 × d2:
/// ∂e/∂d1 = −½[d̂1]× + ½[d̂3]×[d2]×, ∂e/∂d2 = −½[d̂2]× − ½[d̂3]×[d1]×,
/// ∂(tr Q)/∂d1 = d̂1 + d2 × d̂3, ∂(tr Q)/∂d2 = d̂2 + d̂3 × d1;
/// ∂(Qa)/∂d1 = c1 I − c3[d2]×, ∂(Qa)/∂d2 = c2 I + c3[d1]×.
struct Turn {
    v: Vector3<f64>,
    f: f64,
    g: f64,
    dv_d1: Matrix3<f64>,
    dv_d2: Matrix3<f64>,
    dcos_d1: Vector3<f64>,
    dcos_d2: Vector3<f64>,
}

impl Turn {
    /// The turn of the whole frame (a clamped tip).
    fn frame(support: &TipSupport, tip: &TipState) -> Self {
        let hat: [Vector3<f64>; 3] = std::array::from_fn(|i| support.frame.column(i).into_owned());
        let [d1, d2, _] = tip.d;
        let e: Vector3<f64> = (0..3)
            .map(|i| tip.d[i].cross(&hat[i]))
            .sum::<Vector3<f64>>()
            * 0.5;
        let trace: f64 = (0..3).map(|i| tip.d[i].dot(&hat[i])).sum();
        let x = |v: &Vector3<f64>| v.cross_matrix();
        Turn::with_angle(
            e,
            0.5 * (trace - 1.0),
            (-x(&hat[0]) + x(&hat[2]) * x(&d2)) * 0.5,
            (-x(&hat[1]) - x(&hat[2]) * x(&d1)) * 0.5,
            (hat[0] + d2.cross(&hat[2])) * 0.5,
            (hat[1] + hat[2].cross(&d1)) * 0.5,
        )
    }

    /// The swing of the axis a (a tip free to spin about a).
    fn swing(support: &TipSupport, tip: &TipState, a: &Vector3<f64>) -> Self {
        let [d1, d2, d3] = tip.d;
        let c: Vector3<f64> = support.frame.transpose() * a;
        let qa = d1 * c[0] + d2 * c[1] + d3 * c[2];
        let dqa_d1 = Matrix3::identity() * c[0] - d2.cross_matrix() * c[2];
        let dqa_d2 = Matrix3::identity() * c[1] + d1.cross_matrix() * c[2];
        let ax = a.cross_matrix();
        Turn::with_angle(
            a.cross(&qa),
            a.dot(&qa),
            ax * dqa_d1,
            ax * dqa_d2,
            dqa_d1.transpose() * a,
            dqa_d2.transpose() * a,
        )
    }

    fn with_angle(
        v: Vector3<f64>,
        cos: f64,
        dv_d1: Matrix3<f64>,
        dv_d2: Matrix3<f64>,
        dcos_d1: Vector3<f64>,
        dcos_d2: Vector3<f64>,
    ) -> Self {
        let (f, g) = turn_factors(v.norm().atan2(cos));
        Turn {
            v,
            f,
            g,
            dv_d1,
            dv_d2,
            dcos_d1,
            dcos_d2,
        }
    }

    /// b·ω and its gradient.
    fn row(&self, b: Vector3<f64>) -> Row {
        let vb = self.v.dot(&b);
        let grad = |dv: &Matrix3<f64>, dcos: &Vector3<f64>| {
            dv.transpose() * b * self.f - dcos * (self.g * vb)
        };
        Row {
            value: self.f * vb,
            grad: vec![
                (D1, grad(&self.dv_d1, &self.dcos_d1)),
                (D2, grad(&self.dv_d2, &self.dcos_d2)),
            ],
        }
    }
}

/// f(θ) = θ / sin θ and g(θ) = f′(θ)/sin θ = (sin θ − θ cos θ)/sin³ θ, by
/// their Taylor series near θ = 0 where the quotients lose digits. Beyond
/// θ ≈ π − 1e-8 (a frame turned half-way round) f is capped at that value:
/// the residual |ω| ≈ π there is far from zero, which is all Newton needs.
fn turn_factors(theta: f64) -> (f64, f64) {
    let t2 = theta * theta;
    if theta < 1e-3 {
        return (
            1.0 + t2 / 6.0 + 7.0 * t2 * t2 / 360.0,
            1.0 / 3.0 + t2 / 30.0,
        );
    }
    let theta = theta.min(std::f64::consts::PI - 1e-8);
    let (sin, cos) = theta.sin_cos();
    (theta / sin, (sin - theta * cos) / sin.powi(3))
}

/// (m(L)·a − C·a) / M_s with m = Σ M_i d_i: the couple about the spin
/// axis, in the smallest moment scale (a spin axis need not be a body axis).
fn spin_row(tip: &TipState, a: &Vector3<f64>, unit: f64) -> Row {
    let [d1, d2, d3] = tip.d;
    let m = tip.m;
    let da = Vector3::new(d1.dot(a), d2.dot(a), d3.dot(a));
    Row {
        value: (m.dot(&da) - tip.couple.dot(a)) / unit,
        grad: vec![
            (KAPPA, tip.h.transpose() * da / unit),
            (D1, (a * m[0] + d2.cross(a) * m[2]) / unit),
            (D2, (a * m[1] + a.cross(&d1) * m[2]) / unit),
        ],
    }
}
