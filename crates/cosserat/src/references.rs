//! Closed-form references of the validation cases, evaluated here from
//! their formulas — independently of the solvers under test (nothing in
//! this file calls into `bvp`, `stability` or `continuation`).
//!
//! Elliptic integrals: Carlson's symmetric forms R_F, R_D by the
//! duplication algorithm (DLMF 19.36.i; Carlson, Numer. Algorithms 10,
//! 1995), Legendre's F, E through DLMF 19.25.5 and 19.25.9. Bessel zeros:
//! bisection on the power series of J_ν (DLMF 10.2.2). The snap-through of
//! the shallow arch and of the buckled strip (`arch`): an independent
//! shooting of the planar elastica, and the inextensible shallow-arch
//! limit.

use std::collections::BTreeMap;
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, PI};

use crate::numerics::scalar::bisect;

mod arch;
pub use arch::{arch_elastica_folds, shallow_arch_fold, strip_elastica_fold, ArchFolds};

/// Carlson's R_F(x, y, z).
pub fn carlson_rf(x: f64, y: f64, z: f64) -> f64 {
    let (mut x, mut y, mut z) = (x, y, z);
    for _ in 0..100 {
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * sy + sy * sz + sz * sx;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        let a = (x + y + z) / 3.0;
        let (dx, dy, dz) = (1.0 - x / a, 1.0 - y / a, 1.0 - z / a);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-4 {
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0)
                / a.sqrt();
        }
    }
    f64::NAN
}

/// Carlson's R_D(x, y, z).
pub fn carlson_rd(x: f64, y: f64, z: f64) -> f64 {
    let (mut x, mut y, mut z) = (x, y, z);
    let (mut sum, mut fac) = (0.0, 1.0);
    for _ in 0..100 {
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * sy + sy * sz + sz * sx;
        sum += fac / (sz * (z + lam));
        fac *= 0.25;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        let a = (x + y + 3.0 * z) / 5.0;
        let (dx, dy, dz) = (1.0 - x / a, 1.0 - y / a, 1.0 - z / a);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-4 {
            let ea = dx * dy;
            let eb = dz * dz;
            let ec = ea - eb;
            let ed = ea - 6.0 * eb;
            let ee = ed + ec + ec;
            let series = 1.0
                + ed * (-3.0 / 14.0 + 9.0 / 88.0 * ed - 4.5 / 26.0 * dz * ee)
                + dz * (ee / 6.0 + dz * (-9.0 / 22.0 * ec + dz * 3.0 / 26.0 * ea));
            return 3.0 * sum + fac * series / (a * a.sqrt());
        }
    }
    f64::NAN
}

/// F(φ, k) = ∫_0^φ dθ / √(1 − k² sin²θ), 0 ≤ φ ≤ π/2.
pub fn ellip_f(phi: f64, k: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    s * carlson_rf(c * c, 1.0 - (k * s).powi(2), 1.0)
}

/// E(φ, k) = ∫_0^φ √(1 − k² sin²θ) dθ, 0 ≤ φ ≤ π/2.
pub fn ellip_e(phi: f64, k: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let q = 1.0 - (k * s).powi(2);
    s * carlson_rf(c * c, q, 1.0) - (k * k) * s.powi(3) * carlson_rd(c * c, q, 1.0) / 3.0
}

/// The first positive zero of J_ν in (lo, hi), from the reduced power
/// series S(x) = Σ_m (−x²/4)^m / (m! (ν + 1)_m), whose zeros for x > 0 are
/// those of J_ν.
pub fn bessel_first_zero(nu: f64, lo: f64, hi: f64) -> f64 {
    let series = |x: f64| {
        let q = -x * x / 4.0;
        let (mut term, mut sum) = (1.0, 1.0);
        for m in 1..200 {
            term *= q / (f64::from(m) * (nu + f64::from(m)));
            sum += term;
            if term.abs() < 1e-18 * sum.abs().max(1e-300) {
                break;
            }
        }
        sum
    };
    let fa = series(lo);
    if fa * series(hi) >= 0.0 {
        return f64::NAN;
    }
    let (a, b) = bisect(lo, hi, 200, |m| series(m) * fa > 0.0, |_, _| false);
    0.5 * (a + b)
}

