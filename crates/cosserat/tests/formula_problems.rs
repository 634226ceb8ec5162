//! Validation of energies written as formulas in problem files, against
//! every method (issue 17, item 6):
//!
//! - the linear energy of paper (17) written as a formula reproduces the
//!   built-in linear solution to 1e-12 (a tapered cantilever, in 3-D);
//! - the quartic-stiffening planar cantilever W = ½ B κ² + ¼ C κ⁴ against
//!   an independent reference computed here: a scalar shooting of the
//!   planar equations θ′ = κ(m), m′ = −F cos θ (κ(m) the real root of
//!   Bκ + Cκ³ = m), by classical Runge–Kutta with Richardson extrapolation
//!   and a secant on m(0).

use cosserat::bvp::solve;
use cosserat::input::Problem;

const METHODS: [&str; 3] = ["shooting", "multiple-shooting", "collocation"];

fn tip(text: &str, method: &str) -> nalgebra::Vector3<f64> {
    let set = [
        format!("solver.method=\"{method}\""),
        "solver.tolerance=1e-12".to_owned(),
    ];
    let p = Problem::from_str_with(text, &set).unwrap();
    let eq = solve(&p.rod, &p.model, &p.options).unwrap();
    eq.samples.last().unwrap().position
}

fn tapered(energy: &str) -> String {
    format!(
        "
[rod]
length = 1.0
[energy]
{energy}
stiffness = [{{ polynomial = [2.0, -0.6] }}, {{ polynomial = [1.0, -0.3, 0.1] }}, 1.5]
intrinsic_curvature = [0.2, {{ polynomial = [0.1, 0.5] }}, 0.3]
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [1.5, -0.8, 0.4]
tip_couple = [0.1, 0.2, -0.3]
"
    )
}

#[test]
fn linear_formula_reproduces_the_linear_energy_on_every_method() {
    let linear = tapered(r#"kind = "linear""#);
    let formula = tapered(
        r#"kind = "formula"
density = "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2)""#,
    );
    for method in METHODS {
        let (a, b) = (tip(&linear, method), tip(&formula, method));
        assert!((a - b).amax() < 1e-12, "{method}: {a:?} vs {b:?}");
    }
}

/// κ with B κ + C κ³ = m: the one real root (B, C > 0), by Newton from
/// the smaller of the linear and cubic estimates.
fn curvature(m: f64, b: f64, c: f64) -> f64 {
    let mut k = (m / b).abs().min((m / c).abs().cbrt()) * m.signum();
    for _ in 0..60 {
        let step = (b * k + c * k.powi(3) - m) / (b + 3.0 * c * k * k);
        k -= step;
        if step.abs() <= 1e-16 * k.abs().max(1e-300) {
            break;
        }
    }
    k
}

/// (θ, m, x, z) at s = L from θ(0) = 0, m(0) = m0, by RK4 with n steps.
fn integrate(m0: f64, (b, c, f, l): (f64, f64, f64, f64), n: usize) -> [f64; 4] {
    let rhs = |y: [f64; 4]| {
        [
            curvature(y[1], b, c),
            -f * y[0].cos(),
            y[0].sin(),
            y[0].cos(),
        ]
    };
    let h = l / n as f64;
    let mut y = [0.0, m0, 0.0, 0.0];
    let add = |y: [f64; 4], k: [f64; 4], t: f64| std::array::from_fn(|i| y[i] + t * k[i]);
    for _ in 0..n {
        let k1 = rhs(y);
        let k2 = rhs(add(y, k1, h / 2.0));
        let k3 = rhs(add(y, k2, h / 2.0));
        let k4 = rhs(add(y, k3, h));
        y = std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    y
}

/// The tip (x, z) with m(L) = 0, Richardson-extrapolated from n and 2n
/// steps (RK4: error ∝ h⁴), and the size of that correction.
fn reference_tip(params: (f64, f64, f64, f64)) -> ([f64; 2], f64) {
    let solve_with = |n: usize| {
        let (mut a, mut b) = (0.0, params.2 * params.3);
        let (mut fa, mut fb) = (integrate(a, params, n)[1], integrate(b, params, n)[1]);
        for _ in 0..100 {
            let c = b - fb * (b - a) / (fb - fa);
            (a, fa) = (b, fb);
            b = c;
            fb = integrate(b, params, n)[1];
            if fb.abs() < 1e-15 {
                break;
            }
        }
        let y = integrate(b, params, n);
        [y[2], y[3]]
    };
    let (coarse, fine) = (solve_with(2000), solve_with(4000));
    let extrapolated = [0, 1].map(|i| fine[i] + (fine[i] - coarse[i]) / 15.0);
    let correction = (fine[0] - coarse[0]).abs().max((fine[1] - coarse[1]).abs());
    (extrapolated, correction)
}

/// problems/quartic_formula_cantilever.toml: B2 = 1, C = 0.5, F = 4, L = 1.
#[test]
fn quartic_planar_cantilever_matches_an_independent_shooting() {
    let (b, c, f, l) = (1.0, 0.5, 4.0, 1.0);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../problems/quartic_formula_cantilever.toml"
    ))
    .unwrap();
    let p = Problem::from_str_with(&text, &[]).unwrap();
    assert_eq!(p.model.level.name(), "planar", "{}", p.model.reason);
    let ([x, z], correction) = reference_tip((b, c, f, l));
    assert!(correction < 1e-9, "reference not converged: {correction:e}");
    for method in METHODS {
        let r = tip(&text, method);
        let err = (r[0] - x).abs().max((r[2] - z).abs());
        eprintln!("{method}: tip error {err:.1e} (reference correction {correction:.1e})");
        assert!(
            err < 1e-9,
            "{method}: tip {r:?} vs ({x}, {z}), error {err:e}"
        );
    }
}

