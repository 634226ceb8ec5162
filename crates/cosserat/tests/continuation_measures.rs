//! Per-point measures against closed forms: the buckled Euler column's
//! unfolded turning angle and stored energy along the elastica, and the
//! force a displacement-controlled support exerts.

use std::f64::consts::FRAC_PI_2;

use cosserat::continuation::continuation;
use cosserat::input::Problem;
use cosserat::numerics::scalar::bisect;
use cosserat::references::{clamped_elastica_load, ellip_e, ellip_f};

const EULER: &str = include_str!("../../../problems/euler_column.toml");
const DISPLACEMENT: &str = include_str!("../../../problems/clamped_elastica_displacement.toml");

/// The modulus k of the clamped–free elastica at the load p = F L²/B:
/// p = K(k)² (B = L = 1).
fn modulus(p: f64) -> f64 {
    let (lo, hi) = bisect(
        0.0,
        1.0 - 1e-15,
        200,
        |k| ellip_f(FRAC_PI_2, k).powi(2) < p,
        |_, _| false,
    );
    0.5 * (lo + hi)
}

/// On the buckled column (B = L = 1, load p): the tip turns by
/// α = 2 asin k, and the stored energy is ½∫θ'² ds = 2K(E − (1 − k²)K)
/// (θ' = 2kλ cn(λs), λ = K: ∫₀ᴷ cn² = (E − k'²K)/k²).
#[test]
fn turning_and_energy_follow_the_elastica() {
    let set = [
        "continuation.measures=[\"turning\", \"stored_energy\"]".to_string(),
        "continuation.switch_depth=1".to_string(),
    ];
    let problem = Problem::from_str_with(EULER, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    assert_eq!(d.measure_names, ["turning", "stored_energy"]);
    let buckled = &d.branches[1];
    let mut checked = 0;
    for point in &buckled.points[1..] {
        let k = modulus(point.parameter);
        let alpha = 2.0 * k.asin();
        let (kk, ee) = (ellip_f(FRAC_PI_2, k), ellip_e(FRAC_PI_2, k));
        let energy = 2.0 * kk * (ee - (1.0 - k * k) * kk);
        let (turning, stored) = (point.measures[0], point.measures[1]);
        assert!(
            (turning.abs() - alpha).abs() < 1e-8,
            "p = {}: turning {turning}, α {alpha}",
            point.parameter
        );
        assert!(
            (stored - energy).abs() < 1e-8 * energy.max(1e-3),
            "p = {}: {stored} vs {energy}",
            point.parameter
        );
        checked += 1;
    }
    assert!(checked > 20);
    // Unfolded: the last point has turned 170°, and the sign is kept.
    let last = buckled.points.last().unwrap().measures[0];
    assert!((last.abs() - 170f64.to_radians()).abs() < 1e-8, "{last}");
}

/// `continuation.stop_at`: each buckled branch ends exactly where its tip
/// has turned by one radian, α = 2 asin k = ±1, i.e. at the load
/// p = K(sin ½)² of the elastica (B = L = 1) — the step that passes it
/// shortened onto it (measured 4.2e-13 from the closed form). A stop on a
/// measure that `measures` does not list is refused, naming the key.
#[test]
fn a_branch_stops_where_its_measure_reaches_the_value() {
    let set = [
        "continuation.measures=[\"turning\"]".to_string(),
        "continuation.stop_at=[{measure=\"turning\", value=1.0}, {measure=\"turning\", \
         value=-1.0}]"
            .to_string(),
    ];
    let problem = Problem::from_str_with(EULER, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let k = 0.5f64.sin();
    let exact = ellip_f(FRAC_PI_2, k).powi(2);
    let buckled: Vec<_> = d.branches.iter().skip(1).collect();
    assert_eq!(buckled.len(), 2, "{:?}", d.warnings);
    for branch in buckled {
        let last = branch.points.last().unwrap();
        assert!(
            (last.measures[0].abs() - 1.0).abs() <= 1e-10,
            "turning {}",
            last.measures[0]
        );
        assert!(
            (last.parameter - exact).abs() <= 1e-9 * exact,
            "p = {} against K(sin ½)² = {exact}",
            last.parameter
        );
        let end = branch.stop_reason.to_string();
        assert!(end.starts_with("reached turning = "), "{end}");
    }
    let unlisted = ["continuation.stop_at=[{measure=\"turning\", value=1.0}]".to_string()];
    let e = Problem::from_str_with(EULER, &unlisted)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("continuation.stop_at[0]") && e.contains("continuation.measures"),
        "{e}"
    );
}

/// The total potential energy Π = ∫W ds − P·r(L) along the buckled
/// column (load P = λP₀, P₀ = −e3, B = L = 1). The elastica gives it in
/// closed form, Π = 2K(E − k'²K) + λ z(L) with λ = K² and the tip height
/// z(L) = 2E/K − 1 (Timoshenko & Gere, Sec. 2.7); and by the envelope
/// theorem its slope along the branch is dΠ/dλ = −P₀·r(L) = z(L), which
/// the central difference between neighbouring points meets to its
/// O(Δλ²) truncation error.
#[test]
fn the_total_potential_energy_has_the_envelope_slope() {
    let set = [
        "continuation.measures=[\"total_potential_energy\", \"position[2]@1\"]".to_string(),
        "continuation.step=0.05".to_string(),
        "continuation.max_step=0.05".to_string(),
    ];
    let problem = Problem::from_str_with(EULER, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    assert_eq!(d.measure_names, ["total_potential_energy", "position[2]@1"]);
    let tip_height = |lambda: f64| {
        let k = modulus(lambda);
        2.0 * ellip_e(FRAC_PI_2, k) / ellip_f(FRAC_PI_2, k) - 1.0
    };
    let buckled = &d.branches[1];
    for point in &buckled.points[1..] {
        let lambda = point.parameter;
        let k = modulus(lambda);
        let (kk, ee) = (ellip_f(FRAC_PI_2, k), ellip_e(FRAC_PI_2, k));
        let exact = 2.0 * kk * (ee - (1.0 - k * k) * kk) + lambda * tip_height(lambda);
        assert!(
            (point.measures[0] - exact).abs() < 1e-8 * exact.abs().max(1.0),
            "λ = {lambda}: Π {} vs {exact}",
            point.measures[0]
        );
    }
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for pair in buckled.points[1..].windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let h = b.parameter - a.parameter;
        if h.abs() < 1e-6 {
            continue;
        }
        let slope = (b.measures[0] - a.measures[0]) / h;
        let exact = tip_height(0.5 * (a.parameter + b.parameter));
        // The central difference's truncation error is h²/24 · z''(λ), and
        // |z''| < 0.74 on the buckled branch (the closed form's second
        // difference, largest next to λ = π²/4); 1e-7 for the points'
        // own Π, accurate to the corrector's tolerance.
        let error = (slope - exact).abs();
        assert!(
            error < h * h / 24.0 + 1e-7,
            "λ = {}: {slope} vs {exact}",
            a.parameter
        );
        worst = worst.max(error);
        checked += 1;
    }
    assert!(checked > 20, "{checked} slopes checked");
    eprintln!("dΠ/dλ against z(L): {checked} slopes, worst error {worst:.2e}");
}

/// The stored measure is the force the support exerts (−P along the axis).
#[test]
fn the_support_force_is_measured_along_the_displacement_branch() {
    let problem = Problem::from_str_with(DISPLACEMENT, &[]).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    assert_eq!(d.measure_names[0], "force[2]@1");
    for point in d.branches.iter().flat_map(|b| &b.points) {
        let delta = 1.0 - point.parameter;
        if delta < 1e-3 {
            continue;
        }
        let exact = clamped_elastica_load(delta);
        assert!(
            (-point.measures[0] - exact).abs() <= 1e-8 * exact,
            "δ = {delta}"
        );
        // The midspan sways by two quarter-waves' 2k/λ: k/K (λ = 4K).
        let (lo, hi) = bisect(
            0.0,
            1.0 - 1e-15,
            200,
            |k| 2.0 * (1.0 - ellip_e(FRAC_PI_2, k) / ellip_f(FRAC_PI_2, k)) < delta,
            |_, _| false,
        );
        let k = 0.5 * (lo + hi);
        let sway = k / ellip_f(FRAC_PI_2, k);
        assert!(
            (point.measures[2].abs() - sway).abs() < 1e-8,
            "δ = {delta}: sway {}",
            point.measures[2]
        );
    }
}

/// Measures that cannot be computed for the scene are refused by name.
#[test]
fn measures_outside_their_scene_are_refused() {
    const TWISTED: &str = include_str!("../../../problems/twisted_rod.toml");
    for (text, set, says) in [
        (TWISTED, "continuation.measures=[\"turning\"]", "planar"),
        (
            EULER,
            "continuation.measures=[\"force[3]@0\"]",
            "not a measure",
        ),
        (
            EULER,
            "continuation.measures=[\"force[2]@2\"]",
            "not a measure",
        ),
        (
            EULER,
            "continuation.measures=[\"turning\", \"turning\"]",
            "twice",
        ),
        (
            EULER,
            "continuation.measure=\"force[0]@0\"",
            "unknown measure",
        ),
    ] {
        let err = Problem::from_str_with(text, &[set.to_string()])
            .unwrap_err()
            .to_string();
        assert!(err.contains(says), "{set}: {err}");
    }
}

/// Full-resolution shapes: `continuation.shape_points` positions per point,
/// equally spaced, clamp and tip included — on the buckled elastica the
/// last one is the tip, and neighbours are one chord apart (the rod is
/// inextensible: |Δr| ≤ L/(S − 1), equal on straight stretches).
#[test]
fn shapes_have_the_asked_resolution() {
    let set = ["continuation.shape_points=401".to_string()];
    let problem = Problem::from_str_with(EULER, &set).unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let point = d.branches[1].points.last().unwrap();
    assert_eq!(point.shape.len(), 401);
    assert!((point.shape[400].position - point.tip.position).norm() < 1e-12);
    let h = 1.0 / 400.0;
    for w in point.shape.windows(2) {
        let chord = (w[1].position - w[0].position).norm();
        assert!(chord <= h * (1.0 + 1e-9) && chord > 0.99 * h, "{chord}");
        // Equally spaced in s, and each sample a rod: orthonormal directors.
        assert!((w[1].s - w[0].s - h).abs() < 1e-12, "{}", w[1].s - w[0].s);
        let d = &w[1].directors;
        for (i, j) in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)] {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((d[i].dot(&d[j]) - want).abs() < 1e-8);
        }
    }
    let bad = ["continuation.shape_points=1".to_string()];
    let err = Problem::from_str_with(EULER, &bad).unwrap_err().to_string();
    assert!(err.contains("continuation.shape_points"), "{err}");
}

