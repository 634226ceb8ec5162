//! Scalar root finding and one-dimensional search: bisection on a bracket,
//! the Illinois variant of regula falsi, the secant step, golden-section
//! search for a maximum and Newton's iteration on one unknown.
//!
//! Each keeps the arithmetic its callers were written with (the midpoint
//! 0.5·(lo + hi), the false position (lo·f_hi − hi·f_lo)/(f_hi − f_lo),
//! the golden ratio g = (√5 − 1)/2), so moving a caller here changes no
//! result to the bit. Callers decide the side of a bracket and when to
//! stop; the algorithms only move the bracket.

use std::convert::Infallible;
use std::ops::ControlFlow;

/// Bisection of [lo, hi]: at most `iterations` halvings at the midpoint
/// m = 0.5·(lo + hi), keeping the upper half [m, hi] when `keep_upper(m)`
/// and the lower half [lo, m] otherwise, and stopping early once
/// `done(lo, hi)` holds after a halving. Returns the final bracket.
pub fn bisect(
    lo: f64,
    hi: f64,
    iterations: usize,
    mut keep_upper: impl FnMut(f64) -> bool,
    done: impl FnMut(f64, f64) -> bool,
) -> (f64, f64) {
    let ControlFlow::Continue(bracket) = bisect_or_break::<Infallible>(
        lo,
        hi,
        iterations,
        |m| ControlFlow::Continue(keep_upper(m)),
        done,
    );
    bracket
}

/// [`bisect`] whose side test may end the search: `side(m)` returns
/// `Continue(keep_upper)` or `Break(b)`, and then the search returns
/// `Break(b)` at once (an interruption, an exact root at m).
pub fn bisect_or_break<B>(
    mut lo: f64,
    mut hi: f64,
    iterations: usize,
    mut side: impl FnMut(f64) -> ControlFlow<B, bool>,
    mut done: impl FnMut(f64, f64) -> bool,
) -> ControlFlow<B, (f64, f64)> {
    for _ in 0..iterations {
        let mid = 0.5 * (lo + hi);
        if side(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
        if done(lo, hi) {
            break;
        }
    }
    ControlFlow::Continue((lo, hi))
}

/// Whether no floating-point number lies strictly between lo and hi (the
/// midpoint rounds onto an end): a bracket bisected as far as it goes.
pub fn adjacent(lo: f64, hi: f64) -> bool {
    let mid = 0.5 * (lo + hi);
    mid <= lo || mid >= hi
}

/// Which end of a bracket an update moved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// The lower end lo.
    Lower,
    /// The upper end hi.
    Upper,
}

/// The Illinois method (regula falsi whose retained end has its value
/// halved when the same end is kept twice in a row; Dowell & Jarratt,
/// BIT 11, 1971) on a bracket [lo, hi] with f(lo)·f(hi) ≤ 0. The caller
/// evaluates f at [`Self::next_point`], reports it with [`Self::update`]
/// and decides when to stop.
#[derive(Debug, Clone, PartialEq)]
pub struct Illinois {
    lo: f64,
    hi: f64,
    f_lo: f64,
    f_hi: f64,
    /// The end moved last: −1 lower, 1 upper, 0 none yet.
    side: i32,
}

impl Illinois {
    /// The bracket [lo, hi] with its values; None when they have the same
    /// strict sign (no sign change is bracketed).
    pub fn new(lo: f64, hi: f64, f_lo: f64, f_hi: f64) -> Option<Self> {
        if f_lo * f_hi > 0.0 {
            return None;
        }
        Some(Illinois {
            lo,
            hi,
            f_lo,
            f_hi,
            side: 0,
        })
    }

