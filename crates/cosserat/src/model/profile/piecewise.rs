//! Piecewise polynomials: profiles smooth between breakpoints and kinked at
//! them — the stiffness b A(s)² of a section A piecewise linear between
//! knots (quadratic on each piece, exactly), and the intrinsic curvature
//! that makes a fixed shape an equilibrium of such a rod (smooth on each
//! piece, interpolated there to rounding).
//!
//! Each piece is a Chebyshev series Σ c_j T_j(t) in the local variable
//! t = (2s − s_k − s_{k+1})/(s_{k+1} − s_k) ∈ [−1, 1], evaluated by
//! Clenshaw's recurrence (stable for any degree; Trefethen, *Approximation
//! Theory and Approximation Practice*, 2013, Ch. 3). A natural spline
//! through many samples of such a function is C² across the kinks and
//! rings there, and its third derivative jumps at every sample: an
//! adaptive integrator then misjudges its error at each of them (the
//! tapered arm's loading path stalled at a scaled residual of 10⁻⁸ that
//! way, docs/extensions.md). A piecewise profile instead hands its
//! breakpoints to the solvers ([`super::Profile::breaks`]), which stop
//! there as at a point force, and is smooth in between.

use super::polynomial::{polynomial_extremes, Extremes};
use crate::model::ModelError;

/// The breakpoints and the Chebyshev coefficients of each piece, checked
/// by [`Pieces::new`]: at least two breakpoints, strictly increasing, one
/// non-empty coefficient list per interval between them.
#[derive(Debug, Clone, PartialEq)]
pub struct Pieces {
    breaks: Vec<f64>,
    coefficients: Vec<Vec<f64>>,
    /// The coefficients of d/dt of each piece (Chebyshev series too).
    slopes: Vec<Vec<f64>>,
}

impl Pieces {
    /// The piecewise polynomial with `coefficients[k]` (Chebyshev, in the
    /// local t of [s_k, s_{k+1}]) on each interval of `breaks`; refused
    /// with [`ModelError::Profile`] unless there are at least two
    /// breakpoints, strictly increasing, and one non-empty list per
    /// interval.
    pub fn new(breaks: Vec<f64>, coefficients: Vec<Vec<f64>>) -> Result<Pieces, ModelError> {
        if breaks.len() < 2 || coefficients.len() + 1 != breaks.len() {
            return Err(ModelError::Profile(format!(
                "a piecewise profile needs at least two breakpoints and one piece between each \
                 two ({} breakpoints, {} pieces)",
                breaks.len(),
                coefficients.len()
            )));
        }
        if !breaks.windows(2).all(|w| w[1] > w[0]) {
            return Err(ModelError::Profile(
                "the breakpoints must be strictly increasing".into(),
            ));
        }
        if coefficients.iter().any(Vec::is_empty) {
            return Err(ModelError::Profile(
                "every piece needs at least one coefficient".into(),
            ));
        }
        let slopes = coefficients.iter().map(|c| chebyshev_slope(c)).collect();
        Ok(Pieces {
            breaks,
            coefficients,
            slopes,
        })
    }

    /// The breakpoints s_0 < … < s_K.
    pub fn breaks(&self) -> &[f64] {
        &self.breaks
    }

    /// The Chebyshev coefficients of each piece.
    pub fn coefficients(&self) -> &[Vec<f64>] {
        &self.coefficients
    }

    /// The piece k holding s (the right one at a breakpoint, the first or
    /// last outside) and the local t of s there, clamped to [−1, 1].
    fn locate(&self, s: f64) -> (usize, f64) {
        let (k, fraction) = super::locate(&self.breaks, s);
        (k, 2.0 * fraction - 1.0)
    }

    /// The value at s; held constant outside [s_0, s_K].
    pub fn value(&self, s: f64) -> f64 {
        let (k, t) = self.locate(s);
        clenshaw(&self.coefficients[k], t)
    }

    /// The derivative d/ds at s: the right piece's at a breakpoint, zero
    /// outside [s_0, s_K].
    pub fn derivative(&self, s: f64) -> f64 {
        let n = self.breaks.len();
        if s < self.breaks[0] || s > self.breaks[n - 1] {
            return 0.0;
        }
        let (k, t) = self.locate(s);
        let h = self.breaks[k + 1] - self.breaks[k];
        2.0 / h * clenshaw(&self.slopes[k], t)
    }

