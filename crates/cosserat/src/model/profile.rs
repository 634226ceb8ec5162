//! Functions of the reference arc length s: stiffness and intrinsic-curvature
//! profiles of non-prismatic or pre-curved rods.
//!
//! A profile is a constant, a polynomial in s (coefficients in increasing
//! powers, s in the same length unit as the rod), or a piecewise-linear table.
//! Energies need the value and its s-derivative: the body moment
//! M = ∇W(s, κ) depends on s explicitly, so M' = H κ' + ∂s∇W and the
//! equations solve κ' = H⁻¹(M' − ∂s∇W) with H = ∂²W/∂κ² (Antman,
//! *Nonlinear Problems of Elasticity*, 2nd ed., Ch. 8).

use super::ModelError;

/// A scalar function of the arc length s.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// The same value everywhere.
    Constant(f64),
    /// Σ c_k s^k, coefficients in increasing powers.
    Polynomial(Vec<f64>),
    /// Piecewise-linear interpolation of (s_k, v_k), held constant outside
    /// the table; build with [`Profile::table`].
    Table(Knots),
    /// The natural cubic spline through (s_k, v_k) (C², so that equations
    /// using the derivative stay continuous); build with [`Profile::spline`].
    Spline(SplineKnots),
}

/// The points (s_k, v_k) of a table or spline: at least two, as many
/// values as knots, s strictly increasing (the interpolation divides by
/// s_{k+1} − s_k and looks knots up by bisection). Checked by
/// [`Knots::new`]; read through [`Knots::s`] and [`Knots::values`].
#[derive(Debug, Clone, PartialEq)]
pub struct Knots {
    s: Vec<f64>,
    values: Vec<f64>,
}

impl Knots {
    /// The points (s_k, v_k); refused with [`ModelError::Profile`] when
    /// there are fewer than two, the lengths differ, or s is not strictly
    /// increasing (a NaN knot is not).
    pub fn new(s: Vec<f64>, values: Vec<f64>) -> Result<Knots, ModelError> {
        if s.len() < 2 || s.len() != values.len() {
            return Err(ModelError::Profile(format!(
                "a table or spline needs at least two knots and as many values ({} s, {} values)",
                s.len(),
                values.len()
            )));
        }
        if !s.windows(2).all(|w| w[1] > w[0]) {
            return Err(ModelError::Profile(
                "the knots s must be strictly increasing".into(),
            ));
        }
        Ok(Knots { s, values })
    }

    /// The knots s_k, strictly increasing.
    pub fn s(&self) -> &[f64] {
        &self.s
    }

    /// The values v_k at the knots.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The same knots with other values (as many): the invariant is the
    /// knots', so it holds.
    fn with_values(&self, values: Vec<f64>) -> Knots {
        debug_assert_eq!(values.len(), self.s.len());
        Knots {
            s: self.s.clone(),
            values,
        }
    }
}

/// A natural cubic spline: its [`Knots`] and the second derivatives there,
/// computed by [`Profile::spline`] (so that they always belong to the
/// knots).
#[derive(Debug, Clone, PartialEq)]
pub struct SplineKnots {
    knots: Knots,
    curvature: Vec<f64>,
}

impl SplineKnots {
    /// The knots and values.
    pub fn knots(&self) -> &Knots {
        &self.knots
    }

    /// The second derivatives at the knots.
    pub fn curvature(&self) -> &[f64] {
        &self.curvature
    }
}

impl Default for Profile {
    fn default() -> Self {
        Profile::Constant(0.0)
    }
}

impl Profile {
    /// The piecewise-linear table through (s_k, v_k); refused as in
    /// [`Knots::new`].
    pub fn table(s: Vec<f64>, values: Vec<f64>) -> Result<Profile, ModelError> {
        Ok(Profile::Table(Knots::new(s, values)?))
    }

