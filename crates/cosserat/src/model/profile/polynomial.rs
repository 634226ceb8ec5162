//! Polynomials on an interval: Horner evaluation with its rounding bound,
//! derivatives, and extremes certified by bracketing the derivative's
//! roots — the bounds a profile's checks rely on (a stiffness must stay
//! positive on [0, L], not only at the sampled points).

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
    pub(super) fn at(v: f64, s: f64, slack: f64) -> Self {
        Extremes {
            min: v,
            argmin: s,
            max: v,
            argmax: s,
            min_lower: v - slack,
            max_upper: v + slack,
        }
    }

    pub(super) fn include(&mut self, v: f64, s: f64, slack: f64) {
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
    pub(super) fn merge(&mut self, other: &Extremes, to_s: impl Fn(f64) -> f64) {
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
pub(super) fn polynomial_extremes(c: &[f64], a: f64, b: f64) -> Extremes {
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
