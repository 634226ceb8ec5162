//! The closed forms of `cosserat::references` (the one copy the validation
//! runner and the tests share) against published values and limits.
mod support;
use cosserat::references::{
    bessel_first_zero, clamped_elastica_load, ellip_e, ellip_f, greenhill_clamped,
    haringx_clamped_second, haringx_load, twisted_clamped_moment, CantileverTip,
};

#[test]
fn complete_integrals_match_tabulated_values() {
    // K(k = sin 45°) and E(k = sin 45°), i.e. parameter m = 1/2:
    // Abramowitz & Stegun Table 17.1, DLMF 19.6.2 / 19.20.
    let k = std::f64::consts::FRAC_1_SQRT_2;
    let half_pi = std::f64::consts::FRAC_PI_2;
    assert!((ellip_f(half_pi, k) - 1.854_074_677_301_372).abs() < 1e-14);
    assert!((ellip_e(half_pi, k) - 1.350_643_881_047_675).abs() < 1e-14);
}

#[test]
fn cantilever_reference_small_load_limit() {
    // Linear beam theory: deflection kL/3 for k → 0.
    let t = CantileverTip::at(1e-4);
    assert!((t.x / 1e-4 - 1.0 / 3.0).abs() < 1e-4);
    assert!((t.z - 1.0).abs() < 1e-7);
}

#[test]
fn cantilever_reference_matches_mattiasson_table() {
    // Mattiasson (1981), Table 1: k = 1: tip deflection 0.30172, horizontal
    // displacement 0.05643 (so z = 0.94357), tip rotation 0.46135.
    let t = CantileverTip::at(1.0);
    assert!((t.x - 0.30172).abs() < 1e-5, "x {}", t.x);
    assert!((1.0 - t.z - 0.05643).abs() < 1e-5, "z {}", t.z);
    assert!((t.angle - 0.46135).abs() < 1e-5, "angle {}", t.angle);
}

#[test]
fn bessel_zeros_match_tabulated_values() {
    // j_{0,1} = 2.404825557695773 and j_{1,1} = 3.831705970207512
    // (Abramowitz & Stegun Table 9.5; DLMF 10.21).
    assert!((bessel_first_zero(0.0, 1.0, 3.0) - 2.404_825_557_695_773).abs() < 1e-13);
    assert!((bessel_first_zero(1.0, 3.0, 4.5) - 3.831_705_970_207_512).abs() < 1e-13);
}

#[test]
fn column_references_match_their_classical_limits() {
    use support::columns::clamped_pinned;
    // tan x = x: x = 4.493409457909064 (A&S Table 4.19).
    assert!((clamped_pinned() - 4.493_409_457_909_064f64.powi(2)).abs() < 1e-12);
    // No torque: the clamped–guided column, 4π² B/L².
    let p = greenhill_clamped(0.0);
    assert!((p - 4.0 * std::f64::consts::PI.powi(2)).abs() < 1e-9, "{p}");
    // The torque lowers the thrust, to none at Greenhill's torque for
    // clamped ends, tan(ML/2B) = ML/2B: M L/B = 2 × 4.4934 = 2.861π
    // (Greenhill 1883; Ziegler, Principles of Structural Stability, Sec. 2.7).
    assert!(greenhill_clamped(5.0) < greenhill_clamped(2.0));
    let (near, nearer) = (greenhill_clamped(8.95), greenhill_clamped(8.98));
    let vanishes_at = 8.98 + nearer * 0.03 / (near - nearer);
    let greenhill = 2.0 * 4.493_409_457_909_064;
    assert!((vanishes_at - greenhill).abs() < 2e-3, "{vanishes_at}");
}

/// The twisted clamped rod: 2x₁ with x₁ = 4.493409457909064 (tan x = x,
/// tabulated in Abramowitz & Stegun Table 4.19); the P = 0 end of the
/// independent Greenhill determinant is checked against the same value in
/// `column_references_match_their_classical_limits`.
#[test]
fn twisted_rod_reference_is_twice_the_root_of_tan_x_equals_x() {
    let m = twisted_clamped_moment();
    assert!((m - 2.0 * 4.493_409_457_909_064).abs() < 1e-13, "{m}");
}

/// Haringx's loads: Euler's as the shear and extension stiffnesses grow
/// (at order 1 in 1/S), Haringx's own shear-only form
/// (S/2)(√(1 + 4P_E/S) − 1) without extension (Bažant & Cedolin §1.7),
/// and the clamped column's second mode tends to 4x₁² (x₁ = 4.4934…, tan
/// x = x: the inextensible clamped–clamped column's antisymmetric mode,
/// Timoshenko & Gere §2.5).
#[test]
fn haringx_references_match_their_classical_limits() {
    let euler = 4.0 * std::f64::consts::PI.powi(2);
    let shear_only = 0.5 * 400.0 * ((1.0 + 4.0 * euler / 400.0).sqrt() - 1.0);
    assert!((haringx_load(euler, 400.0, f64::INFINITY) - shear_only).abs() < 1e-12 * euler);
    assert_eq!(haringx_load(euler, 500.0, 500.0), euler);
    let second = 4.0 * 4.493_409_457_909_064_f64.powi(2);
    let errors: Vec<f64> = [1e4, 1e5, 1e6]
        .iter()
        .map(|&s| (haringx_clamped_second(1.0, s, 2.0 * s, 1.0) - second).abs())
        .collect();
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log10();
        assert!((order - 1.0).abs() < 0.05, "{errors:?}");
    }
    assert!(errors[2] < 1e-3 * second, "{errors:?}");
}

/// The clamped–clamped elastica: at small shortening the load tends to
/// Euler's 4π² with the classical post-buckling slope, P ≈ 4π²(1 + δ/2)
/// (δ = k² + O(k⁴) and 16K² = 4π²(1 + k²/2 + O(k⁴))), and it grows with
/// the shortening.
#[test]
fn clamped_elastica_reference_starts_at_euler_with_its_slope() {
    let euler = 4.0 * std::f64::consts::PI.powi(2);
    for delta in [1e-4, 1e-3] {
        let p = clamped_elastica_load(delta);
        let slope = (p / euler - 1.0) / delta;
        assert!(
            (slope - 0.5).abs() < 2.0 * delta,
            "δ = {delta}: slope {slope}"
        );
    }
    assert!(clamped_elastica_load(0.2) > clamped_elastica_load(0.1));
}

/// The shallow arch's references agree with each other where both hold:
/// the elastica's fold over Θ approaches the inextensible shallow-arch
/// limit as Θ → 0 (within 1e-3 at Θ = 0.02, where the O(Θ²) gap is 1e-4),
/// and the Richardson correction of the elastica is far below 1e-10.
#[test]
fn arch_elastica_tends_to_the_shallow_arch_limit() {
    let limit = cosserat::references::shallow_arch_fold();
    assert!((limit - 7.415_43).abs() < 1e-5, "{limit}");
    let theta = 0.02;
    let folds = cosserat::references::arch_elastica_folds(theta).unwrap();
    assert!(folds.correction < 1e-11, "{}", folds.correction);
    let q = folds.loads[0] / theta;
    assert!((q - limit).abs() < 1e-3 * limit, "{q} vs {limit}");
    assert!(
        folds.loads[1] < folds.loads[0],
        "the restabilization below the snap"
    );
}
