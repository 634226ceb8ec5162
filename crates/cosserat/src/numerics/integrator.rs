//! The adaptive explicit Runge–Kutta method of Dormand and Prince, order 8
//! with the 5th- and 3rd-order embedded error estimate (DOP853; Hairer,
//! Nørsett & Wanner, *Solving ODEs I*, 2nd ed., Sec. II.10).
//!
//! Shooting integrates the state together with its sensitivities (the
//! variational equations) on the same steps, so the Jacobian it returns is
//! the exact derivative of the discrete flow ("internal numerical
//! differentiation", Bock 1981). Step size control therefore looks only at
//! the first `controlled` components (the state), never at the
//! sensitivities. After each accepted step an optional projection restores
//! invariants (orthonormal directors).

// The tableau is kept digit for digit as published (dop853.f).
#![allow(clippy::excessive_precision)]

mod dense;
mod fixed;

pub use dense::DenseRecord;
pub use fixed::{FixedDop853, FixedRecorder};

/// Tolerances and limits of one integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance per step.
    pub rtol: f64,
    /// Absolute tolerance per step.
    pub atol: f64,
    /// Maximum number of steps (accepted and rejected).
    pub max_steps: usize,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
            max_steps: 100_000,
        }
    }
}

/// Work done by one integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IntegrationStats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Right-hand side evaluations.
    pub evaluations: usize,
}

impl std::ops::AddAssign for IntegrationStats {
    fn add_assign(&mut self, o: Self) {
        self.accepted += o.accepted;
        self.rejected += o.rejected;
        self.evaluations += o.evaluations;
    }
}

/// Why an integration stopped before its end.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum IntegrationError {
    /// The solution left the finite numbers (blow-up).
    #[error("the solution is not finite at s = {s:.6e} (blow-up)")]
    NotFinite {
        /// Arc length where the state stopped being finite.
        s: f64,
    },
    /// The step size fell below round-off of s.
    #[error("step size underflow at s = {s:.6e} (stiff or singular equations)")]
    StepSizeUnderflow {
        /// Arc length where the step fell below round-off.
        s: f64,
    },
    /// The step budget ran out.
    #[error("more than {steps} steps before s = {s:.6e}")]
    TooManySteps {
        /// Arc length reached when the budget ran out.
        s: f64,
        /// The step budget.
        steps: usize,
    },
    /// The state's jump at an interior point had no value: the equation
    /// that gives the state after the jump (the curvature that carries the
    /// moment after a point couple) has no solution its Newton found.
    #[error("the state has no value after its jump at s = {s:.6e} ({reason})")]
    JumpWithoutValue {
        /// The point of the jump.
        s: f64,
        /// Why, in words.
        reason: &'static str,
    },
}

// Butcher tableau of DOP853 (Hairer's dop853.f; stages 1..12, c12 = 1).
const C: [f64; 12] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510e+00,
    0.281649658092772603273242802490e+00,
    0.333333333333333333333333333333e+00,
    0.25e+00,
    0.307692307692307692307692307692e+00,
    0.651282051282051282051282051282e+00,
    0.6e+00,
    0.857142857142857142857142857142e+00,
    1.0,
];

