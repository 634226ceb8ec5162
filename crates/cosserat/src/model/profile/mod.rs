//! Functions of the reference arc length s: stiffness and intrinsic-curvature
//! profiles of non-prismatic or pre-curved rods.
//!
//! A profile is a constant, a polynomial in s (coefficients in increasing
//! powers, s in the same length unit as the rod), a piecewise-linear table, a
//! natural cubic spline, or a piecewise polynomial with breakpoints where the
//! solvers stop (`piecewise.rs`).
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
    /// A polynomial on each interval between breakpoints, possibly kinked
    /// at them (a tapered section's stiffness); the solvers stop at its
    /// breakpoints ([`Profile::breaks`]). Build with
    /// [`Profile::piecewise`] or [`Profile::piecewise_interpolant`].
    Piecewise(Pieces),
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

mod piecewise;
mod polynomial;
pub use piecewise::{Pieces, Sampler};
use polynomial::polynomial_extremes;
pub use polynomial::Extremes;

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

    /// The piecewise polynomial with the Chebyshev coefficients
    /// `coefficients[k]` on [s_k, s_{k+1}] in t = (2s − s_k − s_{k+1})/(s_{k+1}
    /// − s_k); refused as in [`Pieces::new`].
    pub fn piecewise(breaks: Vec<f64>, coefficients: Vec<Vec<f64>>) -> Result<Profile, ModelError> {
        Ok(Profile::Piecewise(Pieces::new(breaks, coefficients)?))
    }

    /// The piecewise interpolant of a function smooth between `breaks`, to
    /// `tolerance` × max(`scale`, each piece's largest |value|); `f` gives
    /// its values at sorted points of one piece. Refused where the
    /// function is not smooth on a piece (degree 128 does not meet the
    /// tolerance) or `f` fails (see the module `piecewise`).
    pub fn piecewise_interpolant(
        breaks: Vec<f64>,
        f: &mut Sampler<'_>,
        (tolerance, scale): (f64, f64),
    ) -> Result<Profile, ModelError> {
        Ok(Profile::Piecewise(piecewise::interpolate(
            breaks,
            f,
            (tolerance, scale),
        )?))
    }

    /// The interior points where the profile is not smooth and the
    /// solvers stop: a piecewise profile's breakpoints strictly inside
    /// (0, length). A table's knots are not listed (its kinks are left to
    /// the integrator's step control, as they always were).
    pub fn breaks(&self, length: f64) -> Vec<f64> {
        match self {
            Profile::Piecewise(p) => p
                .interior_breaks()
                .iter()
                .copied()
                .filter(|s| *s > 0.0 && *s < length)
                .collect(),
            _ => Vec::new(),
        }
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
            Profile::Piecewise(p) => Profile::Piecewise(p.map(|v| v * factor)),
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
            (Profile::Piecewise(a), Profile::Piecewise(b)) => Profile::Piecewise(a.blend(b, p)?),
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
            Profile::Piecewise(p) => p.value(s),
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
            Profile::Piecewise(p) => p.derivative(s),
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
            Profile::Piecewise(p) => p.is_zero(),
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
            Profile::Piecewise(p) => p.extremes_on(length),
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
            Profile::Piecewise(p) => p.is_finite(),
        }
    }
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
mod tests;