const CANTILEVER: &str = include_str!("../../../problems/cantilever_tip_load.toml");

/// A continuation in the rod's length keeps each point's shape points on
/// that point's rod (equally spaced on [0, L], the last one the tip) and
/// its tip where an independent solve at that length puts it — for every
/// method. It starts at L = 1.715, where L·20/20 > L in floating point.
/// (L·i/20 once landed an ulp beyond the tip at such lengths, the
/// sampler left that point out, and shape points were paired with the
/// wrong samples: a tip 0.085 off at L = 1.715.)
#[test]
fn a_length_continuation_keeps_each_points_rod() {
    for method in ["shooting", "multiple-shooting", "collocation"] {
        let mut text = CANTILEVER.to_string();
        text.push_str(
            "\n[continuation]\nparameter = \"rod.length\"\nstart = 1.715\nbounds = [1.0, 2.0]\n\
             step = 0.07\nmax_step = 0.07\nelements = 16\neigenvalues = 1\n",
        );
        let set = [format!("solver.method=\"{method}\"")];
        let problem = Problem::from_str_with(&text, &set).unwrap();
        let (family, opts) = problem.continuation.clone().unwrap();
        let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
        let points = &d.branches[0].points;
        assert!(points.len() > 3, "{method}: {} points", points.len());
        for point in points {
            let l = point.parameter;
            let n = point.shape.len();
            assert_eq!(n, 21, "{method} at L = {l}");
            for (i, sample) in point.shape.iter().enumerate() {
                let s = l * i as f64 / (n - 1) as f64;
                assert!(
                    (sample.s - s).abs() < 1e-12 * l,
                    "{method} at L = {l}: s {}",
                    sample.s
                );
            }
            assert!((point.shape[n - 1].position - point.tip.position).norm() < 1e-12);
            let at = Problem::from_str_with(CANTILEVER, &[format!("rod.length={l:e}")]).unwrap();
            let eq = cosserat::bvp::solve(&at.rod, &at.model, &at.options).unwrap();
            let tip = eq.samples.last().unwrap().position;
            let off = (point.tip.position - tip).norm();
            assert!(
                off < 1e-7 * l,
                "{method} at L = {l}: tip {off:e} from the solve"
            );
        }
    }
}