#[rustfmt::skip]
const A: [[f64; 11]; 12] = [
    [0.0; 11],
    [5.26001519587677318785587544488e-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [2.95875854768068491816892993775e-2, 0.0, 8.87627564304205475450678981324e-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [2.41365134159266685502369798665e-1, 0.0, -8.84549479328286085344864962717e-1, 9.24834003261792003115737966543e-1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.7037037037037037037037037037e-2, 0.0, 0.0, 1.70828608729473871279604482173e-1, 1.25467687566822425016691814123e-1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.7109375e-2, 0.0, 0.0, 1.70252211019544039314978060272e-1, 6.02165389804559606850219397283e-2, -1.7578125e-2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.70920001185047927108779319836e-2, 0.0, 0.0, 1.70383925712239993810214054705e-1, 1.07262030446373284651809199168e-1, -1.53194377486244017527936158236e-2, 8.27378916381402288758473766002e-3, 0.0, 0.0, 0.0, 0.0],
    [6.24110958716075717114429577812e-1, 0.0, 0.0, -3.36089262944694129406857109825e0, -8.68219346841726006818189891453e-1, 2.75920996994467083049415600797e1, 2.01540675504778934086186788979e1, -4.34898841810699588477366255144e1, 0.0, 0.0, 0.0],
    [4.77662536438264365890433908527e-1, 0.0, 0.0, -2.48811461997166764192642586468e0, -5.90290826836842996371446475743e-1, 2.12300514481811942347288949897e1, 1.52792336328824235832596922938e1, -3.32882109689848629194453265587e1, -2.03312017085086261358222928593e-2, 0.0, 0.0],
    [-9.3714243008598732571704021658e-1, 0.0, 0.0, 5.18637242884406370830023853209e0, 1.09143734899672957818500254654e0, -8.14978701074692612513997267357e0, -1.85200656599969598641566180701e1, 2.27394870993505042818970056734e1, 2.49360555267965238987089396762e0, -3.0467644718982195003823669022e0, 0.0],
    [2.27331014751653820792359768449e0, 0.0, 0.0, -1.05344954667372501984066689879e1, -2.00087205822486249909675718444e0, -1.79589318631187989172765950534e1, 2.79488845294199600508499808837e1, -2.85899827713502369474065508674e0, -8.87285693353062954433549289258e0, 1.23605671757943030647266201528e1, 6.43392746015763530355970484046e-1],
];

/// 8th-order weights.
#[rustfmt::skip]
const B: [f64; 12] = [
    5.42937341165687622380535766363e-2, 0.0, 0.0, 0.0, 0.0,
    4.45031289275240888144113950566e0, 1.89151789931450038304281599044e0,
    -5.8012039600105847814672114227e0, 3.1116436695781989440891606237e-1,
    -1.52160949662516078556178806805e-1, 2.01365400804030348374776537501e-1,
    4.47106157277725905176885569043e-2,
];

/// B minus the 3rd-order weights (nonzero at stages 1, 9, 12).
const BHH: [f64; 3] = [
    0.244094488188976377952755905512e+00,
    0.733846688281611857341361741547e+00,
    0.220588235294117647058823529412e-01,
];

/// The 5th-order error weights.
#[rustfmt::skip]
const ER: [f64; 12] = [
    0.1312004499419488073250102996e-01, 0.0, 0.0, 0.0, 0.0,
    -0.1225156446376204440720569753e+01, -0.4957589496572501915214079952e+00,
    0.1664377182454986536961530415e+01, -0.3503288487499736816886487290e+00,
    0.3341791187130174790297318841e+00, 0.8192320648511571246570742613e-01,
    -0.2235530786388629525884427845e-01,
];

/// A DOP853 integrator with its stage storage, reusable across calls so that
/// Newton iterations allocate nothing.
#[derive(Debug, Clone)]
pub struct Dop853 {
    k: [Vec<f64>; 12],
    stage: Vec<f64>,
    next: Vec<f64>,
    /// The continuous extension, built on the first interpolated stop.
    dense: Option<dense::Interpolant>,
    /// The extensions of the steps integrated with [`Stops::Recorded`].
    record: DenseRecord,
}

impl Dop853 {
    /// Storage for systems of dimension `n`.
    pub fn new(n: usize) -> Self {
        Dop853::with_room(n, n)
    }

    /// Storage for systems of dimension `n`, with room for dimensions up
    /// to `room` without reallocating: shooting alternates between the
    /// state alone and the state with its sensitivities.
    pub fn with_room(n: usize, room: usize) -> Self {
        let vector = || {
            let mut v = Vec::with_capacity(n.max(room));
            v.resize(n, 0.0);
            v
        };
        Dop853 {
            k: std::array::from_fn(|_| vector()),
            stage: vector(),
            next: vector(),
            dense: None,
            record: DenseRecord::new(n),
        }
    }

    /// The continuous extensions recorded since the last call (in the
    /// order integrated), leaving an empty record.
    pub fn take_record(&mut self) -> DenseRecord {
        let n = self.stage.len();
        std::mem::replace(&mut self.record, DenseRecord::new(n))
    }

    /// Stage storage for dimension n, reusing the vectors' capacity: a
    /// shooting solve alternates between the state with its sensitivities
    /// and the state alone, which reallocated all fourteen vectors at every
    /// switch. A record of another dimension starts empty.
    fn resize(&mut self, n: usize) {
        if self.stage.len() != n {
            for v in self.k.iter_mut().chain([&mut self.stage, &mut self.next]) {
                v.resize(n, 0.0);
            }
            self.record = DenseRecord::new(n);
        }
    }

    /// Integrates y' = f(s, y) from `s0` to `s1` (s1 > s0) in place.
    ///
    /// Step size control uses the first `controlled` components. Steps land
    /// exactly on every point of `stops` (sorted, inside [s0, s1]), where
    /// `observe(s, y)` is called; `project` runs after every accepted step.
    #[allow(clippy::too_many_arguments)]
    pub fn integrate<F, O, P>(
        &mut self,
        f: F,
        s0: f64,
        s1: f64,
        y: &mut [f64],
        controlled: usize,
        tol: &Tolerances,
        stops: &[f64],
        observe: O,
        project: P,
    ) -> Result<IntegrationStats, IntegrationError>
    where
        F: FnMut(f64, &[f64], &mut [f64]),
        O: FnMut(f64, &[f64]),
        P: FnMut(&mut [f64]),
    {
        let span = (s0, s1, controlled);
        self.integrate_serving(f, span, y, tol, stops, Stops::Landed, observe, project)
    }

    /// As [`Dop853::integrate`] with `span` = (s0, s1, controlled), the
    /// `stops` served as `serve` says: [`Stops::Landed`] is `integrate`;
    /// with [`Stops::Interpolated`] the steps ignore the stops and the
    /// state at each stop inside a step comes from DOP853's continuous
    /// extension of order 7 (Hairer, Nørsett & Wanner, Sec. II.6;
    /// dop853.f, `contd8`; four more evaluations per step that holds a
    /// stop, one of them the next step's first stage), then `project`ed,
    /// so that many output points cost no more steps than the tolerance
    /// needs. A stop at a step's end is the state itself.
    #[allow(clippy::too_many_arguments)]
    pub fn integrate_serving<F, O, P>(
        &mut self,
        mut f: F,
        span: (f64, f64, usize),
        y: &mut [f64],
        tol: &Tolerances,
        stops: &[f64],
        serve: Stops,
        mut observe: O,
        mut project: P,
    ) -> Result<IntegrationStats, IntegrationError>
    where
        F: FnMut(f64, &[f64], &mut [f64]),
        O: FnMut(f64, &[f64]),
        P: FnMut(&mut [f64]),
    {
        let (s0, s1, controlled) = span;
        let n = y.len();
        self.resize(n);
        let mut s = s0;
        let mut next_stop = stops.partition_point(|&t| t < s0);
        while next_stop < stops.len() && stops[next_stop] <= s0 {
            observe(s0, y);
            next_stop += 1;
        }
        f(s, y, &mut self.k[0]);
        let h = initial_step(
            &mut self.k,
            &mut self.stage,
            &mut |t, a: &Vec<f64>, b: &mut Vec<f64>| f(t, a, b),
            s,
            s1,
            y,
            controlled,
            tol,
        );
        let mut control = StepControl::new(h);
        while s < s1 {
            let target = match serve {
                Stops::Landed => stops.get(next_stop).copied().unwrap_or(s1).min(s1),
                Stops::Interpolated | Stops::Recorded => s1,
            };
            let (step, lands) = control.propose(s, target, tol)?;
            stages(
                &mut self.k,
                &mut self.stage,
                &mut self.next,
                &mut |t, a: &Vec<f64>, b: &mut Vec<f64>| f(t, a, b),
                s,
                step,
                y,
            );
            let err = error_norm(&self.k, &self.next, step, y, controlled, tol);
            if !control.judge(err, step, lands, s, (s0, s1))? {
                continue;
            }
            let start = s;
            s = if lands { target } else { s + step };
            let inside = stops[next_stop..].partition_point(|&t| t <= s);
            let extended = serve.extends(inside);
            if extended {
                // The extension needs y and f at the step's start.
                self.interpolant(n).start(y);
            }
            y.copy_from_slice(&self.next);
            project(y);
            if y.iter().any(|v| !v.is_finite()) {
                return Err(IntegrationError::NotFinite { s });
            }
            if extended {
                control.stats.evaluations += self.extend(&mut f, start, step, y);
                let mut dense = self.dense.take().expect("built by interpolant");
                if serve == Stops::Recorded {
                    self.record
                        .push(start, step, &dense.y_old, &dense.coefficients);
                }
                for &t in &stops[next_stop..next_stop + inside] {
                    // The step's end is the state itself, as when landed.
                    if t == s {
                        observe(t, y);
                    } else {
                        observe(t, dense.at((t - start) / step, &mut project));
                    }
                }
                // f(s, y) is the extension's first extra stage.
                self.k[0].copy_from_slice(dense.end_slope());
                self.dense = Some(dense);
                next_stop += inside;
            } else {
                f(s, y, &mut self.k[0]);
                control.stats.evaluations += 1;
            }
            if lands && next_stop < stops.len() && target == stops[next_stop] {
                observe(s, y);
                next_stop += 1;
            }
        }
        Ok(control.stats)
    }
}

/// Stage storage of one step: a vector of the system's dimension (a
/// `Vec` for [`Dop853`], an array for [`FixedDop853`], whose loops then
/// have a length known at compile time).
pub(crate) trait StageVector: AsRef<[f64]> + AsMut<[f64]> {}

impl<K: AsRef<[f64]> + AsMut<[f64]>> StageVector for K {}

/// Hairer's starting step (II.4, "automatic selection of the initial
/// step size"), with k[0] = f(s, y) already evaluated; k[1] and `stage`
/// are overwritten.
#[allow(clippy::too_many_arguments)]
fn initial_step<K: StageVector, F: FnMut(f64, &K, &mut K)>(
    k: &mut [K; 12],
    stage: &mut K,
    f: &mut F,
    s: f64,
    s1: f64,
    y: &[f64],
    controlled: usize,
    tol: &Tolerances,
) -> f64 {
    let scale = |v: f64| tol.atol + tol.rtol * v.abs();
    let rms = |a: &dyn Fn(usize) -> f64| {
        ((0..controlled).map(|i| a(i).powi(2)).sum::<f64>() / controlled.max(1) as f64).sqrt()
    };
    let d0 = rms(&|i| y[i] / scale(y[i]));
    let d1 = rms(&|i| k[0].as_ref()[i] / scale(y[i]));
    let span = s1 - s;
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6 * span
    } else {
        (0.01 * d0 / d1).min(span)
    };
    for (i, st) in stage.as_mut().iter_mut().enumerate() {
        *st = y[i] + h0 * k[0].as_ref()[i];
    }
    let (k0, rest) = k.split_at_mut(1);
    f(s + h0, stage, &mut rest[0]);
    let (k0, k1) = (k0[0].as_ref(), rest[0].as_ref());
    let d2 = rms(&|i| (k1[i] - k0[i]) / scale(y[i])) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6 * span)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / 8.0)
    };
    // Hairer's 100 h0 bound, but not below 1e-6 of the span: with y
    // nearly zero and above Hairer's threshold (a straight column whose
    // clamp curvature is 1e-17), h0 = 0.01 d0/d1 is ~1e-19 and the first
    // step would count as an underflow; h1 still bounds the step.
    (100.0 * h0).max(1e-6 * span).min(h1).min(span)
}