/// A softening formula whose Hessian loses definiteness at the loaded
/// curvature: no equilibrium is reported, on any method — either the
/// solver fails, or the solution is refused as a material instability.
#[test]
fn a_material_instability_is_never_reported_as_an_equilibrium() {
    let text = r#"
[rod]
length = 1.0
[energy]
kind = "formula"
density = "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) - k2^4/4"
stiffness = [10.0, 1.0, 10.0]
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [3.0, 0.0, 0.0]
"#;
    for method in METHODS {
        let set = [format!("solver.method=\"{method}\"")];
        let p = Problem::from_str_with(text, &set).unwrap();
        if let Ok(eq) = solve(&p.rod, &p.model, &p.options) {
            let worst = eq
                .samples
                .iter()
                .map(|x| 1.0 - 3.0 * x.curvature[1].powi(2))
                .fold(f64::INFINITY, f64::min);
            panic!("{method}: reported an equilibrium, least H22 = {worst}");
        }
    }
}

/// A formula's parameter is a continuation parameter: the quartic
/// cantilever continued in C = energy.parameters.C, every point's tip
/// against the independent shooting at that C.
#[test]
fn a_formula_parameter_is_continued() {
    let (b, f, l) = (1.0, 4.0, 1.0);
    let text = format!(
        r#"
[rod]
length = {l}
[energy]
kind = "formula"
density = "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) + C/4*(k1^2 + k2^2 + k3^2)^2"
stiffness = [10.0, {b}, 10.0]
parameters = {{ C = 0.2 }}
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [{f}, 0.0, 0.0]
[solver]
tolerance = 1e-12
[continuation]
parameter = "energy.parameters.C"
start = 0.2
bounds = [0.0, 1.5]
step = 0.1
max_step = 0.3
"#
    );
    let p = Problem::from_str_with(&text, &[]).unwrap();
    let (family, opts) = p.continuation.as_ref().unwrap();
    let diagram = cosserat::continuation::continuation(family, opts, &mut |_, _| true).unwrap();
    let points = &diagram.branches[0].points;
    assert!(points.len() >= 5 && (points.last().unwrap().parameter - 1.5).abs() < 1e-12);
    for pt in points {
        let ([x, z], _) = reference_tip((b, pt.parameter, f, l));
        let err = (pt.tip.position[0] - x)
            .abs()
            .max((pt.tip.position[2] - z).abs());
        assert!(err < 1e-8, "C = {}: tip error {err:e}", pt.parameter);
    }
}

/// A tapered cantilever (B2 = 1 − 0.6 s) written as a formula: as F → 0
/// the tip deflection per unit load tends to the Euler–Bernoulli value
/// w = ∫₀ᴸ (L − s)²/B(s) ds = ∫₀¹ (1 − s)²/(1 − 0.6 s) ds (closed form,
/// evaluated below), with an error of order F² (x/F is even in F); the
/// order is measured on every method and the Richardson-extrapolated
/// limit matches w.
#[test]
fn tapered_cantilever_tends_to_the_linear_theory_at_second_order() {
    // ∫₀¹ (1 − s)²/(1 − c s) ds with u = 1 − c s: closed form.
    let c: f64 = 0.6;
    let w = {
        // (1 − s) = (u − 1 + c)/c, ds = −du/c, u from 1 to 1 − c.
        let d = c - 1.0;
        let f = |u: f64| (u * u / 2.0 + 2.0 * d * u + d * d * u.ln()) / c.powi(3);
        f(1.0) - f(1.0 - c)
    };
    let text = |force: f64, method: &str| {
        format!(
            "[rod]\nlength = 1.0\n[energy]\nkind = \"formula\"\n\
             density = \"0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2)\"\n\
             stiffness = [10.0, {{ polynomial = [1.0, -0.6] }}, 10.0]\n\
             [clamp]\nd1 = [1.0, 0.0, 0.0]\nd3 = [0.0, 0.0, 1.0]\n\
             [loads]\ntip_force = [{force}, 0.0, 0.0]\n\
             [solver]\nmethod = \"{method}\"\ntolerance = 1e-13\n"
        )
    };
    for method in METHODS {
        let per_load = |f: f64| {
            let p = Problem::from_str_with(&text(f, method), &[]).unwrap();
            solve(&p.rod, &p.model, &p.options)
                .unwrap()
                .samples
                .last()
                .unwrap()
                .position[0]
                / f
        };
        let r: Vec<f64> = [0.04, 0.02, 0.01].iter().map(|&f| per_load(f)).collect();
        let order = ((r[0] - r[1]) / (r[1] - r[2])).log2();
        let limit = r[2] + (r[2] - r[1]) / 3.0;
        eprintln!("{method}: order {order:.3}, limit {limit:.12} vs w = {w:.12}");
        assert!((order - 2.0).abs() < 0.05, "{method}: order {order}");
        assert!((limit - w).abs() < 1e-8 * w, "{method}: {limit} vs {w}");
    }
}

