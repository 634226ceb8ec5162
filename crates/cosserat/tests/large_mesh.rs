//! Stability on meshes far finer than the integrator's step budget (issue
//! 18): sampling an equilibrium at 3·10⁵ quadrature points once landed
//! one DOP853 step on each and failed with "more than 100000 steps". The
//! samples now come from the continuous extension. Checked against
//! Timoshenko's lateral–torsional buckling load 2 j (j the first zero of
//! J₋₁/₄, `references::evaluate("timoshenko_ltb")`) and the classical
//! Euler load π²/4 of the shipped cantilever column.

use std::collections::BTreeMap;
use std::path::Path;

use cosserat::bvp::solve;
use cosserat::input::Problem;
use cosserat::references::evaluate;
use cosserat::stability::{analyze, critical_load, FiniteElements, StabilityOptions};

/// The shipped problem `name` (problems/<name>.toml).
fn shipped(name: &str) -> Problem {
    let path = format!(
        "{}/problems/{name}.toml",
        concat!(env!("CARGO_MANIFEST_DIR"), "/../..")
    );
    Problem::from_path(Path::new(&path), &[]).unwrap()
}

/// A mesh with more quadrature points (3 per element at order 2) than the
/// 100 000 steps of the default integration budget; smaller in debug builds
/// but still above it.
fn large_mesh() -> usize {
    if cfg!(debug_assertions) {
        40_000
    } else {
        100_000
    }
}

/// γ_cr of the Timoshenko problem's fixed shape on `elements` elements.
fn timoshenko_gamma(problem: &Problem, elements: usize) -> f64 {
    let opts = problem.stability.with_elements(elements).unwrap();
    critical_load(&problem.rod, problem.shape.as_ref().unwrap(), &opts)
        .unwrap()
        .gamma
        .unwrap()
}

/// The fixed-shape critical load on a large mesh succeeds and agrees with
/// 2 j; on coarse meshes the error falls at the measured order ≈ 2p = 4 of
/// Lagrange elements of order p = 2 (not a number taken from the code).
#[test]
fn timoshenko_load_converges_and_survives_a_large_mesh() {
    let problem = shipped("timoshenko_ltb");
    assert_eq!(problem.stability.order(), 2);
    let exact = evaluate("timoshenko_ltb", &BTreeMap::new()).unwrap();
    let errors: Vec<f64> = [4, 8, 16]
        .iter()
        .map(|&n| (timoshenko_gamma(&problem, n) - exact).abs())
        .collect();
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(
            (3.5..4.5).contains(&order),
            "measured order {order} from errors {errors:?}"
        );
    }
    let large = timoshenko_gamma(&problem, large_mesh());
    let relative = (large - exact).abs() / exact;
    // The discretization error at 10⁵ elements is ~1e-20; what remains is
    // round-off, ε N from the factored forms (stability::factored), where
    // the assembled matrices' ε N² made it 4e-6.
    assert!(
        relative < 1e-8,
        "γ_cr on {} elements: {large} against {exact} ({relative:e})",
        large_mesh()
    );
}

/// The round-off of λ1 does not grow like N² (issue 18): Timoshenko's γ_cr
/// on 10⁴ and 10⁵ elements agree to 1e-8 (it drifted 4e-6 when read from
/// the assembled K0, whose rounding is ε N² relative), and the cantilever
/// column's lowest eigenvalue, a smooth mode, to 1e-8 as well. Both meshes
/// are far past the discretization error (order 4: below 1e-15 at 10⁴),
/// so any difference is round-off. Release only: ~3 s there.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn lowest_eigenvalue_does_not_drift_with_the_mesh() {
    let problem = shipped("timoshenko_ltb");
    let exact = evaluate("timoshenko_ltb", &BTreeMap::new()).unwrap();
    let (coarse, fine) = (
        timoshenko_gamma(&problem, 10_000),
        timoshenko_gamma(&problem, 100_000),
    );
    assert!(
        (coarse - fine).abs() <= 1e-8 * exact,
        "γ_cr {coarse} on 10⁴ elements against {fine} on 10⁵"
    );
    let problem = shipped("cantilever_tip_load");
    let eq = solve(&problem.rod, &problem.model, &problem.options).unwrap();
    let lowest = |elements: usize| {
        let opts = problem.stability.with_elements(elements).unwrap();
        let st = analyze(&problem.rod, &eq, &problem.options, &opts).unwrap();
        st.blocks[0].eigenvalues[0]
    };
    let (coarse, fine) = (lowest(10_000), lowest(100_000));
    assert!(
        (coarse - fine).abs() <= 1e-8 * coarse.abs(),
        "λ1 {coarse} on 10⁴ elements against {fine} on 10⁵"
    );
}

/// Sampling the shipped cantilever's equilibrium at the quadrature points
/// of a large mesh (what failed): every point served, the last one the
/// solve's own tip; in release builds the whole analysis on that mesh too,
/// with the same Morse index and lowest eigenvalues as the problem's own
/// mesh, to that mesh's discretization error plus round-off (debug builds
/// skip the eigen solve, ~1 min there).
#[test]
fn equilibrium_stability_survives_a_large_mesh() {
    let problem = shipped("cantilever_tip_load");
    let eq = solve(&problem.rod, &problem.model, &problem.options).unwrap();
    let opts: StabilityOptions = problem.stability.with_elements(large_mesh()).unwrap();
    let fe = FiniteElements::new(problem.rod.length(), opts.elements(), opts.order());
    let mut points = fe.quadrature_points();
    points.push(problem.rod.length());
    assert!(points.len() > 100_000, "{} points", points.len());
    let samples = eq
        .resample(&problem.rod, &problem.options, &points)
        .unwrap();
    assert_eq!(samples.len(), points.len());
    let tip = samples.last().unwrap();
    assert!((tip.position - eq.tip().position).norm() < 1e-10);
    if cfg!(debug_assertions) {
        return;
    }
    let coarse = analyze(&problem.rod, &eq, &problem.options, &problem.stability).unwrap();
    let fine = analyze(&problem.rod, &eq, &problem.options, &opts).unwrap();
    assert_eq!(fine.morse_index, coarse.morse_index);
    for (a, b) in coarse.blocks.iter().zip(&fine.blocks) {
        let (a, b) = (a.eigenvalues[0], b.eigenvalues[0]);
        assert!(
            (a - b).abs() <= 1e-5 * a.abs(),
            "λ1 {a} (coarse) against {b}"
        );
    }
}