/// The 12 stages of one step of size h from (s, y); the 8th-order result
/// goes to `next`. Stage 1 (k[0]) is f(s, y) from the previous step.
fn stages<K: StageVector, F: FnMut(f64, &K, &mut K)>(
    k: &mut [K; 12],
    stage: &mut K,
    next: &mut K,
    f: &mut F,
    s: f64,
    h: f64,
    y: &[f64],
) {
    for j in 1..12 {
        stage.as_mut().copy_from_slice(y);
        for (l, &a) in A[j][..j].iter().enumerate() {
            if a != 0.0 {
                axpy(stage.as_mut(), h * a, k[l].as_ref());
            }
        }
        let (_, rest) = k.split_at_mut(j);
        f(s + C[j] * h, stage, &mut rest[0]);
    }
    next.as_mut().copy_from_slice(y);
    for (l, &b) in B.iter().enumerate() {
        if b != 0.0 {
            axpy(next.as_mut(), h * b, k[l].as_ref());
        }
    }
}

/// Hairer's combined error norm of DOP853: the 5th-order estimate,
/// corrected by the 3rd-order one so that it behaves like an 8th-order
/// error (dop853.f, "error estimation").
#[allow(clippy::needless_range_loop)] // i indexes y, next and 12 stages
fn error_norm<K: StageVector>(
    k: &[K; 12],
    next: &K,
    h: f64,
    y: &[f64],
    controlled: usize,
    tol: &Tolerances,
) -> f64 {
    let k: [&[f64]; 12] = std::array::from_fn(|l| k[l].as_ref());
    let next = next.as_ref();
    let (mut err5, mut err3) = (0.0, 0.0);
    for i in 0..controlled {
        let sk = tol.atol + tol.rtol * y[i].abs().max(next[i].abs());
        // B and ER vanish at stages 2 to 5: summing over the others
        // alone is the same sum at two thirds of the cost.
        let (mut bsum, mut e5) = (B[0] * k[0][i], ER[0] * k[0][i]);
        for l in 5..12 {
            bsum += B[l] * k[l][i];
            e5 += ER[l] * k[l][i];
        }
        let e3 = bsum - BHH[0] * k[0][i] - BHH[1] * k[8][i] - BHH[2] * k[11][i];
        err3 += (e3 / sk).powi(2);
        err5 += (e5 / sk).powi(2);
    }
    let mut deno = err5 + 0.01 * err3;
    if deno <= 0.0 {
        deno = 1.0;
    }
    h.abs() * err5 * (1.0 / (controlled as f64 * deno)).sqrt()
}