    /// The natural cubic spline through (s_k, v_k), s strictly increasing,
    /// at least two knots (refused as in [`Knots::new`]; second derivatives
    /// from the tridiagonal system with zero end curvature; de Boor, *A
    /// Practical Guide to Splines*, ch. IV).
    pub fn spline(s: Vec<f64>, values: Vec<f64>) -> Result<Profile, ModelError> {
        let knots = Knots::new(s, values)?;
        let (s, values) = (&knots.s, &knots.values);
        let n = s.len();
        let mut curvature = vec![0.0; n];
        if n > 2 {
            let (mut diag, mut rhs) = (vec![0.0; n], vec![0.0; n]);
            for i in 1..n - 1 {
                let (h0, h1) = (s[i] - s[i - 1], s[i + 1] - s[i]);
                diag[i] = (h0 + h1) / 3.0;
                rhs[i] = (values[i + 1] - values[i]) / h1 - (values[i] - values[i - 1]) / h0;
            }
            // Thomas algorithm on rows 1..n−2 (off-diagonals h/6).
            for i in 2..n - 1 {
                let w = (s[i] - s[i - 1]) / 6.0 / diag[i - 1];
                diag[i] -= w * (s[i] - s[i - 1]) / 6.0;
                rhs[i] -= w * rhs[i - 1];
            }
            for i in (1..n - 1).rev() {
                let upper = if i + 1 < n - 1 {
                    (s[i + 1] - s[i]) / 6.0 * curvature[i + 1]
                } else {
                    0.0
                };
                curvature[i] = (rhs[i] - upper) / diag[i];
            }
        }
        Ok(Profile::Spline(SplineKnots { knots, curvature }))
    }

    /// The profile times a constant factor (a control raising an
    /// intrinsic curvature in proportion, paper Sec. 5).
    #[must_use]
    pub fn scaled(&self, factor: f64) -> Profile {
        let times = |v: &[f64]| v.iter().map(|x| x * factor).collect::<Vec<_>>();
        match self {
            Profile::Constant(v) => Profile::Constant(v * factor),
            Profile::Polynomial(c) => Profile::Polynomial(times(c)),
            Profile::Table(k) => Profile::Table(k.with_values(times(&k.values))),
            Profile::Spline(sp) => Profile::Spline(SplineKnots {
                knots: sp.knots.with_values(times(&sp.knots.values)),
                curvature: times(&sp.curvature),
            }),
        }
    }

