//! DOP853's continuous extension of order 7 (Hairer, Nørsett & Wanner,
//! *Solving ODEs I*, 2nd ed., Sec. II.6; dop853.f, `contd8`): after an
//! accepted step from (s, y₀) to (s + h, y₁), three more stages give
//!
//!   y(s + θh) = y₀ + θ(F₀ + (1−θ)(F₁ + θ(F₂ + (1−θ)(F₃ + θ(F₄ + (1−θ)(F₅ + θF₆)))))),
//!
//! F₀ = y₁ − y₀, F₁ = h f₀ − F₀, F₂ = 2F₀ − h(f₁ + f₀), F₃₊ₘ = h Σⱼ dₘⱼ kⱼ,
//! exact at both ends and within the step's own error in between. The
//! coefficients are dop853.f's, digit for digit (as tabulated in SciPy's
//! `dop853_coefficients.py`).

#![allow(clippy::excessive_precision)]

use super::{axpy, Dop853, StageVector};

/// Nodes of the extra stages 14, 15, 16.
const C_EXTRA: [f64; 3] = [0.1, 0.2, 0.777777777777777777777777777778];

/// Their coefficients on stages 1..16 (stage 13 is f(s + h, y₁)), as
/// (stage index from 0, a).
const A_EXTRA: [&[(usize, f64)]; 3] = [
    &[
        (0, 5.61675022830479523392909219681e-2),
        (6, 2.53500210216624811088794765333e-1),
        (7, -2.46239037470802489917441475441e-1),
        (8, -1.24191423263816360469010140626e-1),
        (9, 1.5329179827876569731206322685e-1),
        (10, 8.20105229563468988491666602057e-3),
        (11, 7.56789766054569976138603589584e-3),
        (12, -8.298e-3),
    ],
    &[
        (0, 3.18346481635021405060768473261e-2),
        (5, 2.83009096723667755288322961402e-2),
        (6, 5.35419883074385676223797384372e-2),
        (7, -5.49237485713909884646569340306e-2),
        (10, -1.08347328697249322858509316994e-4),
        (11, 3.82571090835658412954920192323e-4),
        (12, -3.40465008687404560802977114492e-4),
        (13, 1.41312443674632500278074618366e-1),
    ],
    &[
        (0, -4.28896301583791923408573538692e-1),
        (5, -4.69762141536116384314449447206e0),
        (6, 7.68342119606259904184240953878e0),
        (7, 4.06898981839711007970213554331e0),
        (8, 3.56727187455281109270669543021e-1),
        (12, -1.39902416515901462129418009734e-3),
        (13, 2.9475147891527723389556272149e0),
        (14, -9.15095847217987001081870187138e0),
    ],
];

/// d₄ⱼ … d₇ⱼ of dop853.f on stages 1, 6..16 (the others are zero).
const D_STAGES: [usize; 12] = [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];
#[rustfmt::skip]
const D: [[f64; 12]; 4] = [
    [-0.84289382761090128651353491142e1, 0.56671495351937776962531783590e0,
     -0.30689499459498916912797304727e1, 0.23846676565120698287728149680e1,
     0.21170345824450282767155149946e1, -0.87139158377797299206789907490e0,
     0.22404374302607882758541771650e1, 0.63157877876946881815570249290e0,
     -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e2,
     -0.91946323924783554000451984436e1, -0.44360363875948939664310572000e1],
    [0.10427508642579134603413151009e2, 0.24228349177525818288430175319e3,
     0.16520045171727028198505394887e3, -0.37454675472269020279518312152e3,
     -0.22113666853125306036270938578e2, 0.77334326684722638389603898808e1,
     -0.30674084731089398182061213626e2, -0.93321305264302278729567221706e1,
     0.15697238121770843886131091075e2, -0.31139403219565177677282850411e2,
     -0.93529243588444783865713862664e1, 0.35816841486394083752465898540e2],
    [0.19985053242002433820987653617e2, -0.38703730874935176555105901742e3,
     -0.18917813819516756882830838328e3, 0.52780815920542364900561016686e3,
     -0.11573902539959630126141871134e2, 0.68812326946963000169666922661e1,
     -0.10006050966910838403183860980e1, 0.77771377980534432092869265740e0,
     -0.27782057523535084065932004339e1, -0.60196695231264120758267380846e2,
     0.84320405506677161018159903784e2, 0.11992291136182789328035130030e2],
    [-0.25693933462703749003312586129e2, -0.15418974869023643374053993627e3,
     -0.23152937917604549567536039109e3, 0.35763911791061412378285349910e3,
     0.93405324183624310003907691704e2, -0.37458323136451633156875139351e2,
     0.10409964950896230045147246184e3, 0.29840293426660503123344363579e2,
     -0.43533456590011143754432175058e2, 0.96324553959188282948394950600e2,
     -0.39177261675615439165231486172e2, -0.14972683625798562581422125276e3],
];

