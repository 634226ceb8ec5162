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

/// What moves at a fixed tip state as p moves: the body moment's rate
/// δM(L) at fixed κ, the tip couple's δC, the support position's δX, the
/// spin Ω of the held frame (δd̂_i = Ω × d̂_i; a sliding or spin axis does
/// not move) and the residual units' rates.
pub struct TipRates<'a> {
    pub m: Vector3<f64>,
    pub couple: &'a Vector3<f64>,
    pub position: &'a Vector3<f64>,
    pub spin: &'a Vector3<f64>,
    pub scales: ResidualScales,
}

/// Whether [`condition_rates`] covers a support moving as `rates` say: a
/// held frame may spin unless the tip is free to spin about an axis (its
/// swing reads the frame through c = F̂ᵀa, not differentiated here).
pub fn rates_cover(support: &TipSupport, spin: &Vector3<f64>) -> bool {
    *spin == Vector3::zeros() || !matches!(support.rotation, Freedom::Axial(_))
}

/// ∂/∂p of [`conditions`] at a fixed tip state, row by row in the same
/// order: each row is a numerator over its unit, value = q/u, so
/// δvalue = δq/u − value δu/u. Positions: δq = −δX·b, u = L; the axial
/// force: δq = 0, u the force scale; natural rows: δq = δM_i − δC·d_i;
/// the spin row δq = δM·(d_i·a) − δC·a over the smallest moment scale;
/// the turn ω(d, d̂) of a held frame moves with the held frame's spin Ω
/// only: ω is equivariant (ω(Gd, Gd̂) = G ω(d, d̂) for a rotation G), so
/// δω = Ω × ω − ∂ω/∂d (Ω × d), the last term from the rows' own gradients
/// in d1, d2; a swing has no rate ([`rates_cover`]).
pub fn condition_rates(
    support: &TipSupport,
    tip: &TipState,
    scales: &ResidualScales,
    rates: &TipRates,
) -> Vec<f64> {
    let ratio = |value: f64, dq: f64, u: f64, du: f64| dq / u - value * du / u;
    let mut out = Vec::with_capacity(6);
    if support.holds_position() {
        let dr = tip.r - support.position;
        let (l, dl) = (scales.length, rates.scales.length);
        let mut position = |b: Vector3<f64>| {
            out.push(ratio(dr.dot(&b) / l, -rates.position.dot(&b), l, dl));
        };
        match support.translation {
            Freedom::Free => {}
            Freedom::Fixed => (0..3).for_each(|j| position(Vector3::ith(j, 1.0))),
            Freedom::Axial(a) => {
                across(&a).into_iter().for_each(&mut position);
                let value = tip.reaction.dot(&a) / scales.force;
                out.push(ratio(value, 0.0, scales.force, rates.scales.force));
            }
        }
    }
    match support.rotation {
        Freedom::Free => {
            for i in 0..3 {
                let (u, du) = (scales.moment[i], rates.scales.moment[i]);
                let value = (tip.m[i] - tip.couple.dot(&tip.d[i])) / u;
                out.push(ratio(
                    value,
                    rates.m[i] - rates.couple.dot(&tip.d[i]),
                    u,
                    du,
                ));
            }
        }
        Freedom::Fixed => {
            let turn = Turn::frame(support, tip);
            let omega = turn.v * turn.f;
            let spin = rates.spin;
            let moved = [-spin.cross(&tip.d[0]), -spin.cross(&tip.d[1])];
            for j in 0..3 {
                let b = Vector3::ith(j, 1.0);
                let row = turn.row(b);
                let inner: f64 = row
                    .grad
                    .iter()
                    .map(|(col, g)| g.dot(&moved[usize::from(*col == D2)]))
                    .sum();
                out.push(b.dot(&spin.cross(&omega)) + inner);
            }
        }
        Freedom::Axial(a) => {
            out.extend([0.0; 2]);
            let i = scales.moment.imin();
            let (u, du) = (scales.moment[i], rates.scales.moment[i]);
            let da = Vector3::new(tip.d[0].dot(&a), tip.d[1].dot(&a), tip.d[2].dot(&a));
            let value = (tip.m.dot(&da) - tip.couple.dot(&a)) / u;
            out.push(ratio(value, rates.m.dot(&da) - rates.couple.dot(&a), u, du));
        }
    }
    out
}