    /// (1 − p) self + p other, where both are of one kind on the same knots
    /// (so that the result is again a profile of that kind: the natural
    /// spline is linear in its values); None otherwise. A control moving
    /// an intrinsic curvature from one profile to another.
    pub fn blend(&self, other: &Profile, p: f64) -> Option<Profile> {
        let mix = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter()
                .zip(b)
                .map(|(x, y)| (1.0 - p) * x + p * y)
                .collect()
        };
        Some(match (self, other) {
            (Profile::Constant(a), Profile::Constant(b)) => {
                Profile::Constant((1.0 - p) * a + p * b)
            }
            (Profile::Polynomial(a), Profile::Polynomial(b)) => {
                let n = a.len().max(b.len());
                let pad = |c: &[f64]| {
                    (0..n)
                        .map(|i| c.get(i).copied().unwrap_or(0.0))
                        .collect::<Vec<_>>()
                };
                Profile::Polynomial(mix(&pad(a), &pad(b)))
            }
            (Profile::Table(a), Profile::Table(b)) if a.s == b.s => {
                Profile::Table(a.with_values(mix(&a.values, &b.values)))
            }
            (Profile::Spline(a), Profile::Spline(b)) if a.knots.s == b.knots.s => {
                Profile::Spline(SplineKnots {
                    knots: a.knots.with_values(mix(&a.knots.values, &b.knots.values)),
                    curvature: mix(&a.curvature, &b.curvature),
                })
            }
            _ => return None,
        })
    }

    /// The value at s.
    #[inline]
    pub fn value(&self, s: f64) -> f64 {
        match self {
            Profile::Constant(c) => *c,
            Profile::Polynomial(c) => c.iter().rev().fold(0.0, |acc, &ck| acc * s + ck),
            Profile::Table(Knots { s: knots, values }) => {
                let (k, t) = locate(knots, s);
                values[k] + t * (values[k + 1] - values[k])
            }
            Profile::Spline(SplineKnots {
                knots: Knots { s: knots, values },
                curvature,
            }) => {
                let (k, t) = locate(knots, s);
                let h = knots[k + 1] - knots[k];
                let (a, b) = (1.0 - t, t);
                a * values[k]
                    + b * values[k + 1]
                    + h * h / 6.0
                        * ((a * a * a - a) * curvature[k] + (b * b * b - b) * curvature[k + 1])
            }
        }
    }

    /// The derivative d/ds at s (one-sided at table knots: the right segment).
    #[inline]
    pub fn derivative(&self, s: f64) -> f64 {
        match self {
            Profile::Constant(_) => 0.0,
            Profile::Polynomial(c) => c
                .iter()
                .enumerate()
                .skip(1)
                .rev()
                .fold(0.0, |acc, (k, &ck)| acc * s + k as f64 * ck),
            Profile::Table(Knots { s: knots, values }) => {
                if s < knots[0] || s > knots[knots.len() - 1] {
                    return 0.0;
                }
                let (k, _) = locate(knots, s);
                (values[k + 1] - values[k]) / (knots[k + 1] - knots[k])
            }
            Profile::Spline(SplineKnots {
                knots: Knots { s: knots, values },
                curvature,
            }) => {
                let (k, t) = locate(knots, s);
                let h = knots[k + 1] - knots[k];
                let (a, b) = (1.0 - t, t);
                (values[k + 1] - values[k]) / h
                    + h / 6.0
                        * (-(3.0 * a * a - 1.0) * curvature[k]
                            + (3.0 * b * b - 1.0) * curvature[k + 1])
            }
        }
    }

    /// True when the profile is identically zero.
    pub fn is_zero(&self) -> bool {
        match self {
            Profile::Constant(c) => *c == 0.0,
            Profile::Polynomial(c) => c.iter().all(|&x| x == 0.0),
            Profile::Table(Knots { values, .. })
            | Profile::Spline(SplineKnots {
                knots: Knots { values, .. },
                ..
            }) => values.iter().all(|&x| x == 0.0),
        }
    }

    /// The smallest value on [0, length] ([`Profile::extremes_on`]).
    pub fn minimum_on(&self, length: f64) -> f64 {
        self.extremes_on(length).min
    }

    /// The extremes on [0, length], exactly where the profile allows:
    ///
    /// - a constant: itself;
    /// - a table (piecewise linear, constant outside): the values at the
    ///   knots inside [0, length] and at both ends, exact;
    /// - a polynomial: the values at the ends and at the real roots of the
    ///   derivative in (0, length), found by the derivative cascade (the
    ///   roots of p^(k+1) split [0, L] into intervals where p^(k) is
    ///   monotone, so each holds at most one root, bracketed by a sign
    ///   change and bisected to adjacent floating-point numbers);
    /// - a natural spline: the same on each cubic piece.
    ///
    /// `min_lower` and `max_upper` bound the true extremes: a root's
    /// bracket [a, b] contributes p(a), p(b) widened by (b − a) max |p'|
    /// there, and every value by Horner's rounding bound
    /// γ_2n Σ |c_k| |s|^k (Higham, *Accuracy and Stability*, eq. (5.3)).
    pub fn extremes_on(&self, length: f64) -> Extremes {
        match self {
            Profile::Constant(c) => Extremes::at(*c, 0.0, 0.0),
            Profile::Table(Knots { s, values }) => {
                let mut e = Extremes::at(self.value(0.0), 0.0, 0.0);
                e.include(self.value(length), length, 0.0);
                for (sk, vk) in s.iter().zip(values) {
                    if (0.0..=length).contains(sk) {
                        e.include(*vk, *sk, 0.0);
                    }
                }
                // Linear between knots: the extremes are knot values, exact.
                e
            }
            Profile::Polynomial(c) => polynomial_extremes(c, 0.0, length),
            Profile::Spline(SplineKnots {
                knots: Knots { s: knots, values },
                curvature,
            }) => {
                let n = knots.len();
                let mut e = Extremes::at(self.value(0.0), 0.0, 0.0);
                e.include(self.value(length), length, 0.0);
                for k in 0..n - 1 {
                    let (a, b) = (knots[k].max(0.0), knots[k + 1].min(length));
                    if a > b {
                        continue;
                    }
                    // The piece as a cubic in t = (s − s_k)/h.
                    let h = knots[k + 1] - knots[k];
                    let w = h * h / 6.0;
                    let cubic = [
                        values[k],
                        values[k + 1] - values[k] - w * (2.0 * curvature[k] + curvature[k + 1]),
                        3.0 * w * curvature[k],
                        w * (curvature[k + 1] - curvature[k]),
                    ];
                    let piece = polynomial_extremes(&cubic, (a - knots[k]) / h, (b - knots[k]) / h);
                    e.merge(&piece, |t| knots[k] + t * h);
                }
                e
            }
        }
    }
    /// Every number in the profile is finite.
    pub fn is_finite(&self) -> bool {
        match self {
            Profile::Constant(c) => c.is_finite(),
            Profile::Polynomial(c) => c.iter().all(|x| x.is_finite()),
            Profile::Table(Knots { s, values }) => s.iter().chain(values).all(|x| x.is_finite()),
            Profile::Spline(SplineKnots {
                knots: Knots { s, values },
                curvature,
            }) => s
                .iter()
                .chain(values)
                .chain(curvature)
                .all(|x| x.is_finite()),
        }
    }
}