/// The continuous extension of the last accepted step, with its buffers.
#[derive(Debug, Clone)]
pub(super) struct Interpolant {
    pub(super) y_old: Vec<f64>,
    /// Stages 13..16: f(s + h, y₁) and the three extra ones.
    late: [Vec<f64>; 4],
    pub(super) coefficients: [Vec<f64>; 7],
    value: Vec<f64>,
}

impl Interpolant {
    fn new(n: usize) -> Self {
        Interpolant {
            y_old: vec![0.0; n],
            late: std::array::from_fn(|_| vec![0.0; n]),
            coefficients: std::array::from_fn(|_| vec![0.0; n]),
            value: vec![0.0; n],
        }
    }

    /// Remembers the state at the start of the step.
    pub(super) fn start(&mut self, y: &[f64]) {
        self.y_old.copy_from_slice(y);
    }

    /// f(s + h, y₁), evaluated by [`Dop853::extend`]: the next step's
    /// first stage.
    pub(super) fn end_slope(&self) -> &[f64] {
        &self.late[0]
    }

    /// The state at θ ∈ [0, 1] of the step, passed through `project`.
    pub(super) fn at(&mut self, theta: f64, project: &mut impl FnMut(&mut [f64])) -> &[f64] {
        interpolate(&self.coefficients, &self.y_old, theta, &mut self.value);
        project(&mut self.value);
        &self.value
    }
}

/// The extension y₀ + θ(F₀ + (1−θ)(F₁ + …)) of a step at θ into `value`,
/// from its start y₀ and coefficients F₀ … F₆ (heap vectors or arrays).
pub(super) fn interpolate<K: StageVector>(
    coefficients: &[K; 7],
    y_old: &[f64],
    theta: f64,
    value: &mut [f64],
) {
    value.fill(0.0);
    for (i, f) in coefficients.iter().rev().enumerate() {
        let w = if i % 2 == 0 { theta } else { 1.0 - theta };
        value
            .iter_mut()
            .zip(f.as_ref())
            .for_each(|(v, c)| *v = (*v + c) * w);
    }
    axpy(value, 1.0, y_old);
}

/// The extension's three extra stages (`late[1..]`, with `late[0]` =
/// f(s + h, y_new) already evaluated) and its coefficients F₀ … F₆, of
/// the step of size h from (s, y_old) to `y_new` whose 12 stages are in
/// `k`; shared by [`Dop853`] and [`super::FixedDop853`] as the stages
/// are.
#[allow(clippy::too_many_arguments)]
pub(super) fn extension<K: StageVector, F: FnMut(f64, &K, &mut K)>(
    k: &[K; 12],
    stage: &mut K,
    late: &mut [K; 4],
    coefficients: &mut [K; 7],
    f: &mut F,
    (s, h): (f64, f64),
    y_old: &[f64],
    y_new: &[f64],
) {
    for (i, (&c, row)) in C_EXTRA.iter().zip(A_EXTRA).enumerate() {
        stage.as_mut().copy_from_slice(y_old);
        for &(j, a) in row {
            let kj = if j < 12 {
                k[j].as_ref()
            } else {
                late[j - 12].as_ref()
            };
            axpy(stage.as_mut(), h * a, kj);
        }
        f(s + c * h, stage, &mut late[i + 1]);
    }
    let [f0, f1, f2, rest @ ..] = coefficients;
    let (f0, f1, f2) = (f0.as_mut(), f1.as_mut(), f2.as_mut());
    let (k0, end_slope) = (k[0].as_ref(), late[0].as_ref());
    for i in 0..y_new.len() {
        let dy = y_new[i] - y_old[i];
        f0[i] = dy;
        f1[i] = h * k0[i] - dy;
        f2[i] = 2.0 * dy - h * (end_slope[i] + k0[i]);
    }
    for (fm, d) in rest.iter_mut().zip(&D) {
        let fm = fm.as_mut();
        fm.fill(0.0);
        for (&j, &dj) in D_STAGES.iter().zip(d) {
            let kj = if j < 12 {
                k[j].as_ref()
            } else {
                late[j - 12].as_ref()
            };
            axpy(fm, h * dj, kj);
        }
    }
}

