//! Unit tests of profiles.
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
    let fresh_scaled = Profile::spline(s.clone(), a.iter().map(|x| -2.5 * x).collect()).unwrap();
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

/// A piecewise profile lists its interior breakpoints inside (0, L) (other
/// kinds none), and scales and blends as the function does.
#[test]
fn piecewise_breaks_scale_and_blend() {
    let a = Profile::piecewise(
        vec![0.0, 0.4, 1.0, 2.0],
        vec![vec![1.0, 0.5], vec![2.0], vec![1.0, 0.0, 0.25]],
    )
    .unwrap();
    let b = Profile::piecewise(
        vec![0.0, 0.4, 1.0, 2.0],
        vec![vec![3.0], vec![0.0, 1.0], vec![-1.0]],
    )
    .unwrap();
    assert_eq!(a.breaks(1.5), vec![0.4, 1.0]);
    assert_eq!(a.breaks(1.0), vec![0.4]);
    assert!(Profile::Constant(1.0).breaks(1.0).is_empty());
    let mix = a.blend(&b, 0.25).unwrap();
    let twice = a.scaled(2.0);
    for s in [0.0, 0.1, 0.4, 0.7, 1.0, 1.3, 2.0] {
        let expect = 0.75 * a.value(s) + 0.25 * b.value(s);
        assert!((mix.value(s) - expect).abs() < 1e-15, "{s}");
        let slope = 0.75 * a.derivative(s) + 0.25 * b.derivative(s);
        assert!((mix.derivative(s) - slope).abs() < 1e-14, "{s}");
        assert!((twice.value(s) - 2.0 * a.value(s)).abs() < 1e-15);
    }
    let other = Profile::piecewise(vec![0.0, 0.5, 2.0], vec![vec![1.0], vec![1.0]]).unwrap();
    assert!(a.blend(&other, 0.5).is_none(), "other breakpoints");
    assert!(Profile::piecewise(vec![0.0, 1.0], vec![]).is_err());
    assert!(Profile::piecewise(vec![1.0, 0.0], vec![vec![1.0]]).is_err());
}