/// Tip of the planar cantilever of unit length under a tip force
/// perpendicular to the clamp's tangent, k = F L²/B (Bisshopp & Drucker,
/// Q. Appl. Math. 3, 1945): with the tip angle φ0, p² = (1 + sin φ0)/2 and
/// sin θ0 = 1/(p√2), √k = K(p) − F(θ0, p); the deflection along the force
/// is 1 − 2 (E(p) − E(θ0, p))/√k and the projection on the clamp's tangent
/// √(2 sin φ0 / k). Returns (deflection, projection, tip angle).
pub fn cantilever_tip(k: f64) -> (f64, f64, f64) {
    let sqrt_k = k.sqrt();
    let lhs = |p: f64| {
        let theta0 = (1.0 / (p * 2f64.sqrt())).asin();
        ellip_f(FRAC_PI_2, p) - ellip_f(theta0, p)
    };
    let (lo, hi) = bisect(FRAC_1_SQRT_2, 1.0, 200, |m| lhs(m) < sqrt_k, |_, _| false);
    let p = 0.5 * (lo + hi);
    let theta0 = (1.0 / (p * 2f64.sqrt())).asin();
    let sin_phi0 = 2.0 * p * p - 1.0;
    (
        1.0 - 2.0 * (ellip_e(FRAC_PI_2, p) - ellip_e(theta0, p)) / sqrt_k,
        (2.0 * sin_phi0 / k).sqrt(),
        sin_phi0.asin(),
    )
}

/// The cantilever's tip of [`cantilever_tip`] with named fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CantileverTip {
    /// Deflection along the force.
    pub x: f64,
    /// Coordinate along the clamp's tangent.
    pub z: f64,
    /// Tip angle φ0 from the clamp's tangent.
    pub angle: f64,
}

impl CantileverTip {
    /// The tip at k = F L²/B (see [`cantilever_tip`]).
    pub fn at(k: f64) -> Self {
        let (x, z, angle) = cantilever_tip(k);
        Self { x, z, angle }
    }
}

/// The formulas a case file can name, with their parameters and their
/// source; every length is for L = 1, every load is F L²/B.
pub const FORMULAS: &[(&str, &str, &str)] = &[
    (
        "upward_reach_limit",
        "",
        "Rb = π/2: the tallest straight column under a top load, √(π²/4) (paper eq. (2))",
    ),
    (
        "cantilever_tip_x",
        "k",
        "deflection 1 − 2(E(p) − E(θ0, p))/√k (Bisshopp & Drucker 1945)",
    ),
    (
        "cantilever_tip_z",
        "k",
        "projection √(2 sin φ0 / k) (Bisshopp & Drucker 1945)",
    ),
    (
        "cantilever_tip_angle",
        "k",
        "tip angle φ0, √k = K(p) − F(θ0, p), p² = (1 + sin φ0)/2 (Bisshopp & Drucker 1945)",
    ),
    ("euler_clamped_free", "", "F L²/B = π²/4 (Euler 1744)"),
    (
        "deflection_span",
        "tilt",
        "|z|√(F/B) = ∫_0^{π−ε} cos(θ/2) dθ = 2 cos(ε/2): the elastica from a clamp tilted ε from \
         the vertical to the hanging tail (L → ∞); ε → 0 gives Rdef = 2 (paper eq. (3))",
    ),
    (
        "clamped_guided",
        "",
        "F L²/B = 4π²: a column clamped at both ends, one sliding (Timoshenko & Gere 1961, Sec. 2.3)",
    ),
    (
        "greenhill_clamped",
        "twist",
        "smallest P L²/B with a nontrivial w of B w'''' − i M w''' + P w'' = 0, w = w' = 0 at both \
         ends (Greenhill 1883; Ziegler 1968, Sec. 2.7), M L/B = twist",
    ),
    (
        "elastica_column_load",
        "alpha_deg",
        "F L²/B = K(sin(α/2))² (clamped–free elastica)",
    ),
    (
        "elastica_column_tip_deflection",
        "alpha_deg",
        "δ/L = 2 sin(α/2)/K(sin(α/2))",
    ),
    (
        "elastica_column_tip_axial",
        "alpha_deg",
        "z(L)/L = 2E(sin(α/2))/K(sin(α/2)) − 1",
    ),
    (
        "elastica_column_tip_angle",
        "alpha_deg",
        "the tip angle α itself",
    ),
    (
        "circle_tip_x",
        "m",
        "(1 − cos m)/m: a circular arc of curvature m = M L/B",
    ),
    (
        "circle_tip_z",
        "m",
        "sin m / m: a circular arc of curvature m = M L/B",
    ),
    (
        "circle_tip_angle",
        "m",
        "the tip angle m, wrapped to (−π, π]",
    ),
    ("circle_chord", "m", "|r(L) − r(0)| = 2|sin(m/2)|/m"),
    (
        "coupled_circle_couple",
        "m, c, s3",
        "the end couple M = m (B2 − c²/S3) (L = B2 = 1) that bends W = ½B2κ2² + ½S3(ν3 − 1)² + \
         cκ2(ν3 − 1) into a circle of turn m: N = 0 gives ν3 − 1 = −cκ2/S3",
    ),
    (
        "coupled_circle_tip_x",
        "m, c, s3",
        "(1 − c m/S3)(1 − cos m)/m: the circle of turn m stretched by ν3 = 1 − c m/S3",
    ),
    (
        "coupled_circle_tip_z",
        "m, c, s3",
        "(1 − c m/S3) sin m / m: the circle of turn m stretched by ν3 = 1 − c m/S3",
    ),
    (
        "stiffening_stretch",
        "tension, ea, stiff",
        "L(1 + e), e the real root of stiff e³ + ea e = tension (Cardano): a straight rod under \
         tension with the axial law φ(e) = ½ ea e² + ¼ stiff e⁴",
    ),
    (
        "none",
        "",
        "no such value exists (e.g. no static critical load): the reference is `none`",
    ),
    (
        "twisted_clamped_moment",
        "",
        "M L/B = 2x₁, tan x₁ = x₁: a rod twisted between two clamps at a fixed distance \
         (Love, Treatise §272)",
    ),
    (
        "clamped_elastica_load",
        "shortening",
        "P L²/B = 16K(k)², δ/L = 2(1 − E(k)/K(k)): the clamped–clamped elastica under end \
         shortening δ (Love, Treatise §263)",
    ),
    (
        "timoshenko_ltb",
        "",
        "F L²/√(B1 B3) = 2 j₋₁/₄,₁ (Timoshenko & Gere 1961, Sec. 6.3)",
    ),
    (
        "timoshenko_chi",
        "",
        "χ = √(2 j₋₁/₄,₁), the paper's eq. (1): L ≤ χ (B1 B3)^¼ / F^½",
    ),
];