/// The quartic formula cantilever continued in its length: a uniform
/// formula energy gets the exact ∂F/∂p of a length change, and every
/// point's tip matches the independent shooting at that length.
#[test]
fn a_formula_rod_is_continued_in_its_length_with_an_exact_derivative() {
    use cosserat::continuation::DerivativeMethod;
    let (b, c, f) = (1.0, 0.5, 4.0);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../problems/quartic_formula_cantilever.toml"
    ))
    .unwrap();
    let set = [
        "continuation.parameter=\"rod.length\"".to_owned(),
        "continuation.start=1.0".to_owned(),
        "continuation.bounds=[0.5, 1.4]".to_owned(),
        "continuation.measures=[]".to_owned(),
        "solver.tolerance=1e-12".to_owned(),
    ];
    let p = Problem::from_str_with(&text, &set).unwrap();
    let (family, opts) = p.continuation.as_ref().unwrap();
    assert_eq!(
        family.derivative_method(1.0).unwrap(),
        DerivativeMethod::Exact
    );
    let diagram = cosserat::continuation::continuation(family, opts, &mut |_, _| true).unwrap();
    let points = &diagram.branches[0].points;
    assert!(points.len() >= 3);
    for pt in points {
        let ([x, z], _) = reference_tip((b, c, f, pt.parameter));
        let err = (pt.tip.position[0] - x)
            .abs()
            .max((pt.tip.position[2] - z).abs());
        assert!(err < 1e-8, "L = {}: tip error {err:e}", pt.parameter);
    }
}

/// A formula in the shear-extension strains equal to the quadratic part
/// that `energy.shear` adds, ½ (ν − e3)ᵀ diag(S) (ν − e3), reproduces the
/// `energy.shear` solution (the explicit ν = e3 + S⁻¹N of the fast path)
/// through the general path (ν from W_ν = N by Newton), tapered and
/// curved, in 3-D, on every method.
#[test]
// Six solves on the general path: a second in release, long in debug.
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn shear_formula_reproduces_energy_shear_on_every_method() {
    let quadratic = tapered(
        r#"kind = "linear"
shear = [10.0, 20.0, 30.0]"#,
    );
    let formula = tapered(
        r#"kind = "formula"
density = "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) + 0.5*(S1*v1^2 + S2*v2^2 + S3*(v3 - 1)^2)"
parameters = { S1 = 10.0, S2 = 20.0, S3 = 30.0 }"#,
    );
    for method in METHODS {
        let (a, b) = (tip(&quadratic, method), tip(&formula, method));
        assert!((a - b).amax() < 1e-12, "{method}: {a:?} vs {b:?}");
    }
}

/// A stiffening axial law as a formula, φ(e) = ½ EA e² + ¼ c e⁴ in
/// e = v3 − 1, under tension P: the tip moves to L (1 + e) with e the
/// real root of c e³ + EA e = P (Cardano), on every method.
#[test]
fn stiffening_axial_formula_stretches_as_its_closed_form() {
    let (ea, c, p): (f64, f64, f64) = (4.0, 30.0, 6.0);
    let (pp, q) = (ea / c, -p / c);
    let disc = (q / 2.0).powi(2) + (pp / 3.0).powi(3);
    let e = (-q / 2.0 + disc.sqrt()).cbrt() + (-q / 2.0 - disc.sqrt()).cbrt();
    let text = format!(
        r#"
[rod]
length = 1.0
[energy]
kind = "formula"
density = "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) + 2.5*(v1^2 + v2^2) + 0.5*EA*(v3 - 1)^2 + 0.25*c*(v3 - 1)^4"
parameters = {{ EA = {ea}, c = {c} }}
stiffness = [1.0, 1.0, 2.0]
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [0.0, 0.0, {p}]
"#
    );
    for method in METHODS {
        let t = tip(&text, method);
        assert!(
            (t[2] - (1.0 + e)).abs() < 1e-10 && t.xy().norm() < 1e-12,
            "{method}: {t:?} vs 1 + {e}"
        );
    }
}

/// `energy.shear` beside a formula that reads v1..v3 would count the
/// shear energy twice: refused, naming the key.
#[test]
fn energy_shear_beside_a_formula_in_v_is_refused() {
    let text = tapered(
        r#"kind = "formula"
density = "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) + 5*(v1^2 + v2^2 + (v3 - 1)^2)"
shear = [10.0, 20.0, 30.0]"#,
    );
    let err = Problem::from_str_with(&text, &[]).unwrap_err();
    assert!(err.to_string().contains("energy.shear"), "{err}");
}