/// Hairer's step size control, shared by [`Dop853`] and [`FixedDop853`]:
/// the next step from the last error norm (factor 0.9 err^(−1/8) within
/// [1/3, 6], not growing right after a rejection), the step budget, the
/// underflow test, and the work count.
struct StepControl {
    h: f64,
    rejected_last: bool,
    stats: IntegrationStats,
}

impl StepControl {
    /// After f(s0, y0) and the starting step's one evaluation.
    fn new(h: f64) -> Self {
        StepControl {
            h,
            rejected_last: false,
            stats: IntegrationStats {
                evaluations: 2,
                ..IntegrationStats::default()
            },
        }
    }

    /// The next step from s towards `target` and whether it lands there
    /// (a step within round-off of `target` is stretched onto it).
    fn propose(
        &self,
        s: f64,
        target: f64,
        tol: &Tolerances,
    ) -> Result<(f64, bool), IntegrationError> {
        if self.stats.accepted + self.stats.rejected >= tol.max_steps {
            return Err(IntegrationError::TooManySteps {
                s,
                steps: tol.max_steps,
            });
        }
        let lands = s + self.h >= target - 1e-14 * target.abs().max(1.0);
        let step = if lands { target - s } else { self.h };
        if step.abs() <= 10.0 * f64::EPSILON * s.abs().max(1.0) && !lands {
            return Err(IntegrationError::StepSizeUnderflow { s });
        }
        Ok((step, lands))
    }

