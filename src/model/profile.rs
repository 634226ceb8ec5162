//! Functions of the reference arc length s: stiffness and intrinsic-curvature
//! profiles of non-prismatic or pre-curved rods.
//!
//! A profile is a constant, a polynomial in s (coefficients in increasing
//! powers, s in the same length unit as the rod), or a piecewise-linear table.
//! Energies need the value and its s-derivative (the explicit s-dependence of
//! the body moment, DESIGN.md "κ' from M' = Hκ' + ∂s∇W").

/// A scalar function of the arc length s.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// The same value everywhere.
    Constant(f64),
    /// Σ c_k s^k, coefficients in increasing powers.
    Polynomial(Vec<f64>),
    /// Piecewise-linear interpolation of (s_k, v_k), s strictly increasing;
    /// held constant outside the table.
    Table { s: Vec<f64>, values: Vec<f64> },
    /// The natural cubic spline through (s_k, v_k) (C², so that equations
    /// using the derivative stay continuous); build with [`Profile::spline`].
    Spline {
        s: Vec<f64>,
        values: Vec<f64>,
        /// Second derivatives at the knots.
        curvature: Vec<f64>,
    },
}

impl Default for Profile {
    fn default() -> Self {
        Profile::Constant(0.0)
    }
}

impl Profile {
    /// The natural cubic spline through (s_k, v_k), s strictly increasing,
    /// at least two knots (second derivatives from the tridiagonal system
    /// with zero end curvature; de Boor, *A Practical Guide to Splines*,
    /// ch. IV).
    pub fn spline(s: Vec<f64>, values: Vec<f64>) -> Profile {
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
        Profile::Spline {
            s,
            values,
            curvature,
        }
    }

    /// The profile times a constant factor (a control raising an
    /// intrinsic curvature in proportion, paper Sec. 5).
    pub fn scaled(&self, factor: f64) -> Profile {
        let times = |v: &[f64]| v.iter().map(|x| x * factor).collect::<Vec<_>>();
        match self {
            Profile::Constant(v) => Profile::Constant(v * factor),
            Profile::Polynomial(c) => Profile::Polynomial(times(c)),
            Profile::Table { s, values } => Profile::Table {
                s: s.clone(),
                values: times(values),
            },
            Profile::Spline {
                s,
                values,
                curvature,
            } => Profile::Spline {
                s: s.clone(),
                values: times(values),
                curvature: times(curvature),
            },
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
            (Profile::Table { s, values: a }, Profile::Table { s: t, values: b }) if s == t => {
                Profile::Table {
                    s: s.clone(),
                    values: mix(a, b),
                }
            }
            (
                Profile::Spline {
                    s,
                    values: a,
                    curvature: ca,
                },
                Profile::Spline {
                    s: t,
                    values: b,
                    curvature: cb,
                },
            ) if s == t => Profile::Spline {
                s: s.clone(),
                values: mix(a, b),
                curvature: mix(ca, cb),
            },
            _ => return None,
        })
    }

    /// The value at s.
    #[inline]
    pub fn value(&self, s: f64) -> f64 {
        match self {
            Profile::Constant(c) => *c,
            Profile::Polynomial(c) => c.iter().rev().fold(0.0, |acc, &ck| acc * s + ck),
            Profile::Table { s: knots, values } => {
                let (k, t) = locate(knots, s);
                values[k] + t * (values[k + 1] - values[k])
            }
            Profile::Spline {
                s: knots,
                values,
                curvature,
            } => {
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
            Profile::Table { s: knots, values } => {
                if s < knots[0] || s > knots[knots.len() - 1] {
                    return 0.0;
                }
                let (k, _) = locate(knots, s);
                (values[k + 1] - values[k]) / (knots[k + 1] - knots[k])
            }
            Profile::Spline {
                s: knots,
                values,
                curvature,
            } => {
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
            Profile::Table { values, .. } | Profile::Spline { values, .. } => {
                values.iter().all(|&x| x == 0.0)
            }
        }
    }

    /// The smallest value on [0, length]: exact for constants and tables
    /// (extremes sit at knots), sampled densely plus the end points for
    /// polynomials. Used to reject non-positive stiffness.
    pub fn minimum_on(&self, length: f64) -> f64 {
        match self {
            Profile::Constant(c) => *c,
            Profile::Table { s, values } => {
                let mut m = self.value(0.0).min(self.value(length));
                for (sk, vk) in s.iter().zip(values) {
                    if (0.0..=length).contains(sk) {
                        m = m.min(*vk);
                    }
                }
                m
            }
            Profile::Polynomial(_) | Profile::Spline { .. } => (0..=1000)
                .map(|i| self.value(length * i as f64 / 1000.0))
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// Every number in the profile is finite.
    pub fn is_finite(&self) -> bool {
        match self {
            Profile::Constant(c) => c.is_finite(),
            Profile::Polynomial(c) => c.iter().all(|x| x.is_finite()),
            Profile::Table { s, values } => s.iter().chain(values).all(|x| x.is_finite()),
            Profile::Spline {
                s,
                values,
                curvature,
            } => s
                .iter()
                .chain(values)
                .chain(curvature)
                .all(|x| x.is_finite()),
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
mod tests {
    use super::*;

    /// Scaling and blending act on the function itself: the spline built
    /// from scaled or blended knot values (built afresh) has the same
    /// values and derivatives everywhere.
    #[test]
    fn scaled_and_blended_splines_are_the_splines_of_the_values() {
        let s: Vec<f64> = (0..9).map(|i| i as f64 / 8.0).collect();
        let a: Vec<f64> = s.iter().map(|x| (3.0 * x).sin()).collect();
        let b: Vec<f64> = s.iter().map(|x| x * x - 2.0 * x).collect();
        let (sa, sb) = (
            Profile::spline(s.clone(), a.clone()),
            Profile::spline(s.clone(), b.clone()),
        );
        let mix: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.7 * x + 0.3 * y).collect();
        let fresh_mix = Profile::spline(s.clone(), mix);
        let fresh_scaled = Profile::spline(s.clone(), a.iter().map(|x| -2.5 * x).collect());
        let blended = sa.blend(&sb, 0.3).unwrap();
        let scaled = sa.scaled(-2.5);
        for t in [0.0, 0.13, 0.5, 0.77, 1.0] {
            assert!((blended.value(t) - fresh_mix.value(t)).abs() < 1e-13);
            assert!((blended.derivative(t) - fresh_mix.derivative(t)).abs() < 1e-12);
            assert!((scaled.value(t) - fresh_scaled.value(t)).abs() < 1e-13);
        }
        assert!(sa.blend(&Profile::Constant(0.0), 0.5).is_none());
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
        let s: Vec<f64> = (0..=200).map(|i| i as f64 / 200.0).collect();
        let p = Profile::spline(s.clone(), s.iter().map(|&x| f(x)).collect());
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
        let p = Profile::Table {
            s: vec![0.0, 1.0, 3.0],
            values: vec![1.0, 3.0, 2.0],
        };
        assert_eq!(p.value(0.5), 2.0);
        assert_eq!(p.value(2.0), 2.5);
        assert_eq!(p.value(5.0), 2.0);
        assert_eq!(p.derivative(2.0), -0.5);
        assert_eq!(p.minimum_on(3.0), 1.0);
    }
}
