//! DOP853 on a state of a size known at compile time: the same stages,
//! error norm and step control as [`Dop853`](super::Dop853) (the shared
//! functions of the parent module, monomorphized on arrays), so that the
//! loops over the N components unroll and vectorize and the stage storage
//! lives in the struct instead of on the heap. No projection: what
//! shooting's Newton iterations integrate (the planar state with its
//! sensitivity column, N = 8, no stops) and what its sampling integrates
//! (the planar state, N = 4, every step's continuous extension recorded:
//! [`FixedRecorder::integrate_recorded`]).

use super::dense::{extension, interpolate, DenseRecord};
use super::{
    error_norm, initial_step, stages, IntegrationError, IntegrationStats, StepControl, Tolerances,
};

/// A DOP853 integrator of an N-component system, every component under
/// step size control.
#[derive(Debug, Clone)]
pub struct FixedDop853<const N: usize> {
    k: [[f64; N]; 12],
    stage: [f64; N],
    next: [f64; N],
}

impl<const N: usize> Default for FixedDop853<N> {
    fn default() -> Self {
        FixedDop853 {
            k: [[0.0; N]; 12],
            stage: [0.0; N],
            next: [0.0; N],
        }
    }
}

/// A [`FixedDop853`] with room for DOP853's continuous extension
/// (`integrator/dense.rs`): what a recorded integration needs, kept apart
/// so that the Newton iterations' integrator does not carry (and zero)
/// it.
#[derive(Debug, Clone)]
pub struct FixedRecorder<const N: usize> {
    dop: FixedDop853<N>,
    /// The last step's start, stages 13..16, coefficients F₀ … F₆, and a
    /// state read from them.
    y_old: [f64; N],
    late: [[f64; N]; 4],
    coefficients: [[f64; N]; 7],
    value: [f64; N],
}

impl<const N: usize> Default for FixedRecorder<N> {
    fn default() -> Self {
        FixedRecorder {
            dop: FixedDop853::default(),
            y_old: [0.0; N],
            late: [[0.0; N]; 4],
            coefficients: [[0.0; N]; 7],
            value: [0.0; N],
        }
    }
}

impl<const N: usize> FixedDop853<N> {
    /// Integrates y' = f(s, y) from `s0` to `s1` (s1 > s0) in place, the
    /// step sequence and result those of [`Dop853::integrate`](super::Dop853::integrate)
    /// with all N components controlled, no stops and no projection, bit
    /// for bit.
    pub fn integrate<F>(
        &mut self,
        mut f: F,
        s0: f64,
        s1: f64,
        y: &mut [f64; N],
        tol: &Tolerances,
    ) -> Result<IntegrationStats, IntegrationError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        let mut s = s0;
        f(s, y, &mut self.k[0]);
        let h = initial_step(&mut self.k, &mut self.stage, &mut f, s, s1, y, N, tol);
        let mut control = StepControl::new(h);
        while s < s1 {
            let (step, lands) = control.propose(s, s1, tol)?;
            stages(
                &mut self.k,
                &mut self.stage,
                &mut self.next,
                &mut f,
                s,
                step,
                y,
            );
            let err = error_norm(&self.k, &self.next, step, y, N, tol);
            if !control.judge(err, step, lands, s, (s0, s1))? {
                continue;
            }
            s = if lands { s1 } else { s + step };
            *y = self.next;
            if y.iter().any(|v| !v.is_finite()) {
                return Err(IntegrationError::NotFinite { s });
            }
            f(s, y, &mut self.k[0]);
            control.stats.evaluations += 1;
        }
        Ok(control.stats)
    }
}

impl<const N: usize> FixedRecorder<N> {
    /// Integrates y' = f(s, y) over `span` = (s0, s1) in place as
    /// [`Dop853::integrate_serving`](super::Dop853::integrate_serving)
    /// with [`Stops::Recorded`](super::Stops::Recorded), all N components
    /// controlled and no projection: every accepted step's continuous
    /// extension appended to `record`, the state at each of `stops`
    /// (sorted, in [s0, s1]) passed to `observe` — the same steps, states,
    /// samples and record, bit for bit.
    #[allow(clippy::too_many_arguments)] // integrate_serving's, less the projection
    pub fn integrate_recorded<F, O>(
        &mut self,
        mut f: F,
        (s0, s1): (f64, f64),
        y: &mut [f64; N],
        tol: &Tolerances,
        stops: &[f64],
        mut observe: O,
        record: &mut DenseRecord,
    ) -> Result<IntegrationStats, IntegrationError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        O: FnMut(f64, &[f64]),
    {
        let mut s = s0;
        let mut next_stop = stops.partition_point(|&t| t < s0);
        while next_stop < stops.len() && stops[next_stop] <= s0 {
            observe(s0, y);
            next_stop += 1;
        }
        f(s, y, &mut self.dop.k[0]);
        let h = initial_step(
            &mut self.dop.k,
            &mut self.dop.stage,
            &mut f,
            s,
            s1,
            y,
            N,
            tol,
        );
        let mut control = StepControl::new(h);
        while s < s1 {
            let (step, lands) = control.propose(s, s1, tol)?;
            stages(
                &mut self.dop.k,
                &mut self.dop.stage,
                &mut self.dop.next,
                &mut f,
                s,
                step,
                y,
            );
            let err = error_norm(&self.dop.k, &self.dop.next, step, y, N, tol);
            if !control.judge(err, step, lands, s, (s0, s1))? {
                continue;
            }
            let start = s;
            s = if lands { s1 } else { s + step };
            let inside = stops[next_stop..].partition_point(|&t| t <= s);
            self.y_old = *y;
            *y = self.dop.next;
            if y.iter().any(|v| !v.is_finite()) {
                return Err(IntegrationError::NotFinite { s });
            }
            self.extend(&mut f, start, step, y);
            control.stats.evaluations += 4;
            record.push(start, step, &self.y_old, &self.coefficients);
            for &t in &stops[next_stop..next_stop + inside] {
                // The step's end is the state itself, as when landed.
                if t == s {
                    observe(t, y);
                } else {
                    let theta = (t - start) / step;
                    interpolate(&self.coefficients, &self.y_old, theta, &mut self.value);
                    observe(t, &self.value);
                }
            }
            // f(s, y) is the extension's first extra stage.
            self.dop.k[0] = self.late[0];
            next_stop += inside;
            if lands && next_stop < stops.len() && s1 == stops[next_stop] {
                observe(s, y);
                next_stop += 1;
            }
        }
        Ok(control.stats)
    }