fn param(params: &BTreeMap<String, f64>, name: &str, formula: &str) -> Result<f64, String> {
    params
        .get(name)
        .copied()
        .ok_or_else(|| format!("formula `{formula}` needs the parameter `{name}`"))
}

/// Greenhill's twisted column with clamped ends (B = L = 1, torque τ): the
/// lateral deflection w = a + b s + c e^{i k1 s} + d e^{i k2 s},
/// k = (τ ± √(τ² + 4P))/2, meets w(0) = w'(0) = w(1) = w'(1) = 0 where the
/// 4 × 4 determinant vanishes; det · e^{−iτ/2} is imaginary, and its
/// imaginary part is scanned from P = 0.01 and bisected.
pub fn greenhill_clamped(tau: f64) -> f64 {
    use nalgebra::{Complex, Matrix4};
    let f = |p: f64| {
        let r = (tau * tau + 4.0 * p).sqrt();
        let (k1, k2) = (f64::midpoint(tau, r), (tau - r) / 2.0);
        let i = Complex::new(0.0, 1.0);
        let (one, zero) = (Complex::new(1.0, 0.0), Complex::new(0.0, 0.0));
        let (e1, e2) = ((i * k1).exp(), (i * k2).exp());
        let a = Matrix4::new(
            one,
            zero,
            one,
            one, //
            zero,
            one,
            i * k1,
            i * k2, //
            one,
            one,
            e1,
            e2, //
            zero,
            one,
            i * k1 * e1,
            i * k2 * e2,
        );
        (a.determinant() * (-i * tau / 2.0).exp()).im
    };
    let step = 0.01;
    let mut lo = step;
    while f(lo) * f(lo + step) > 0.0 && lo < 100.0 {
        lo += step;
    }
    // The sign test is against f at the bracket's current lower end.
    let mut below = lo;
    let keep_upper = |mid: f64| {
        let lower = f(below) * f(mid) <= 0.0;
        if !lower {
            below = mid;
        }
        !lower
    };
    let (lo, hi) = bisect(lo, lo + step, 200, keep_upper, |_, _| false);
    0.5 * (lo + hi)
}

