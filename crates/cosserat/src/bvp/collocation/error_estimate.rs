//! The local error estimate of every mesh interval, by step doubling.
//!
//! From the converged node state y_i, one collocation step of width h is
//! compared with two of width h/2; as the local error is O(h^{2m+1}), the
//! estimate is |y_h − y_{h/2}| / (1 − 2^{−2m}) (scaled). The stage
//! equations of each step are solved by a simplified Newton iteration
//! that reuses a factored stage matrix while it contracts fast. The
//! intervals whose estimate exceeds their share tol · h / L of the
//! tolerance are flagged for refinement.

use super::grid::{Grid, Scratch};
use super::iteration::Linearization;
use super::tableau::{interpolation_nodes, lagrange};

impl Grid<'_> {
    /// One collocation step of width h from y at s: its stage equations
    /// solved in `st` (holding the guess) by Newton, the end state into
    /// `out`; false if that fails. The stage matrix is factored at the
    /// guess and refreshed only while the iteration contracts slowly
    /// (Θ > 1/4); `frozen`, a factored stage matrix of this width at nearby
    /// stages, is used instead while it contracts fast. The iteration stops
    /// once the remainder is below round-off (see the test below), at the
    /// latest one correction after the first of at most 1e-13 (scaled).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn local_step(
        &self,
        s: f64,
        h: f64,
        y: &[f64],
        st: &mut [f64],
        out: &mut [f64],
        ws: &mut Scratch,
        frozen: Option<(&[f64], &[u8])>,
    ) -> bool {
        let (n, m) = (self.n, self.tab.m);
        let mut use_frozen = frozen.is_some();
        let (mut factored, mut refresh) = (false, !use_frozen);
        let (mut small, mut prev) = (false, f64::NAN);
        for _ in 0..30 {
            if refresh {
                self.stage_jacobians(s, h, st, &mut ws.f, &mut ws.jac);
                if !self
                    .split
                    .factor(&self.tab, h, &ws.jac, &mut ws.w, &mut ws.piv)
                {
                    return false;
                }
                (factored, use_frozen) = (true, false);
            } else {
                self.stage_rates(s, h, st, &mut ws.f);
            }
            for (r, (g, v)) in ws.g.iter_mut().zip(st.iter()).enumerate() {
                let (j, k) = (r / n, r % n);
                let acc: f64 = (0..m).map(|l| self.tab.a(j, l) * ws.f[l * n + k]).sum();
                *g = y[k] + h * acc - v;
            }
            let (lu, piv) = match frozen.filter(|_| use_frozen) {
                Some(f) => f,
                None => (&ws.w[..], &ws.piv[..]),
            };
            self.split
                .solve(&self.tab, h, lu, piv, &mut ws.g, &mut ws.z);
            st.iter_mut().zip(&ws.g).for_each(|(a, b)| *a += b);
            let size =
                ws.g.iter()
                    .enumerate()
                    .map(|(r, v)| (v * self.w[r % n]).abs())
                    .fold(0.0, f64::max);
            if !size.is_finite() {
                return false;
            }
            let theta = size / prev;
            // Converged: after the correction following one of at most
            // 1e-13 (the rule of a plain Newton iteration), or as soon as
            // the remainder is below round-off: Θ·‖δ‖ ≤ 1e-17 with a reliable
            // Θ ≤ 1/4, or ‖δ‖ ≤ 1e-15 at the first correction of a matrix
            // factored at (nearly) these stages.
            if small || size <= 1e-15 || (theta <= 0.25 && theta * size <= 1e-17) {
                break;
            }
            small = size <= 1e-13;
            // Slow contraction: refactor at the current stages.
            // (Θ is NaN after the first correction: refresh then only if
            // nothing is factored yet.)
            let slow = theta.is_nan() || theta > 0.25;
            refresh = slow && !(prev.is_nan() && (factored || use_frozen));
            prev = size;
        }
        self.stage_rates(s, h, st, &mut ws.f);
        for k in 0..n {
            out[k] = y[k] + h * (0..m).map(|j| self.tab.b[j] * ws.f[j * n + k]).sum::<f64>();
        }
        true
    }

    /// Local error of every interval by step doubling from the converged
    /// node state: one step of width h against two of h/2, the difference
    /// scaled by 1/(1 − 2^{−2m}) (the local error is O(h^{2m+1})). The
    /// full step starts from the converged stages (with `lin`'s factored
    /// stage matrices when given), the half steps from the collocation
    /// polynomial.
    pub(super) fn local_errors(&self, x: &[f64], lin: Option<&Linearization>) -> Vec<f64> {
        let (n, m, p) = (self.n, self.tab.m, self.p);
        let mn = m * n;
        let (len, rows) = (self.split.len(), self.split.coupled_rows());
        let factor = 1.0 / (1.0 - 0.5f64.powi(2 * m as i32));
        let lin = lin.filter(|l| l.valid);
        // Lagrange weights on the nodes (0, c_1 … c_m) at the stage points of
        // the two half steps, t = c_j / 2 and 1/2 + c_j / 2.
        let (nodes, _) = interpolation_nodes(m);
        let nodes = &nodes[..=m];
        let weights: Vec<f64> = [0.0, 0.5]
            .iter()
            .flat_map(|&a| {
                self.tab
                    .c
                    .iter()
                    .flat_map(move |&c| (0..=m).map(move |q| lagrange(nodes, q, a + 0.5 * c)))
            })
            .collect();
        let guess = |half: usize, y: &[f64], stv: &[f64], g: &mut [f64]| {
            for j in 0..m {
                let wj = &weights[(half * m + j) * (m + 1)..(half * m + j + 1) * (m + 1)];
                for k in 0..n {
                    let mut acc = wj[0] * y[k];
                    for q in 1..=m {
                        acc += wj[q] * stv[(q - 1) * n + k];
                    }
                    g[j * n + k] = acc;
                }
            }
        };
        let mut ws = Scratch::new(self);
        let mut y0 = vec![0.0; n];
        self.eq.initial_state(&x[..p], &mut y0);
        let (mut st, mut a, mut mid, mut b) =
            (vec![0.0; mn], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        (0..self.intervals())
            .map(|i| {
                let (s, h) = self.span(i);
                let y = self.node_ref(x, &y0, i);
                let stv = self.stages(x, i);
                st.copy_from_slice(stv);
                let frozen = lin.map(|l| {
                    (
                        &l.lu[i * len..(i + 1) * len],
                        &l.piv[i * rows..(i + 1) * rows],
                    )
                });
                let full = self.local_step(s, h, y, &mut st, &mut a, &mut ws, frozen);
                guess(0, y, stv, &mut st);
                let mut half = self.local_step(s, 0.5 * h, y, &mut st, &mut mid, &mut ws, None);
                if half {
                    guess(1, y, stv, &mut st);
                    half =
                        self.local_step(s + 0.5 * h, 0.5 * h, &mid, &mut st, &mut b, &mut ws, None);
                }
                if full && half {
                    factor
                        * (0..n)
                            .map(|k| ((a[k] - b[k]) * self.w[k]).abs())
                            .fold(0.0, f64::max)
                } else {
                    f64::INFINITY
                }
            })
            .collect()
    }

    /// Intervals whose estimate exceeds their share tolerance · h / L.
    pub(super) fn flagged(&self, errors: &[f64], tolerance: f64) -> Vec<usize> {
        let l = self.eq.length();
        errors
            .iter()
            .enumerate()
            .filter(|&(i, &e)| e.is_nan() || e > tolerance * self.span(i).1 / l)
            .map(|(i, _)| i)
            .collect()
    }
}