    /// The false position (lo·f_hi − hi·f_lo)/(f_hi − f_lo), or the
    /// midpoint when the values are equal or the false position is not
    /// strictly inside the bracket.
    pub fn next_point(&self) -> f64 {
        let (lo, hi, f_lo, f_hi) = (self.lo, self.hi, self.f_lo, self.f_hi);
        let x = if f_hi == f_lo {
            0.5 * (lo + hi)
        } else {
            (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        };
        if x <= lo || x >= hi {
            0.5 * (lo + hi)
        } else {
            x
        }
    }

    /// Takes f(x) = fx at a point inside the bracket: x replaces the end
    /// whose value has the sign of fx (hi when fx is 0), and when the same
    /// end moves twice in a row the other end's value is halved.
    pub fn update(&mut self, x: f64, fx: f64) -> End {
        if fx * self.f_lo > 0.0 {
            self.lo = x;
            self.f_lo = fx;
            if self.side == -1 {
                self.f_hi *= 0.5;
            }
            self.side = -1;
            End::Lower
        } else {
            self.hi = x;
            self.f_hi = fx;
            if self.side == 1 {
                self.f_lo *= 0.5;
            }
            self.side = 1;
            End::Upper
        }
    }

    /// The bracket's width hi − lo.
    pub fn width(&self) -> f64 {
        self.hi - self.lo
    }
}

/// The secant step x1 − f1·(x1 − x0)/(f1 − f0): the root of the line
/// through (x0, f0) and (x1, f1).
pub fn secant_step(x0: f64, f0: f64, x1: f64, f1: f64) -> f64 {
    x1 - f1 * (x1 - x0) / (f1 - f0)
}

/// Golden-section search for a maximum of f on [a, b]: at most
/// `iterations` steps, each evaluating f at c = b − g(b − a) and then at
/// d = a + g(b − a), g = (√5 − 1)/2, keeping [a, d] when f(c) > f(d) and
/// [c, b] otherwise, and stopping early once `done(a, b)` holds. `f` may
/// end the search with `Break`. Returns the final bracket.
pub fn golden_section_max<B>(
    mut a: f64,
    mut b: f64,
    iterations: usize,
    mut f: impl FnMut(f64) -> ControlFlow<B, f64>,
    mut done: impl FnMut(f64, f64) -> bool,
) -> ControlFlow<B, (f64, f64)> {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..iterations {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if f(c)? > f(d)? {
            b = d;
        } else {
            a = c;
        }
        if done(a, b) {
            break;
        }
    }
    ControlFlow::Continue((a, b))
}

/// Newton's iteration on one unknown from x0: x ← x − δ with the step
/// δ = g(x)/g'(x) that `step(x)` returns, at most `iterations` times,
/// stopping once |δ| ≤ `tolerance`·max(|x|, 1) after the update.
pub fn newton(x0: f64, iterations: usize, tolerance: f64, mut step: impl FnMut(f64) -> f64) -> f64 {
    let mut x = x0;
    for _ in 0..iterations {
        let dx = step(x);
        x -= dx;
        if dx.abs() <= tolerance * x.abs().max(1.0) {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisection_finds_sqrt2_to_adjacent_numbers() {
        let (lo, hi) = bisect(1.0, 2.0, usize::MAX, |m| m * m < 2.0, adjacent);
        assert!(adjacent(lo, hi) && lo * lo < 2.0 && hi * hi >= 2.0);
        let (lo, hi) = bisect(1.0, 2.0, 3, |m| m * m < 2.0, |_, _| false);
        assert_eq!((lo, hi), (1.375, 1.5));
        let stopped = bisect_or_break(
            1.0,
            2.0,
            60,
            |m| {
                if m < 1.4 {
                    ControlFlow::Break(m)
                } else {
                    ControlFlow::Continue(m * m < 2.0)
                }
            },
            |_, _| false,
        );
        assert_eq!(stopped, ControlFlow::Break(1.25));
    }

    #[test]
    fn illinois_converges_on_a_cubic() {
        let f = |x: f64| x * x * x - 2.0;
        assert!(Illinois::new(2.0, 3.0, f(2.0), f(3.0)).is_none());
        let mut ill = Illinois::new(0.0, 2.0, f(0.0), f(2.0)).unwrap();
        let mut x = 0.0;
        for _ in 0..60 {
            x = ill.next_point();
            ill.update(x, f(x));
            if f(x).abs() < 1e-14 {
                break;
            }
        }
        assert!((x - 2f64.cbrt()).abs() < 1e-13, "{x}");
        assert!(ill.width() < 2.0);
    }

    #[test]
    fn secant_golden_and_newton() {
        assert_eq!(secant_step(0.0, -1.0, 2.0, 3.0), 0.5);
        let ControlFlow::Continue((a, b)) = golden_section_max::<()>(
            0.0,
            3.0,
            200,
            |x| ControlFlow::Continue(-(x - 1.25) * (x - 1.25)),
            |a, b| b - a < 1e-9,
        ) else {
            unreachable!()
        };
        assert!((0.5 * (a + b) - 1.25).abs() < 1e-8);
        let x = newton(1.0, 50, 1e-15, |x| (x * x - 2.0) / (2.0 * x));
        assert!((x - 2f64.sqrt()).abs() < 1e-15);
    }
}
