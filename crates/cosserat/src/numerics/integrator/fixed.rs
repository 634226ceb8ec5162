//! DOP853 on a state of a size known at compile time: the same stages,
//! error norm and step control as [`Dop853`](super::Dop853) (the shared
//! functions of the parent module, monomorphized on arrays), so that the
//! loops over the N components unroll and vectorize and the stage storage
//! lives in the struct instead of on the heap. No stops, no projection,
//! no continuous extension: what shooting's Newton iterations integrate
//! (the planar state with its sensitivity column, N = 8).

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

#[cfg(test)]
mod tests {
    use super::super::Dop853;
    use super::*;

    /// The pendulum with its variational equation (4 components): the
    /// fixed-size integrator takes the generic one's steps and lands on
    /// its result bit for bit, at a loose and a tight tolerance.
    #[test]
    fn the_same_steps_and_result_as_the_generic_integrator() {
        let rhs = |_: f64, y: &[f64], d: &mut [f64]| {
            let (sin, cos) = y[0].sin_cos();
            d[0] = y[1];
            d[1] = -sin;
            d[2] = y[3];
            d[3] = -cos * y[2];
        };
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
}