/// The continuous extensions of consecutive accepted steps (one
/// integration, or several appended in increasing s): the solution at any
/// point of the steps' span from seven coefficient vectors and the step's
/// start state, as the step's own extension reads them, without integrating
/// again. Flat storage: per step its start, its size and 8 n numbers.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DenseRecord {
    n: usize,
    starts: Vec<f64>,
    steps: Vec<f64>,
    /// Per step: y_old, then F₀ … F₆.
    data: Vec<f64>,
}

impl DenseRecord {
    /// An empty record of states of dimension n.
    pub fn new(n: usize) -> Self {
        DenseRecord {
            n,
            ..Default::default()
        }
    }

    /// Whether no step is recorded.
    pub fn is_empty(&self) -> bool {
        self.starts.is_empty()
    }

    /// The recorded span [first step's start, last step's end].
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((
            *self.starts.first()?,
            self.starts.last()? + self.steps.last()?,
        ))
    }

    /// Appends another record whose steps follow this one's.
    pub fn append(&mut self, mut other: DenseRecord) {
        if self.is_empty() {
            self.n = other.n;
        }
        self.starts.append(&mut other.starts);
        self.steps.append(&mut other.steps);
        self.data.append(&mut other.data);
    }

    /// Appends the step of `step` from `start` whose extension starts at
    /// `y_old` with `coefficients` F₀ … F₆.
    pub(super) fn push<K: StageVector>(
        &mut self,
        start: f64,
        step: f64,
        y_old: &[f64],
        coefficients: &[K; 7],
    ) {
        self.starts.push(start);
        self.steps.push(step);
        self.data.extend_from_slice(y_old);
        for c in coefficients {
            self.data.extend_from_slice(c.as_ref());
        }
    }

    /// The state at t into `y` (not projected), from the last step that
    /// starts at or before t (so that at a jump s_k, where one piece ends
    /// an ulp below s_k and the next starts at s_k, the right limit), θ
    /// held in [0, 1]; false when t lies outside the recorded span.
    pub fn state_at(&self, t: f64, y: &mut [f64]) -> bool {
        let Some((a, b)) = self.span() else {
            return false;
        };
        if !(a..=b).contains(&t) {
            return false;
        }
        let i = self.starts.partition_point(|&s| s <= t).saturating_sub(1);
        let theta = ((t - self.starts[i]) / self.steps[i]).clamp(0.0, 1.0);
        let n = self.n;
        let block = &self.data[i * 8 * n..(i + 1) * 8 * n];
        y.fill(0.0);
        for (j, f) in block[n..].chunks_exact(n).rev().enumerate() {
            let w = if j % 2 == 0 { theta } else { 1.0 - theta };
            y.iter_mut().zip(f).for_each(|(v, c)| *v = (*v + c) * w);
        }
        axpy(y, 1.0, &block[..n]);
        true
    }
}

impl Dop853 {
    /// The interpolant's storage for dimension n.
    pub(super) fn interpolant(&mut self, n: usize) -> &mut Interpolant {
        if self.dense.as_ref().is_none_or(|d| d.y_old.len() != n) {
            self.dense = Some(Interpolant::new(n));
        }
        self.dense.as_mut().expect("just built")
    }

    /// Builds the extension of the step of size h from s (its 12 stages
    /// still in `k`, its start remembered by [`Interpolant::start`]) to
    /// `y_new`; returns the right-hand side evaluations made (4).
    pub(super) fn extend<F: FnMut(f64, &[f64], &mut [f64])>(
        &mut self,
        f: &mut F,
        s: f64,
        h: f64,
        y_new: &[f64],
    ) -> usize {
        let mut dense = self.dense.take().expect("Interpolant::start came first");
        f(s + h, y_new, &mut dense.late[0]);
        extension(
            &self.k,
            &mut self.stage,
            &mut dense.late,
            &mut dense.coefficients,
            &mut |t, a: &Vec<f64>, b: &mut Vec<f64>| f(t, a, b),
            (s, h),
            &dense.y_old,
            y_new,
        );
        self.dense = Some(dense);
        4
    }
}