    /// The same breakpoints with every coefficient mapped by `f`.
    pub(super) fn map(&self, f: impl Fn(f64) -> f64) -> Pieces {
        let coefficients: Vec<Vec<f64>> = self
            .coefficients
            .iter()
            .map(|c| c.iter().map(|v| f(*v)).collect())
            .collect();
        let slopes = coefficients.iter().map(|c| chebyshev_slope(c)).collect();
        Pieces {
            breaks: self.breaks.clone(),
            coefficients,
            slopes,
        }
    }

    /// (1 − p) self + p other on the same breakpoints (None otherwise);
    /// shorter series padded with zeros.
    pub(super) fn blend(&self, other: &Pieces, p: f64) -> Option<Pieces> {
        if self.breaks != other.breaks {
            return None;
        }
        let coefficients: Vec<Vec<f64>> = self
            .coefficients
            .iter()
            .zip(&other.coefficients)
            .map(|(a, b)| {
                (0..a.len().max(b.len()))
                    .map(|j| {
                        let (x, y) = (
                            a.get(j).copied().unwrap_or(0.0),
                            b.get(j).copied().unwrap_or(0.0),
                        );
                        (1.0 - p) * x + p * y
                    })
                    .collect()
            })
            .collect();
        Pieces::new(self.breaks.clone(), coefficients).ok()
    }

    /// Every coefficient is zero.
    pub(super) fn is_zero(&self) -> bool {
        self.coefficients.iter().flatten().all(|v| *v == 0.0)
    }

    /// Every breakpoint and coefficient is finite.
    pub(super) fn is_finite(&self) -> bool {
        self.breaks
            .iter()
            .chain(self.coefficients.iter().flatten())
            .all(|v| v.is_finite())
    }

    /// The extremes on [0, length]: each piece's (held constant outside
    /// [s_0, s_K]) by [`polynomial_extremes`] of its power form in t,
    /// widened by the rounding bound of the conversion from the Chebyshev
    /// form (module doc).
    pub(super) fn extremes_on(&self, length: f64) -> Extremes {
        let mut e = Extremes::at(self.value(0.0), 0.0, 0.0);
        e.include(self.value(length), length, 0.0);
        for (k, c) in self.coefficients.iter().enumerate() {
            let (sa, sb) = (self.breaks[k], self.breaks[k + 1]);
            let (a, b) = (sa.max(0.0), sb.min(length));
            if a > b {
                continue;
            }
            let h = sb - sa;
            let local = |s: f64| ((2.0 * s - sa - sb) / h).clamp(-1.0, 1.0);
            let (power, slack) = power_form(c);
            let mut piece = polynomial_extremes(&power, local(a), local(b));
            piece.min_lower -= slack;
            piece.max_upper += slack;
            e.merge(&piece, |t| 0.5 * (sa + sb + t * h));
        }
        e
    }

    /// The interior breakpoints (those strictly inside (s_0, s_K)).
    pub(super) fn interior_breaks(&self) -> &[f64] {
        &self.breaks[1..self.breaks.len() - 1]
    }
}

/// Σ c_j T_j(t) by Clenshaw's recurrence.
fn clenshaw(c: &[f64], t: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &cj in c.iter().skip(1).rev() {
        let b0 = 2.0 * t * b1 - b2 + cj;
        b2 = b1;
        b1 = b0;
    }
    t * b1 - b2 + c[0]
}

/// The Chebyshev coefficients of d/dt Σ c_j T_j: c'_{j−1} = c'_{j+1} +
/// 2j c_j from the top, c'_0 halved (Mason & Handscomb, *Chebyshev
/// Polynomials*, 2003, eq. (2.49)); [0] for a constant.
fn chebyshev_slope(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    if n < 2 {
        return vec![0.0];
    }
    let mut d = vec![0.0; n + 1];
    for j in (1..n).rev() {
        d[j - 1] = d[j + 1] + 2.0 * j as f64 * c[j];
    }
    d[0] *= 0.5;
    d.truncate(n - 1);
    d
}