    /// Counts the step's 11 evaluations, accepts it (true) or rejects it
    /// (false), and sets the next step size; an error norm that is not
    /// finite shrinks the step tenfold, down to a blow-up.
    fn judge(
        &mut self,
        err: f64,
        step: f64,
        lands: bool,
        s: f64,
        (s0, s1): (f64, f64),
    ) -> Result<bool, IntegrationError> {
        self.stats.evaluations += 11;
        if !err.is_finite() {
            if step < 1e-3 * (s1 - s0) * f64::EPSILON.sqrt() {
                return Err(IntegrationError::NotFinite { s });
            }
            self.h = step * 0.1;
            self.stats.rejected += 1;
            self.rejected_last = true;
            return Ok(false);
        }
        let factor = (0.9 * err.powf(-1.0 / 8.0)).clamp(0.333, 6.0);
        if err > 1.0 {
            self.stats.rejected += 1;
            self.h = step * factor.min(1.0);
            self.rejected_last = true;
            return Ok(false);
        }
        self.stats.accepted += 1;
        let grow = if self.rejected_last {
            factor.min(1.0)
        } else {
            factor
        };
        // A step shortened to land on a stop says nothing against h.
        self.h = if lands && step < self.h {
            self.h.max(step * grow)
        } else {
            step * grow
        };
        self.rejected_last = false;
        Ok(true)
    }
}

