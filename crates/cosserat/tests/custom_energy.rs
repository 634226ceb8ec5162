//! The worked example of a custom energy (examples/custom_energy.rs): its
//! derivatives against central differences, the roll-up under an end couple
//! against its closed form through a problem file that names the energy,
//! and the errors a catalog gives.
mod support;
use support::methods::methods;

#[allow(dead_code)]
#[path = "../examples/custom_energy.rs"]
mod custom_energy;

use std::path::Path;

use cosserat::bvp::{solve, SolverOptions};
use cosserat::input::Problem;
use cosserat::model::{LinearElastic, Profile, StoredEnergy};
use custom_energy::{catalog, HyperbolicStiffening};
use nalgebra::Vector3;

const FILE: &str = concat!(
    concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
    "/crates/cosserat/examples/hyperbolic_roll_up.toml"
);

#[test]
fn derivatives_match_central_differences() {
    let e = HyperbolicStiffening {
        linear: LinearElastic::new(
            [
                Profile::Polynomial(vec![2.0, -0.5]),
                Profile::Constant(1.0),
                Profile::Polynomial(vec![1.5, 0.2]),
            ],
            [
                Profile::Polynomial(vec![0.1, 0.4]),
                Profile::Polynomial(vec![-0.3, 0.0, 1.0]),
                Profile::Constant(0.7),
            ],
        )
        .unwrap(),
        stiffening: 0.8,
    };
    let (s, h) = (0.37, 1e-6);
    let kappa = Vector3::new(0.4, -1.2, 0.9);
    let v = Vector3::new(-0.3, 0.8, 0.5);
    let t = e.stiffness_derivative(s, &kappa, &v);
    for i in 0..3 {
        let ei = Vector3::ith(i, h);
        let dw = (e.density(s, &(kappa + ei)) - e.density(s, &(kappa - ei))) / (2.0 * h);
        assert!((dw - e.moment(s, &kappa)[i]).abs() < 1e-8);
        let dm = (e.moment(s, &(kappa + ei)) - e.moment(s, &(kappa - ei))) / (2.0 * h);
        assert!((dm - e.stiffness(s, &kappa).column(i)).norm() < 1e-7);
        let dhv =
            (e.stiffness(s, &(kappa + ei)) * v - e.stiffness(s, &(kappa - ei)) * v) / (2.0 * h);
        assert!((dhv - t.column(i)).norm() < 1e-7);
    }
    let dms = (e.moment(s + h, &kappa) - e.moment(s - h, &kappa)) / (2.0 * h);
    assert!((dms - e.moment_rate(s, &kappa)).norm() < 1e-7);
    let dhs = (e.stiffness(s + h, &kappa) - e.stiffness(s - h, &kappa)) / (2.0 * h);
    assert!((dhs - e.stiffness_rate(s, &kappa)).norm() < 1e-7);
}

/// Uniform curvature κ = asinh(a C/B)/a: the chord |r(L)| = 2 sin(κL/2)/κ
/// and the tip tangent d3(L)·d3(0) = cos κL.
#[test]
fn roll_up_matches_closed_form_from_the_problem_file() {
    let problem = Problem::from_path_in(Path::new(FILE), &[], &catalog()).unwrap();
    assert_eq!(problem.rod.energy().name(), "hyperbolic");
    let (a, c): (f64, f64) = (0.5, 4.0);
    let kappa = (a * c).asinh() / a;
    for method in methods(4) {
        let opts = SolverOptions {
            method,
            ..problem.options.clone()
        };
        let eq = solve(&problem.rod, &problem.model, &opts).unwrap();
        let tip = eq.tip();
        let chord = 2.0 * (kappa / 2.0).sin() / kappa;
        assert!((tip.position.norm() - chord).abs() < 1e-9, "{method:?}");
        assert!(
            (tip.directors[2][2] - kappa.cos()).abs() < 1e-9,
            "{method:?}"
        );
    }
}

#[test]
fn catalog_errors_name_the_field() {
    let text = std::fs::read_to_string(FILE).unwrap();
    let err = |overrides: &[&str], with_catalog: bool| {
        let o: Vec<String> = overrides
            .iter()
            .map(std::string::ToString::to_string)
            .collect();
        let r = if with_catalog {
            Problem::from_str_in(&text, &o, &catalog())
        } else {
            Problem::from_str_with(&text, &o)
        };
        r.unwrap_err().to_string()
    };
    let e = err(&[], false);
    assert!(
        e.contains("energy.kind") && e.contains("linear, quartic"),
        "{e}"
    );
    let e = err(&["energy.parameters.stiffening=-1.0"], true);
    assert!(e.contains("energy.parameters.stiffening"), "{e}");
    let e = err(&["energy.parameters.stiffness=1.0"], true);
    assert!(
        e.contains("energy.parameters.stiffness") && e.contains("unknown"),
        "{e}"
    );
    let e = err(&["energy.kind=\"quartic\""], true);
    assert!(e.contains("energy.parameters.stiffening"), "{e}");
}