/// The critical thrust of a shearable, extensible column (Haringx 1948;
/// Bažant & Cedolin, *Stability of Structures*, §1.7, in the form of the
/// linear Cosserat rod's second variation, docs/methods.md): the least
/// positive P with P (1 − P/S3) + P²/S = P_E, where P_E = B k² is the
/// Euler load of the same mode (k its wavenumber: π/2L clamped–free,
/// 2π/L clamped–clamped), S the shear stiffness across the bending plane
/// and S3 the extensional one. Written 2P_E / (1 + √(1 + 4aP_E)),
/// a = 1/S − 1/S3, with no cancellation as a → 0 (P → P_E).
pub fn haringx_load(euler: f64, shear: f64, extension: f64) -> f64 {
    let a = 1.0 / shear - 1.0 / extension;
    2.0 * euler / (1.0 + (1.0 + 4.0 * a * euler).sqrt())
}

/// The second critical thrust of a shearable, extensible column clamped
/// at both ends a fixed distance apart (the mode whose deflection is odd
/// about the middle, B = L = 1 scaled out by the caller): with
/// μ = P(1 − P/S3) + P²/S the Haringx load of the mode, the rotation
/// ω = C cos kξ + c/μ (ξ from the middle, k² = μ/B) vanishes at both ends,
/// and the lateral tip displacement (1 − P/S3 + P/S)∫ω ds, which the
/// clamped end does not allow, is taken up by shear across the rod: a
/// spring of stiffness K = S(1 − P/S3 + P/S)²/L on ∫ω (the held
/// position on a Cosserat rod, docs/methods.md). Its condition is
/// tan x = x (1 − μ/(K L)), x = kL/2; as S, S3 → ∞ it is tan x = x,
/// P = 4x₁²B/L² (x₁ = 4.4934). The least root above the first mode's
/// [`haringx_load`] (2π/L), by a scan and bisection on
/// sin x − x(1 − μ/(KL)) cos x.
pub fn haringx_clamped_second(bending: f64, shear: f64, extension: f64, length: f64) -> f64 {
    let condition = |p: f64| {
        let mu = p * (1.0 - p / extension) + p * p / shear;
        let k = shear * (1.0 - p / extension + p / shear).powi(2) / length;
        let x = 0.5 * length * (mu / bending).sqrt();
        x.sin() - x * (1.0 - mu / (k * length)) * x.cos()
    };
    let first = haringx_load(
        bending * (2.0 * std::f64::consts::PI / length).powi(2),
        shear,
        extension,
    );
    let step = 1e-3 * first;
    let mut lo = first * (1.0 + 1e-9);
    while condition(lo) * condition(lo + step) > 0.0 {
        lo += step;
    }
    let (mut a, mut b) = (lo, lo + step);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if condition(a) * condition(m) <= 0.0 {
            b = m;
        } else {
            a = m;
        }
    }
    0.5 * (a + b)
}

/// The critical end moment of a twisted rod clamped at both ends, the
/// distance between them held and no axial force (B = L = 1): the
/// deflection w = a + b s + c s² + d e^{iMs} of B w'''' − i M w''' = 0 with
/// w = w' = 0 at both ends exists where tan(M/2) = M/2, so M L/B = 2 x₁
/// with x₁ = 4.4934… the first positive root of tan x = x (Love's
/// Treatise §272; the P = 0 end of [`greenhill_clamped`]). The critical
/// end rotation of a rod of torsional stiffness C is θ = M L/C.
pub fn twisted_clamped_moment() -> f64 {
    // tan x = x ⇔ g(x) = sin x − x cos x = 0; g > 0 at π, g < 0 at 3π/2.
    let g = |x: f64| x.sin() - x * x.cos();
    let (lo, hi) = bisect(PI, 1.5 * PI, 200, |m| g(m) > 0.0, |_, _| false);
    lo + hi
}

/// The load of the clamped–clamped elastica whose ends are brought
/// together by the shortening δ (B = L = 1, the symmetric first mode): the
/// rod is four quarter-waves of the elastica θ'' + λ² sin θ = 0 with
/// modulus k = sin(α/2), so λ = 4K(k), P L²/B = 16 K(k)², and the chord
/// 2E(k)/K(k) − 1 gives δ = 2(1 − E(k)/K(k)) (Love's Treatise §263;
/// Timoshenko & Gere, Sec. 2.7). k is found by bisection (δ grows with k).
pub fn clamped_elastica_load(shortening: f64) -> f64 {
    let delta = |k: f64| 2.0 * (1.0 - ellip_e(FRAC_PI_2, k) / ellip_f(FRAC_PI_2, k));
    let (lo, hi) = bisect(
        0.0,
        1.0 - 1e-15,
        200,
        |m| delta(m) < shortening,
        |_, _| false,
    );
    let k = 0.5 * (lo + hi);
    16.0 * ellip_f(FRAC_PI_2, k).powi(2)
}