    /// The continuous extension of the step of size h from s (its start in
    /// `y_old`, its stages in `k`) to `y_new`: f(s + h, y_new) and the
    /// shared [`extension`].
    fn extend<F>(&mut self, f: &mut F, s: f64, h: f64, y_new: &[f64; N])
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        f(s + h, y_new, &mut self.late[0]);
        extension(
            &self.dop.k,
            &mut self.dop.stage,
            &mut self.late,
            &mut self.coefficients,
            f,
            (s, h),
            &self.y_old,
            y_new,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::super::Dop853;
    use super::*;

    /// θ'' = −sin θ as (θ, ω) with its variational equation (δθ, δω).
    fn pendulum(_: f64, y: &[f64], d: &mut [f64]) {
        let (sin, cos) = y[0].sin_cos();
        d[0] = y[1];
        d[1] = -sin;
        d[2] = y[3];
        d[3] = -cos * y[2];
    }

    /// The pendulum with its variational equation (4 components): the
    /// fixed-size integrator takes the generic one's steps and lands on
    /// its result bit for bit, at a loose and a tight tolerance.
    #[test]
    fn the_same_steps_and_result_as_the_generic_integrator() {
        let rhs = pendulum;
        for rtol in [1e-4, 1e-12] {
            let tol = Tolerances {
                rtol,
                atol: rtol,
                max_steps: 10_000,
            };
            let start = [2.0, 0.0, 1.0, 0.0];
            let mut generic = start;
            let slow = Dop853::new(4)
                .integrate(rhs, 0.0, 7.3, &mut generic, 4, &tol, &[], |_, _| {}, |_| {})
                .unwrap();
            let mut fixed = start;
            let fast = FixedDop853::<4>::default()
                .integrate(|s, y, d| rhs(s, y, d), 0.0, 7.3, &mut fixed, &tol)
                .unwrap();
            assert_eq!(slow, fast, "rtol {rtol}");
            assert_eq!(generic, fixed, "rtol {rtol}");
        }
    }

    /// The pendulum recorded with stops inside steps, on step ends and at
    /// both ends: the fixed-size integrator serves the generic one's
    /// states and records its extensions bit for bit, with the same work.
    #[test]
    fn the_same_record_and_samples_as_the_generic_integrator() {
        let rhs = pendulum;
        let stops: Vec<f64> = (0..=40).map(|i| 7.3 * f64::from(i) / 40.0).collect();
        for rtol in [1e-4, 1e-12] {
            let tol = Tolerances {
                rtol,
                atol: rtol,
                max_steps: 10_000,
            };
            let start = [2.0, 0.0, 1.0, 0.0];
            let (mut generic, mut slow_seen) = (start, vec![]);
            let mut dop = Dop853::new(4);
            let slow = dop
                .integrate_serving(
                    rhs,
                    (0.0, 7.3, 4),
                    &mut generic,
                    &tol,
                    &stops,
                    super::super::Stops::Recorded,
                    |s, y| slow_seen.push((s, y.to_vec())),
                    |_| {},
                )
                .unwrap();
            let (mut fixed, mut fast_seen) = (start, vec![]);
            let mut record = DenseRecord::new(4);
            let fast = FixedRecorder::<4>::default()
                .integrate_recorded(
                    |s, y, d| rhs(s, y, d),
                    (0.0, 7.3),
                    &mut fixed,
                    &tol,
                    &stops,
                    |s, y| fast_seen.push((s, y.to_vec())),
                    &mut record,
                )
                .unwrap();
            assert_eq!(slow, fast, "rtol {rtol}");
            assert_eq!(generic, fixed, "rtol {rtol}");
            assert_eq!(slow_seen, fast_seen, "rtol {rtol}");
            assert_eq!(slow_seen.len(), stops.len());
            assert_eq!(dop.take_record(), record, "rtol {rtol}");
        }
    }
}