/// The extremes of a profile on an interval, with certified bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extremes {
    /// The smallest value found.
    pub min: f64,
    /// Where.
    pub argmin: f64,
    /// The largest value found.
    pub max: f64,
    /// Where.
    pub argmax: f64,
    /// A lower bound of the true minimum.
    pub min_lower: f64,
    /// An upper bound of the true maximum.
    pub max_upper: f64,
}

impl Extremes {
    fn at(v: f64, s: f64, slack: f64) -> Self {
        Extremes {
            min: v,
            argmin: s,
            max: v,
            argmax: s,
            min_lower: v - slack,
            max_upper: v + slack,
        }
    }

    fn include(&mut self, v: f64, s: f64, slack: f64) {
        if v < self.min || v.is_nan() {
            self.min = v;
            self.argmin = s;
        }
        if v > self.max || v.is_nan() {
            self.max = v;
            self.argmax = s;
        }
        self.min_lower = self.min_lower.min(v - slack);
        self.max_upper = self.max_upper.max(v + slack);
    }

    /// Takes in another interval's extremes, its locations mapped by `to_s`.
    fn merge(&mut self, other: &Extremes, to_s: impl Fn(f64) -> f64) {
        self.include(other.min, to_s(other.argmin), 0.0);
        self.include(other.max, to_s(other.argmax), 0.0);
        self.min_lower = self.min_lower.min(other.min_lower);
        self.max_upper = self.max_upper.max(other.max_upper);
    }
}

/// Horner's value of Σ c_k x^k.
fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| acc * x + ck)
}

/// Horner's rounding bound γ_2n Σ |c_k| |x|^k.
fn horner_error(c: &[f64], x: f64) -> f64 {
    let n = 2.0 * c.len() as f64 * f64::EPSILON;
    n / (1.0 - n) * horner(&c.iter().map(|v| v.abs()).collect::<Vec<_>>(), x.abs())
}

fn derivative_of(c: &[f64]) -> Vec<f64> {
    c.iter()
        .enumerate()
        .skip(1)
        .map(|(k, ck)| k as f64 * ck)
        .collect()
}

/// The roots of Σ c_k x^k in (a, b), each as a bracket [lo, hi] of
/// adjacent floating-point numbers (or an exact root lo = hi), by the
/// derivative cascade: between consecutive roots of the derivative the
/// polynomial is monotone, so a sign change brackets its only root there.
fn root_brackets(c: &[f64], a: f64, b: f64) -> Vec<(f64, f64)> {
    use crate::numerics::scalar::{adjacent, bisect_or_break};
    use std::ops::ControlFlow;
    let degree = c.iter().rposition(|&v| v != 0.0).unwrap_or(0);
    if degree == 0 {
        return vec![];
    }
    let c = &c[..=degree];
    let mut splits = vec![a];
    if degree >= 2 {
        splits.extend(
            root_brackets(&derivative_of(c), a, b)
                .into_iter()
                .map(|(lo, hi)| 0.5 * (lo + hi)),
        );
    }
    splits.push(b);
    let mut roots = vec![];
    for w in splits.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        let (flo, fhi) = (horner(c, lo), horner(c, hi));
        if flo == 0.0 || fhi == 0.0 {
            let x = if flo == 0.0 { lo } else { hi };
            if x > a && x < b {
                roots.push((x, x));
            }
            continue;
        }
        if (flo < 0.0) == (fhi < 0.0) {
            continue;
        }
        let negative_at_lo = flo < 0.0;
        if adjacent(lo, hi) {
            roots.push((lo, hi));
            continue;
        }
        // Halved until adjacent, or an exact root at a midpoint.
        let side = |mid: f64| {
            let f = horner(c, mid);
            if f == 0.0 {
                ControlFlow::Break(mid)
            } else {
                ControlFlow::Continue((f < 0.0) == negative_at_lo)
            }
        };
        roots.push(match bisect_or_break(lo, hi, usize::MAX, side, adjacent) {
            ControlFlow::Break(x) => (x, x),
            ControlFlow::Continue(bracket) => bracket,
        });
    }
    roots
}