#[cfg(test)]
mod tests {
    use super::super::Tolerances;
    use super::*;

    /// y' = y from 0 to 1 with 200 interpolated stops: every sample
    /// matches eˢ to the tolerance, with no more steps than without stops.
    #[test]
    fn interpolated_stops_match_the_exponential() {
        let tol = Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
            max_steps: 10_000,
        };
        let stops: Vec<f64> = (0..=200).map(|i| f64::from(i) / 200.0).collect();
        let rhs = |_: f64, y: &[f64], d: &mut [f64]| d[0] = y[0];
        let mut seen = vec![];
        let mut y = [1.0];
        let mut dop = Dop853::new(1);
        let sampled = dop
            .integrate_serving(
                rhs,
                (0.0, 1.0, 1),
                &mut y,
                &tol,
                &stops,
                super::super::Stops::Interpolated,
                |s, y| seen.push((s, y[0])),
                |_| {},
            )
            .unwrap();
        let mut plain_y = [1.0];
        let plain = dop
            .integrate(rhs, 0.0, 1.0, &mut plain_y, 1, &tol, &[], |_, _| {}, |_| {})
            .unwrap();
        assert_eq!(seen.len(), stops.len());
        assert_eq!(sampled.accepted, plain.accepted);
        for (s, v) in seen {
            assert!(
                (v - s.exp()).abs() < 1e-11,
                "s = {s}: {v} against {}",
                s.exp()
            );
        }
    }

    /// One step of size h on y' = y², y(0) = 1 (y = 1/(1 − s)): the
    /// extension's error inside the step falls at least like h⁸ (order 7):
    /// halving h divides it by at least about 2⁸.
    #[test]
    fn extension_error_has_order_seven_or_more() {
        let mut dop = Dop853::new(1);
        let mut inside = |h: f64| {
            let mut f = |_: f64, y: &[f64], d: &mut [f64]| d[0] = y[0] * y[0];
            f(0.0, &[1.0], &mut dop.k[0]);
            dop.stages(&mut f, 0.0, h, &[1.0]);
            dop.interpolant(1).start(&[1.0]);
            let end = dop.next.clone();
            dop.extend(&mut f, 0.0, h, &end);
            let mut dense = dop.dense.take().unwrap();
            let v = dense.at(0.37, &mut |_| {})[0];
            (v - 1.0 / (1.0 - 0.37 * h)).abs()
        };
        let (e1, e2) = (inside(0.2), inside(0.1));
        let order = (e1 / e2).log2();
        assert!(order > 7.5, "local order {order} ({e1:e}, {e2:e})");
    }

    /// y' = y from 0 to 1 recorded: the record read anywhere afterwards
    /// gives the states the served stops gave, with the same steps, and
    /// matches eˢ to the tolerance; outside the span it says so.
    #[test]
    fn recorded_steps_give_the_served_states() {
        let tol = Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
            max_steps: 10_000,
        };
        let stops: Vec<f64> = (0..=37).map(|i| f64::from(i) / 37.0).collect();
        let rhs = |_: f64, y: &[f64], d: &mut [f64]| d[0] = y[0];
        let serve = |how| {
            let mut seen = vec![];
            let mut dop = Dop853::new(1);
            let stats = dop
                .integrate_serving(
                    rhs,
                    (0.0, 1.0, 1),
                    &mut [1.0],
                    &tol,
                    &stops,
                    how,
                    |_, y| seen.push(y[0]),
                    |_| {},
                )
                .unwrap();
            (seen, stats, dop.take_record())
        };
        let (served, plain, none) = serve(super::super::Stops::Interpolated);
        let (recorded, stats, record) = serve(super::super::Stops::Recorded);
        assert!(none.is_empty());
        assert_eq!(stats.accepted, plain.accepted);
        assert_eq!(served, recorded);
        let mut y = [0.0];
        for (&t, &v) in stops.iter().zip(&served) {
            assert!(record.state_at(t, &mut y));
            assert!(
                (y[0] - v).abs() <= 4.0 * f64::EPSILON * v,
                "{t}: {} against {v}",
                y[0]
            );
        }
        for t in [0.123, 0.5, 0.999] {
            assert!(record.state_at(t, &mut y));
            assert!((y[0] - f64::exp(t)).abs() < 1e-11);
        }
        assert!(!record.state_at(1.0 + 1e-9, &mut y));
        assert!(!record.state_at(-1e-9, &mut y));
    }
}