/// Keller's strongest column (Keller 1960, "The shape of the strongest
/// column", Arch. Rational Mech. Anal. 5, 275–285; Tadjbakhsh & Keller
/// 1962): the clamped–free column of unit length and unit volume, bending
/// stiffness B = A² (similar sections), under a tip thrust. Returns the
/// optimal area A(s) (clamp at s = 0) and, as `KELLER_GAIN`, its critical
/// load over the uniform column's π²/4.
///
/// Derivation. The clamped–free column is half of the pinned–pinned one of
/// length 2 (the clamp at its middle). For the pinned column of length ℓ,
/// deflection w, the load is the Rayleigh quotient P = ∫A²w''² / ∫w'²;
/// stationarity under ∫A = V gives 2A w''² = const·∫w'², and with the
/// moment A²w'' = −Pw this is A ∝ w^{2/3}. The parametric solution
/// x = (ℓ/π)(θ − ½ sin 2θ), w = sin³θ, A = k sin²θ, θ ∈ [0, π], satisfies
/// it: dx/dθ = (2ℓ/π) sin²θ, w'' = −(3π²/4ℓ²)/sin θ, so
/// A²w'' = −(3π²k²/4ℓ²) w, P = 3π²k²/(4ℓ²); the volume ∫A dx =
/// (2kℓ/π)∫sin⁴θ dθ = 3kℓ/4 = V gives k = 4V/(3ℓ) and P = (4/3)π²(V/ℓ)²/ℓ²,
/// 4/3 of the uniform column's π²(V/ℓ)²/ℓ². Half of it (ℓ = 2, V = 2,
/// θ ∈ [0, π/2] from the free end) is the clamped–free column: with
/// u = 1 − s the distance from the free end, u = (2/π)(θ − ½ sin 2θ) and
/// A = (4/3) sin²θ, vanishing at the free end like u^{2/3}. θ(u) by
/// bisection (u grows with θ).
pub fn keller_section(s: f64) -> f64 {
    let u = (1.0 - s).clamp(0.0, 1.0);
    let distance = |t: f64| (2.0 / PI) * (t - 0.5 * (2.0 * t).sin());
    let (lo, hi) = bisect(0.0, FRAC_PI_2, 200, |t| distance(t) < u, |_, _| false);
    let theta = 0.5 * (lo + hi);
    4.0 / 3.0 * theta.sin().powi(2)
}

/// The strongest column's gain over the uniform column of the same volume
/// and length ([`keller_section`]).
pub const KELLER_GAIN: f64 = 4.0 / 3.0;

/// The real root of a x³ + b x = c (a, b > 0: one real root), by
/// Cardano's formula.
pub fn cardano_root(a: f64, b: f64, c: f64) -> f64 {
    let (p, q) = (b / a, -c / a);
    let disc = (q / 2.0).powi(2) + (p / 3.0).powi(3);
    (-q / 2.0 + disc.sqrt()).cbrt() + (-q / 2.0 - disc.sqrt()).cbrt()
}