/// The extremes of Σ c_k x^k on [a, b] (locations reported in x).
fn polynomial_extremes(c: &[f64], a: f64, b: f64) -> Extremes {
    let mut e = Extremes::at(horner(c, a), a, horner_error(c, a));
    e.include(horner(c, b), b, horner_error(c, b));
    let dc = derivative_of(c);
    for (lo, hi) in root_brackets(&dc, a, b) {
        let slope = horner(&dc, lo).abs().max(horner(&dc, hi).abs());
        for x in [lo, hi] {
            e.include(horner(c, x), x, horner_error(c, x) + (hi - lo) * slope);
        }
    }
    e
}

/// The table segment k holding s and the fraction t ∈ [0, 1] along it
/// (clamped to the ends outside the table).
fn locate(knots: &[f64], s: f64) -> (usize, f64) {
    let n = knots.len();
    if s <= knots[0] {
        return (0, 0.0);
    }
    if s >= knots[n - 1] {
        return (n - 2, 1.0);
    }
    let k = knots
        .partition_point(|&x| x <= s)
        .saturating_sub(1)
        .min(n - 2);
    (k, (s - knots[k]) / (knots[k + 1] - knots[k]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scaling and blending act on the function itself: the spline built
    /// from scaled or blended knot values (built afresh) has the same
    /// values and derivatives everywhere.
    #[test]
    fn scaled_and_blended_splines_are_the_splines_of_the_values() {
        let s: Vec<f64> = (0..9).map(|i| f64::from(i) / 8.0).collect();
        let a: Vec<f64> = s.iter().map(|x| (3.0 * x).sin()).collect();
        let b: Vec<f64> = s.iter().map(|x| x * x - 2.0 * x).collect();
        let (sa, sb) = (
            Profile::spline(s.clone(), a.clone()).unwrap(),
            Profile::spline(s.clone(), b.clone()).unwrap(),
        );
        let mix: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.7 * x + 0.3 * y).collect();
        let fresh_mix = Profile::spline(s.clone(), mix).unwrap();
        let fresh_scaled =
            Profile::spline(s.clone(), a.iter().map(|x| -2.5 * x).collect()).unwrap();
        let blended = sa.blend(&sb, 0.3).unwrap();
        let scaled = sa.scaled(-2.5);
        for t in [0.0, 0.13, 0.5, 0.77, 1.0] {
            assert!((blended.value(t) - fresh_mix.value(t)).abs() < 1e-13);
            assert!((blended.derivative(t) - fresh_mix.derivative(t)).abs() < 1e-12);
            assert!((scaled.value(t) - fresh_scaled.value(t)).abs() < 1e-13);
        }
        assert!(sa.blend(&Profile::Constant(0.0), 0.5).is_none());
    }

    /// The exact minimum of a polynomial that dips below zero between
    /// 1001 equally spaced samples: p(s) = (s − s0)² − δ on [0, 1] with
    /// s0 = 0.43215 and δ = 1e-9. The nearest sample (0.432) is 1.5e-4
    /// away, where p = 2.3e-8 − 1e-9 > 0; the true minimum is −δ at s0.
    #[test]
    fn polynomial_minimum_is_the_root_of_the_derivative() {
        let (s0, delta) = (0.43215, 1e-9);
        let p = Profile::Polynomial(vec![s0 * s0 - delta, -2.0 * s0, 1.0]);
        let sampled = (0..=1000)
            .map(|i| p.value(f64::from(i) / 1000.0))
            .fold(f64::INFINITY, f64::min);
        assert!(sampled > 0.0, "{sampled}");
        let e = p.extremes_on(1.0);
        assert!((e.min + delta).abs() < 1e-15, "{}", e.min);
        assert!((e.argmin - s0).abs() < 1e-7, "{}", e.argmin);
        assert!(e.min_lower <= -delta && e.min_lower > -delta - 1e-14);
        // A quintic with three interior extremes: the cascade finds them
        // all (p' = 5 (s − 0.1)(s − 0.3)(s − 0.6)(s − 0.9) integrated).
        let roots = [0.1, 0.3, 0.6, 0.9];
        let mut d = vec![5.0];
        for r in roots {
            let mut next = vec![0.0; d.len() + 1];
            for (k, c) in d.iter().enumerate() {
                next[k + 1] += c;
                next[k] -= r * c;
            }
            d = next;
        }
        let mut c = vec![0.0];
        c.extend(d.iter().enumerate().map(|(k, v)| v / (k + 1) as f64));
        let q = Profile::Polynomial(c.clone());
        let e = q.extremes_on(1.0);
        let candidates = [0.0, 0.1, 0.3, 0.6, 0.9, 1.0].map(|s| q.value(s));
        let min = candidates.iter().copied().fold(f64::INFINITY, f64::min);
        let max = candidates.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!((e.min - min).abs() < 1e-15 && (e.max - max).abs() < 1e-15);
    }

    /// A spline's piecewise cubic extremes against dense sampling.
    #[test]
    fn spline_extremes_match_dense_sampling() {
        let s: Vec<f64> = (0..7).map(|i| f64::from(i) / 6.0).collect();
        let v: Vec<f64> = s.iter().map(|x| (7.0 * x).sin()).collect();
        let p = Profile::spline(s, v).unwrap();
        let e = p.extremes_on(1.0);
        let dense = (0..=200_000).map(|i| p.value(f64::from(i) / 200_000.0));
        let (lo, hi) = dense.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        assert!(e.min <= lo && lo - e.min < 1e-9, "{} {lo}", e.min);
        assert!(e.max >= hi && e.max - hi < 1e-9, "{} {hi}", e.max);
    }

    #[test]
    fn polynomial_value_and_derivative() {
        let p = Profile::Polynomial(vec![1.0, -2.0, 3.0]);
        assert_eq!(p.value(2.0), 1.0 - 4.0 + 12.0);
        assert_eq!(p.derivative(2.0), -2.0 + 12.0);
    }

    /// A natural spline reproduces a cubic's interior values to the order
    /// of its end conditions and its derivative matches differences.
    #[test]
    fn spline_interpolates_smoothly() {
        let f = |x: f64| (2.0 * x).sin();
        let s: Vec<f64> = (0..=200).map(|i| f64::from(i) / 200.0).collect();
        let p = Profile::spline(s.clone(), s.iter().map(|&x| f(x)).collect()).unwrap();
        for x in [0.3, 0.5123, 0.77] {
            assert!((p.value(x) - f(x)).abs() < 1e-7, "{x}");
            let h = 1e-6;
            let fd = (p.value(x + h) - p.value(x - h)) / (2.0 * h);
            assert!((p.derivative(x) - fd).abs() < 1e-6);
            assert!((p.derivative(x) - 2.0 * (2.0 * x).cos()).abs() < 1e-5);
        }
    }

    #[test]
    fn table_interpolates_and_clamps() {
        let p = Profile::table(vec![0.0, 1.0, 3.0], vec![1.0, 3.0, 2.0]).unwrap();
        assert_eq!(p.value(0.5), 2.0);
        assert_eq!(p.value(2.0), 2.5);
        assert_eq!(p.value(5.0), 2.0);
        assert_eq!(p.derivative(2.0), -0.5);
        assert_eq!(p.minimum_on(3.0), 1.0);
    }

    #[test]
    fn knots_are_checked() {
        let k = Knots::new(vec![0.0, 0.5, 1.0], vec![1.0, 2.0, 4.0]).unwrap();
        assert_eq!(
            (k.s(), k.values()),
            (&[0.0, 0.5, 1.0][..], &[1.0, 2.0, 4.0][..])
        );
        let sp = Profile::spline(vec![0.0, 1.0], vec![2.0, 3.0]).unwrap();
        let Profile::Spline(sp) = sp else {
            panic!("a spline")
        };
        assert_eq!(sp.knots().values(), &[2.0, 3.0]);
        assert_eq!(sp.curvature(), &[0.0, 0.0]);
        for (s, v) in [
            (vec![0.0], vec![1.0]),
            (vec![0.0, 1.0], vec![1.0]),
            (vec![0.0, 0.0], vec![1.0, 2.0]),
            (vec![1.0, 0.0], vec![1.0, 2.0]),
            (vec![0.0, f64::NAN], vec![1.0, 2.0]),
        ] {
            assert!(matches!(
                Profile::table(s.clone(), v.clone()),
                Err(ModelError::Profile(_))
            ));
            assert!(matches!(Profile::spline(s, v), Err(ModelError::Profile(_))));
        }
    }
}