#[cfg(test)]
impl Dop853 {
    /// One step's stages from (s, y) with k[0] = f(s, y) set: [`stages`]
    /// on this integrator's storage.
    fn stages<F: FnMut(f64, &[f64], &mut [f64])>(&mut self, f: &mut F, s: f64, h: f64, y: &[f64]) {
        let mut f = |t, a: &Vec<f64>, b: &mut Vec<f64>| f(t, a, b);
        stages(
            &mut self.k,
            &mut self.stage,
            &mut self.next,
            &mut f,
            s,
            h,
            y,
        );
    }
}

/// How [`Dop853::integrate_serving`] serves the output points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stops {
    /// Steps land on every stop.
    Landed,
    /// Stops inside a step are read from the continuous extension.
    Interpolated,
    /// As [`Stops::Interpolated`], and every accepted step's continuous
    /// extension is kept ([`Dop853::take_record`]): the whole solution,
    /// readable at any later point without integrating again (three more
    /// evaluations on a step that holds no stop).
    Recorded,
}

impl Stops {
    /// Whether an accepted step holding `inside` stops builds its
    /// continuous extension.
    fn extends(self, inside: usize) -> bool {
        match self {
            Stops::Landed => false,
            Stops::Interpolated => inside > 0,
            Stops::Recorded => true,
        }
    }
}

/// y += a x.
fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y'' = −y: y(2π) = y(0) exactly, and the error shrinks with tolerance.
    #[test]
    fn harmonic_oscillator_period() {
        let mut dop = Dop853::new(2);
        for (tol, bound) in [(1e-6, 1e-4), (1e-10, 1e-8), (1e-13, 1e-11)] {
            let mut y = [1.0, 0.0];
            let t = Tolerances {
                rtol: tol,
                atol: tol,
                max_steps: 10_000,
            };
            let tau = std::f64::consts::TAU;
            let rhs = |_: f64, y: &[f64], d: &mut [f64]| {
                d[0] = y[1];
                d[1] = -y[0];
            };
            dop.integrate(rhs, 0.0, tau, &mut y, 2, &t, &[], |_, _| {}, |_| {})
                .unwrap();
            let err = ((y[0] - 1.0).powi(2) + y[1].powi(2)).sqrt();
            assert!(err < bound, "tol {tol}: error {err}");
        }
    }

    /// A single fixed step of size h on y' = y has error O(h⁹): halving h
    /// divides it by about 2⁹ (the method is of order 8).
    #[test]
    fn one_step_error_has_order_nine() {
        let mut dop = Dop853::new(1);
        let mut one_step = |h: f64| {
            let mut f = |_: f64, y: &[f64], d: &mut [f64]| d[0] = y[0];
            f(0.0, &[1.0], &mut dop.k[0]);
            dop.stages(&mut f, 0.0, h, &[1.0]);
            (dop.next[0] - h.exp()).abs()
        };
        let (e1, e2) = (one_step(0.4), one_step(0.2));
        let order = (e1 / e2).log2();
        assert!((order - 9.0).abs() < 0.5, "local order {order}");
    }

    #[test]
    fn stops_are_hit_exactly() {
        let mut dop = Dop853::new(1);
        let mut seen = vec![];
        let mut y = [0.0];
        dop.integrate(
            |_, _, d: &mut [f64]| d[0] = 1.0,
            0.0,
            1.0,
            &mut y,
            1,
            &Tolerances::default(),
            &[0.0, 0.25, 0.5, 1.0],
            |s, y| seen.push((s, y[0])),
            |_| {},
        )
        .unwrap();
        assert_eq!(seen.len(), 4);
        for (s, y) in seen {
            assert!((s - y).abs() < 1e-14);
        }
    }

    #[test]
    fn blow_up_is_reported() {
        let mut dop = Dop853::new(1);
        let mut y = [1.0];
        let r = dop.integrate(
            |_, y: &[f64], d: &mut [f64]| d[0] = y[0] * y[0],
            0.0,
            2.0,
            &mut y,
            1,
            &Tolerances::default(),
            &[],
            |_, _| {},
            |_| {},
        );
        assert!(r.is_err(), "y' = y² blows up at s = 1: {r:?}");
    }
}
