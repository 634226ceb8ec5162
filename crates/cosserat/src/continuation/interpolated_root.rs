//! The root of a test function from its samples, where the bracket cannot
//! be closed.
//!
//! Near a singular point the corrector's Newton basin shrinks with the
//! distance to it; on a branch of symmetric copies, whose slice system is
//! already bordered once, a multiple branch point leaves two near-null
//! directions, and the slice corrector fails within ~1e-6 of Michell's
//! point of the twisted ring. The bracket then stops at the last points
//! that converged, though the test function there is known to the
//! corrector's accuracy on both sides. Inverse interpolation of those
//! samples (Lagrange, σ, p, x and the tangent as polynomials in the test
//! value g, evaluated at g = 0; the same weights for all) gives the root to
//! the interpolation's order; the estimate of its error is the difference
//! from the interpolant of one degree less (without the sample farthest
//! from the root in |g|), to which the caller adds the resolution every
//! sample's parameter has (the event tolerance, as a closed bracket's).
//! Taken only where the chosen samples bracket the root, lie on a test
//! function strictly monotone in σ, and give an error below the bracket's
//! spread.

use super::events::Located;

/// A sample of the test function along a step: the arclength σ and the
/// located point there (g, x, p, tangent).
pub(super) type Sample = (f64, Located);

/// The interpolated root: σ, the point (g = 0, x, p, unit tangent) and the
/// estimated error of its parameter.
pub(super) type Interpolated = (f64, Located, f64);

/// The root interpolated from the up to four samples around the innermost
/// sign change of g (two on each side where there are), or None where
/// fewer than three bracket it or g is not strictly monotone over them.
pub(super) fn interpolated(samples: &[Sample]) -> Option<Interpolated> {
    let mut s: Vec<&Sample> = samples.iter().filter(|(_, l)| l.0.is_finite()).collect();
    s.sort_by(|a, b| a.0.total_cmp(&b.0));
    s.dedup_by(|a, b| a.0 == b.0);
    let change = (0..s.len().checked_sub(1)?).find(|&i| s[i].1 .0 * s[i + 1].1 .0 < 0.0)?;
    let chosen = &s[change.saturating_sub(1)..=(change + 2).min(s.len() - 1)];
    let g: Vec<f64> = chosen.iter().map(|(_, l)| l.0).collect();
    let monotone = g.windows(2).all(|w| w[1] > w[0]) || g.windows(2).all(|w| w[1] < w[0]);
    if chosen.len() < 3 || !monotone {
        return None;
    }
    let all: Vec<usize> = (0..chosen.len()).collect();
    let far = all
        .iter()
        .copied()
        .max_by(|&i, &j| g[i].abs().total_cmp(&g[j].abs()))?;
    let fewer: Vec<usize> = all.iter().copied().filter(|&i| i != far).collect();
    let (w, w_fewer) = (weights_at_zero(&g, &all), weights_at_zero(&g, &fewer));
    let combine = |w: &[f64], idx: &[usize], f: &dyn Fn(&Sample) -> f64| -> f64 {
        idx.iter().zip(w).map(|(&i, wi)| wi * f(chosen[i])).sum()
    };
    let p = combine(&w, &all, &|a| a.1 .2);
    let error = (p - combine(&w_fewer, &fewer, &|a| a.1 .2)).abs();
    let sigma = combine(&w, &all, &|a| a.0);
    let x = (0..chosen[0].1 .1.len())
        .map(|k| combine(&w, &all, &|a| a.1 .1[k]))
        .collect();
    let mut tangent: Vec<f64> = (0..chosen[0].1 .3.len())
        .map(|k| combine(&w, &all, &|a| a.1 .3[k]))
        .collect();
    let norm = tangent.iter().map(|t| t * t).sum::<f64>().sqrt();
    if !(norm > 0.0 && p.is_finite() && error.is_finite()) {
        return None;
    }
    for t in &mut tangent {
        *t /= norm;
    }
    Some((sigma, (0.0, x, p, tangent), error))
}

/// The Lagrange weights of the nodes g[idx] for the value at 0.
fn weights_at_zero(g: &[f64], idx: &[usize]) -> Vec<f64> {
    idx.iter()
        .map(|&i| {
            idx.iter()
                .filter(|&&j| j != i)
                .map(|&j| -g[j] / (g[i] - g[j]))
                .product()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// g(σ) = (σ − r)(1 + σ), p = 2σ: the root r = 0.3 from samples that
    /// stop 0.05 short of it on one side and 0.1 on the other — the cubic
    /// through four samples is exact for this g's inverse only to its
    /// order, and the stated error bounds the actual one.
    #[test]
    fn the_root_of_a_smooth_function_within_its_stated_error() {
        let r = 0.3;
        let sample = |sigma: f64| -> Sample {
            let g = (sigma - r) * (1.0 + sigma);
            (
                sigma,
                (g, vec![sigma, sigma * sigma], 2.0 * sigma, vec![1.0, 0.0]),
            )
        };
        let samples: Vec<Sample> = [0.0, 0.25, 0.4, 0.5].into_iter().map(sample).collect();
        let (sigma, (_, x, p, t), error) = interpolated(&samples).expect("a root");
        let actual = (p - 2.0 * r).abs();
        assert!(
            actual <= error,
            "p = {p}, error {error:e}, actual {actual:e}"
        );
        assert!(error < 0.02, "{error}");
        assert!((sigma - r).abs() < 0.01 && (x[0] - r).abs() < 0.01);
        assert!((t[0] - 1.0).abs() < 1e-12);
    }

    /// Without a sign change, or with a non-monotone g, there is no root.
    #[test]
    fn refused_without_a_monotone_bracket() {
        let at = |sigma: f64, g: f64| -> Sample { (sigma, (g, vec![], sigma, vec![1.0])) };
        assert!(interpolated(&[at(0.0, 1.0), at(1.0, 2.0), at(2.0, 3.0)]).is_none());
        assert!(interpolated(&[at(0.0, 1.0), at(1.0, -1.0), at(2.0, 0.5)]).is_none());
        assert!(interpolated(&[at(0.0, 1.0), at(1.0, -1.0)]).is_none());
    }
}