/// The power form Σ a_k t^k of Σ c_j T_j(t), with a bound of its rounding
/// error on [−1, 1]: T_j's power coefficients are integers of absolute
/// sum |T_j(i)| ≤ (1 + √2)^j, so the conversion errs by at most
/// γ_n Σ_j |c_j| (1 + √2)^j there (Higham, *Accuracy and Stability*,
/// Sec. 3.1).
fn power_form(c: &[f64]) -> (Vec<f64>, f64) {
    let n = c.len();
    let mut power = vec![0.0; n];
    let (mut previous, mut current) = (vec![1.0], vec![0.0, 1.0]);
    let mut bound = 0.0;
    let growth = 1.0 + std::f64::consts::SQRT_2;
    for (j, cj) in c.iter().enumerate() {
        let t = if j == 0 { &previous } else { &current };
        for (a, v) in power.iter_mut().zip(t) {
            *a += cj * v;
        }
        bound += cj.abs() * growth.powi(j as i32);
        if j >= 1 {
            // T_{j+1} = 2t T_j − T_{j−1}.
            let mut next = vec![0.0; current.len() + 1];
            for (i, v) in current.iter().enumerate() {
                next[i + 1] += 2.0 * v;
            }
            for (i, v) in previous.iter().enumerate() {
                next[i] -= v;
            }
            previous = std::mem::replace(&mut current, next);
        }
    }
    let gamma = 2.0 * n as f64 * f64::EPSILON;
    (power, gamma / (1.0 - gamma) * bound)
}

/// A function sampled at sorted points of one piece, or why not.
pub type Sampler<'a> = dyn FnMut(&[f64]) -> Result<Vec<f64>, ModelError> + 'a;

/// Degrees tried per piece by [`interpolate`], doubling.
const DEGREES: [usize; 5] = [8, 16, 32, 64, 128];

/// The piecewise interpolant of a function smooth on each interval of
/// `breaks`: on each piece, Chebyshev interpolation at the n + 1 points
/// cos(πi/n) (of the second kind) with n doubled from 8 until the last
/// three coefficients fall below the bound `tolerance` × max(`scale`, the
/// piece's largest |value|), then checked at the n midpoints
/// cos(π(i + ½)/n), where it must meet 10 × that bound (Trefethen 2013,
/// Ch. 3 and 8: the coefficients of a function analytic near the piece
/// fall geometrically, and the tail bounds the error; `scale` keeps a
/// piece where the function is nearly zero from chasing its round-off).
/// `f` gives the values at sorted points of one piece. Refused when a
/// piece needs more than degree 128 (a function not smooth there) or `f`
/// fails.
pub fn interpolate(
    breaks: Vec<f64>,
    f: &mut Sampler<'_>,
    (tolerance, scale): (f64, f64),
) -> Result<Pieces, ModelError> {
    if breaks.len() < 2 {
        return Pieces::new(breaks, vec![]);
    }
    let mut coefficients = Vec::with_capacity(breaks.len() - 1);
    for w in breaks.windows(2) {
        coefficients.push(interpolate_piece((w[0], w[1]), f, (tolerance, scale))?);
    }
    Pieces::new(breaks, coefficients)
}