/// Evaluates the formula `name` with the point's parameters.
pub fn evaluate(name: &str, params: &BTreeMap<String, f64>) -> Result<f64, String> {
    let k = || param(params, "k", name);
    let m = || param(params, "m", name);
    let modulus = || param(params, "alpha_deg", name).map(|a| (a.to_radians() / 2.0).sin());
    let j = || bessel_first_zero(-0.25, 1.0, 3.0);
    Ok(match name {
        "cantilever_tip_x" => cantilever_tip(k()?).0,
        "cantilever_tip_z" => cantilever_tip(k()?).1,
        "cantilever_tip_angle" => cantilever_tip(k()?).2,
        "euler_clamped_free" => PI * PI / 4.0,
        "upward_reach_limit" => PI / 2.0,
        "elastica_column_load" => ellip_f(FRAC_PI_2, modulus()?).powi(2),
        "elastica_column_tip_deflection" => {
            let p = modulus()?;
            2.0 * p / ellip_f(FRAC_PI_2, p)
        }
        "elastica_column_tip_axial" => {
            let p = modulus()?;
            2.0 * ellip_e(FRAC_PI_2, p) / ellip_f(FRAC_PI_2, p) - 1.0
        }
        "elastica_column_tip_angle" => param(params, "alpha_deg", name)?.to_radians(),
        "circle_tip_x" => {
            let m = m()?;
            (1.0 - m.cos()) / m
        }
        "circle_tip_z" => {
            let m = m()?;
            m.sin() / m
        }
        "circle_tip_angle" => {
            let m = m()?;
            m.sin().atan2(m.cos())
        }
        "circle_chord" => {
            let m = m()?;
            2.0 * (m / 2.0).sin().abs() / m
        }
        "coupled_circle_couple" | "coupled_circle_tip_x" | "coupled_circle_tip_z" => {
            let (m, c, s3) = (m()?, param(params, "c", name)?, param(params, "s3", name)?);
            let stretch = 1.0 - c * m / s3;
            match name {
                "coupled_circle_couple" => m * (1.0 - c * c / s3),
                "coupled_circle_tip_x" => stretch * (1.0 - m.cos()) / m,
                _ => stretch * m.sin() / m,
            }
        }
        "stiffening_stretch" => {
            let tension = param(params, "tension", name)?;
            let (ea, stiff) = (param(params, "ea", name)?, param(params, "stiff", name)?);
            1.0 + cardano_root(stiff, ea, tension)
        }
        "none" => f64::NAN,
        "greenhill_clamped" => greenhill_clamped(param(params, "twist", name)?),
        "clamped_guided" => 4.0 * PI * PI,
        "deflection_span" => 2.0 * (param(params, "tilt", name)? / 2.0).cos(),
        "timoshenko_ltb" => 2.0 * j(),
        "timoshenko_chi" => (2.0 * j()).sqrt(),
        "twisted_clamped_moment" => twisted_clamped_moment(),
        "clamped_elastica_load" => clamped_elastica_load(param(params, "shortening", name)?),
        other => {
            let known: Vec<&str> = FORMULAS.iter().map(|f| f.0).collect();
            return Err(format!(
                "unknown formula `{other}`; known: {}",
                known.join(", ")
            ));
        }
    })
}

/// The description of a formula, for the report.
pub fn describe(name: &str) -> &'static str {
    FORMULAS.iter().find(|f| f.0 == name).map_or("", |f| f.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // K(1/√2) = Γ(1/4)²/(4√π) (DLMF 19.6.2 / 19.20).
        let k = ellip_f(FRAC_PI_2, FRAC_1_SQRT_2);
        assert!((k - 1.854_074_677_301_372).abs() < 1e-14, "{k}");
        // E(1/√2) = 1.3506438810476755 (A&S Table 17.1; DLMF 19.6.2 / 19.20).
        let e = ellip_e(FRAC_PI_2, FRAC_1_SQRT_2);
        assert!((e - 1.350_643_881_047_675_5).abs() < 1e-14, "{e}");
        // j_{0,1} = 2.404825557695773, j_{1,1} = 3.8317059702075125 (DLMF 10.21,
        // A&S Table 9.5).
        assert!((bessel_first_zero(0.0, 1.0, 3.0) - 2.404_825_557_695_773).abs() < 1e-13);
        assert!((bessel_first_zero(1.0, 3.0, 4.5) - 3.831_705_970_207_512_5).abs() < 1e-13);
        // j₋₁/₄,₁: 2j = 4.0126 (Timoshenko & Gere).
        assert!((2.0 * bessel_first_zero(-0.25, 1.0, 3.0) - 4.0126).abs() < 1e-4);
        // The paper's χ = √(2 j₋₁/₄,₁) ≈ 2.003 (Timoshenko & Gere 1961, Sec. 6.3:
        // F L²/√(B1 B3) = 4.013 for the cantilever under a tip load).
        let chi = evaluate("timoshenko_chi", &BTreeMap::new()).unwrap();
        assert!((chi - 2.003).abs() < 5e-4, "{chi}");
        // The cantilever's small-load limit: x ≈ k/3.
        let (x, _, _) = cantilever_tip(1e-4);
        assert!((x - 1e-4 / 3.0).abs() < 1e-9);
    }
}