/// The Chebyshev coefficients of one piece ([`interpolate`]).
fn interpolate_piece(
    (a, b): (f64, f64),
    f: &mut Sampler<'_>,
    (tolerance, floor): (f64, f64),
) -> Result<Vec<f64>, ModelError> {
    let at = |t: f64| 0.5 * (a + b + t * (b - a));
    let mut worst = f64::NAN;
    for n in DEGREES {
        // Sorted in s: t from −1 to 1.
        let t: Vec<f64> = (0..=n)
            .map(|i| -(std::f64::consts::PI * i as f64 / n as f64).cos())
            .collect();
        let s: Vec<f64> = t.iter().map(|t| at(*t)).collect();
        let values = f(&s)?;
        let c = chebyshev_coefficients(&values);
        let scale = values
            .iter()
            .fold(floor, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        let bound = tolerance * scale;
        if c[n - 2..].iter().any(|v| v.abs() > bound) {
            worst = c[n - 2..].iter().fold(0.0f64, |m, v| m.max(v.abs())) / scale;
            continue;
        }
        let mid: Vec<f64> = (0..n)
            .map(|i| -(std::f64::consts::PI * (i as f64 + 0.5) / n as f64).cos())
            .collect();
        let check = f(&mid.iter().map(|t| at(*t)).collect::<Vec<_>>())?;
        worst = mid
            .iter()
            .zip(&check)
            .map(|(t, v)| (clenshaw(&c, *t) - v).abs())
            .fold(0.0, f64::max)
            / scale;
        if worst <= 10.0 * tolerance {
            return Ok(c);
        }
    }
    Err(ModelError::Profile(format!(
        "the function is not smooth enough on [{a}, {b}] for a piecewise profile: its \
         interpolant of degree {} errs by {worst:.1e} (relative), above {tolerance:.1e}",
        DEGREES[DEGREES.len() - 1]
    )))
}

/// The Chebyshev coefficients of the interpolant through `values` at
/// t_i = −cos(πi/n), i = 0..n (a discrete cosine transform of type I,
/// O(n²) directly: n ≤ 128).
fn chebyshev_coefficients(values: &[f64]) -> Vec<f64> {
    let n = values.len() - 1;
    let nf = n as f64;
    (0..=n)
        .map(|j| {
            let sum: f64 = values
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                    // T_j(−cos θ) = (−1)^j cos(jθ).
                    let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
                    w * v * sign * (std::f64::consts::PI * (j * i) as f64 / nf).cos()
                })
                .sum();
            let w = if j == 0 || j == n { 1.0 } else { 2.0 };
            w * sum / nf
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A piecewise quadratic with a kink: values, one-sided derivatives
    /// (the right piece's at the breakpoint) and the extremes exactly.
    #[test]
    fn quadratic_pieces_are_exact() {
        // On [0, 1]: (s − 0.2)² in power form; t = 2s − 1 ⇒ s = (t + 1)/2.
        // (s − 0.2)² = ((t + 0.6)/2)² = (t² + 1.2t + 0.36)/4
        //            = (0.5 T2 + 0.5 + 1.2 T1 + 0.36)/4.
        let left = vec![(0.5 + 0.36) / 4.0, 0.3, 0.125];
        // On [1, 3]: the constant 0.64.
        let p = Pieces::new(vec![0.0, 1.0, 3.0], vec![left, vec![0.64]]).unwrap();
        for s in [0.0, 0.1, 0.2, 0.55, 0.999] {
            let exact: f64 = (s - 0.2) * (s - 0.2);
            assert!((p.value(s) - exact).abs() < 1e-15, "{s}");
            assert!((p.derivative(s) - 2.0 * (s - 0.2)).abs() < 1e-14, "{s}");
        }
        assert_eq!(p.derivative(1.0), 0.0, "the right piece's slope");
        assert_eq!(p.value(2.0), 0.64);
        assert_eq!(p.value(5.0), 0.64, "held outside");
        let e = p.extremes_on(3.0);
        assert!(
            e.min.abs() < 1e-15 && (e.argmin - 0.2).abs() < 1e-7,
            "{e:?}"
        );
        assert!((e.max - 0.64).abs() < 1e-15 && e.min_lower <= 0.0);
        assert_eq!(p.interior_breaks(), &[1.0]);
    }

    /// Interpolating a function with a pole near its piece: the error
    /// meets the tolerance at 10⁴ points, and the derivative of the
    /// interpolant matches the function's.
    #[test]
    fn interpolant_meets_its_tolerance() {
        let g = |s: f64| 1.0 / (1.1 - s).powi(2);
        let dg = |s: f64| 2.0 / (1.1 - s).powi(3);
        let p = interpolate(
            vec![0.0, 0.5, 1.0],
            &mut |s| Ok(s.iter().map(|s| g(*s)).collect()),
            (1e-14, 0.0),
        )
        .unwrap();
        for i in 0..=10_000 {
            let s = f64::from(i) / 10_000.0;
            assert!((p.value(s) - g(s)).abs() <= 1e-12 * g(s), "{s}");
            assert!((p.derivative(s) - dg(s)).abs() <= 1e-9 * dg(s), "{s}");
        }
        let kinked = interpolate(
            vec![0.0, 1.0],
            &mut |s| Ok(s.iter().map(|s| (s - 0.37).abs()).collect()),
            (1e-14, 0.0),
        );
        assert!(kinked.is_err(), "a kink inside a piece is refused");
    }
}
