//! Energies written as formulas, differentiated automatically, against
//! the hand-written derivatives of the built-in energies (which are thereby
//! checked too: two independent derivations must agree to rounding), and
//! the derivative checker against deliberately wrong energies.

use std::collections::BTreeMap;
use std::sync::Arc;

use cosserat::model::energy_check::{check, Property};
use cosserat::model::{
    EnergyCatalog, EnergySpec, LinearElastic, Profile, QuarticStiffening, Shearable, StoredEnergy,
};
use nalgebra::{Matrix3, Vector3};

fn stiffness() -> [Profile; 3] {
    [
        Profile::Polynomial(vec![2.0, -0.5]),
        Profile::Polynomial(vec![1.0, 0.3, 0.2]),
        Profile::Constant(1.5),
    ]
}

fn curvature() -> [Profile; 3] {
    [
        Profile::Polynomial(vec![0.1, 0.4]),
        Profile::Polynomial(vec![-0.3, 0.0, 1.0]),
        Profile::Constant(0.7),
    ]
}

fn formula(density: &str, parameters: &[(&str, f64)]) -> Arc<dyn StoredEnergy> {
    let spec = EnergySpec {
        stiffness: stiffness(),
        intrinsic_curvature: curvature(),
        parameters: parameters
            .iter()
            .map(|(k, v)| ((*k).to_owned(), *v))
            .collect(),
        density: Some(density.into()),
    };
    EnergyCatalog::standard()
        .build("formula", &spec)
        .unwrap()
        .unwrap()
}

/// Every quantity the equations use, at a few (s, κ), relative to scale.
fn agree(a: &dyn StoredEnergy, b: &dyn StoredEnergy, tol: f64) {
    let v = Vector3::new(0.3, -1.2, 0.8);
    for s in [0.0, 0.31, 0.77, 1.0] {
        for k in [
            Vector3::new(0.2, -0.4, 1.1),
            Vector3::new(-1.5, 0.9, 0.05),
            Vector3::zeros(),
        ] {
            let close = |x: f64, y: f64, scale: f64, what: &str| {
                assert!(
                    (x - y).abs() <= tol * scale.max(1.0),
                    "{what} at s = {s}, κ = {k:?}: {x} vs {y}"
                );
            };
            close(
                a.density(s, &k),
                b.density(s, &k),
                a.density(s, &k).abs(),
                "W",
            );
            let pairs_v = [
                (a.moment(s, &k), b.moment(s, &k), "M"),
                (a.moment_rate(s, &k), b.moment_rate(s, &k), "∂sM"),
            ];
            for (x, y, what) in pairs_v {
                for i in 0..3 {
                    close(x[i], y[i], x.amax(), what);
                }
            }
            let pairs_m: [(Matrix3<f64>, Matrix3<f64>, &str); 3] = [
                (a.stiffness(s, &k), b.stiffness(s, &k), "H"),
                (a.stiffness_rate(s, &k), b.stiffness_rate(s, &k), "∂sH"),
                (
                    a.stiffness_derivative(s, &k, &v),
                    b.stiffness_derivative(s, &k, &v),
                    "∂(Hv)/∂κ",
                ),
            ];
            for (x, y, what) in pairs_m {
                for (p, q) in x.iter().zip(y.iter()) {
                    close(*p, *q, x.amax(), what);
                }
            }
        }
    }
}

/// The linear energy of paper (17) written as a formula: automatic and
/// hand-written derivatives agree to rounding on a tapered rod with
/// varying intrinsic curvature.
#[test]
fn linear_formula_matches_the_hand_written_linear_energy() {
    let linear = LinearElastic::new(stiffness(), curvature()).unwrap();
    let f = formula("0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2)", &[]);
    agree(&linear, f.as_ref(), 1e-13);
    assert!(!f.admits_planar_bending(), "κ⁰₁ ≠ 0 here");
}

/// The quartic stiffening energy (coupled Hessian, non-zero third
/// derivative) as a formula, against its hand-written derivatives.
#[test]
fn quartic_formula_matches_the_hand_written_quartic_energy() {
    let quartic =
        QuarticStiffening::new(LinearElastic::new(stiffness(), curvature()).unwrap(), 0.8).unwrap();
    let f = formula(
        "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) + C/4*(k1^2 + k2^2 + k3^2)^2",
        &[("C", 0.8)],
    );
    agree(&quartic, f.as_ref(), 1e-13);
}

/// The planar claim is proved from the formula's parity, and refused
/// when the formula couples κ1 or κ3 oddly with κ2.
#[test]
fn planar_bending_is_claimed_only_when_proved() {
    let spec = |density: &str| EnergySpec {
        stiffness: stiffness(),
        intrinsic_curvature: Default::default(),
        parameters: BTreeMap::new(),
        density: Some(density.into()),
    };
    let catalog = EnergyCatalog::standard();
    let even = catalog
        .build("formula", &spec("B2*cosh(k2) + k1^2*k3^2 + k1*k3"))
        .unwrap()
        .unwrap();
    assert!(even.admits_planar_bending());
    let odd = catalog
        .build("formula", &spec("B2*k2^2 + k1*k2 + k1^2 + k3^2"))
        .unwrap()
        .unwrap();
    assert!(!odd.admits_planar_bending());
}

/// The checker passes every correct energy, built-in or written as a
/// formula (including the shearable wrapper), with derivatives agreeing
/// to the Richardson-bounded difference error.
#[test]
fn correct_energies_pass_the_check() {
    let linear = Arc::new(LinearElastic::new(stiffness(), curvature()).unwrap());
    let energies: Vec<Arc<dyn StoredEnergy>> = vec![
        linear.clone(),
        Arc::new(QuarticStiffening::new((*linear).clone(), 0.8).unwrap()),
        Arc::new(Shearable::new(linear, Vector3::new(10.0, 20.0, 30.0)).unwrap()),
        formula(
            "B1/a^2*(cosh(a*k1) - 1) + B2/a^2*(cosh(a*k2) - 1) + B3*k3^2/2",
            &[("a", 0.7)],
        ),
        formula(
            "(B1*k1^2 + B2*k2^2 + B3*k3^2) * (1 + s^2) / 2 + exp(k1*k2/4)",
            &[],
        ),
    ];
    for e in energies {
        let report = check(e.as_ref(), 1.0, 1.0);
        assert!(report.passed(), "{}: {report}", e.name());
        assert!(report.worst_passed < 1e-8, "{}: {report}", e.name());
    }
}

/// A kink of W at a sampled strain (|k1| at k1 = 0) is not passed: the
/// one-sided moment there is not a derivative. The variational equations
/// need the third derivative, so W must be C³ where the rod lives: |k2|³
/// (third derivative jumping at 0) is not passed either, |k2|⁵ is.
#[test]
fn a_kink_is_not_passed() {
    let kink = formula("B1*k1^2 + B2*k2^2 + B3*k3^2 + abs(k1)", &[]);
    let report = check(kink.as_ref(), 1.0, 1.0);
    assert!(!report.passed(), "{report}");
    assert!(report
        .failures()
        .all(|f| f.kappa[0] == 0.1 + 0.4 * f.s || f.undecided));
    let c2 = formula("B1*k1^2 + B2*k2^2 + B3*k3^2 + abs(k2)^3", &[]);
    assert!(!check(c2.as_ref(), 1.0, 1.0).passed());
    let smooth = formula("B1*k1^2 + B2*k2^2 + B3*k3^2 + abs(k2)^5", &[]);
    let report = check(smooth.as_ref(), 1.0, 1.0);
    assert!(report.passed(), "{report}");
}

/// An energy with one derivative deliberately wrong, each in turn.
#[derive(Debug)]
struct Wrong {
    right: LinearElastic,
    broken: Property,
    factor: f64,
}

impl StoredEnergy for Wrong {
    fn density(&self, s: f64, k: &Vector3<f64>) -> f64 {
        self.right.density(s, k) + 0.1 * k[1].powi(4)
    }
    fn moment(&self, s: f64, k: &Vector3<f64>) -> Vector3<f64> {
        let mut m = self.right.moment(s, k) + Vector3::new(0.0, 0.4 * k[1].powi(3), 0.0);
        if self.broken == Property::Moment {
            m *= self.factor;
        }
        m
    }
    fn stiffness(&self, s: f64, k: &Vector3<f64>) -> Matrix3<f64> {
        let mut h = self.right.stiffness(s, k);
        h[(1, 1)] += 1.2 * k[1].powi(2);
        if self.broken == Property::Stiffness {
            h *= self.factor;
        }
        h
    }
    fn moment_rate(&self, s: f64, k: &Vector3<f64>) -> Vector3<f64> {
        let m = self.right.moment_rate(s, k);
        if self.broken == Property::MomentRate {
            m * self.factor
        } else {
            m
        }
    }
    fn stiffness_rate(&self, s: f64, k: &Vector3<f64>) -> Matrix3<f64> {
        let h = self.right.stiffness_rate(s, k);
        if self.broken == Property::StiffnessRate {
            h * self.factor
        } else {
            h
        }
    }
    fn stiffness_derivative(&self, _: f64, k: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        let mut t = Matrix3::zeros();
        t[(1, 1)] = 2.4 * k[1] * v[1];
        if self.broken == Property::StiffnessDerivative {
            t *= self.factor;
        }
        t
    }
    fn admits_planar_bending(&self) -> bool {
        self.right.admits_planar_bending()
    }
    fn name(&self) -> &'static str {
        "wrong"
    }
}

/// Each wrong derivative, 2 % off, is found and named.
#[test]
fn a_wrong_derivative_is_caught_and_named() {
    let right = LinearElastic::new(stiffness(), curvature()).unwrap();
    for broken in [
        Property::Moment,
        Property::Stiffness,
        Property::MomentRate,
        Property::StiffnessRate,
        Property::StiffnessDerivative,
    ] {
        let e = Wrong {
            right: right.clone(),
            broken,
            factor: 1.02,
        };
        let report = check(&e, 1.0, 1.0);
        assert!(!report.passed(), "{broken:?} not caught");
        assert!(
            report.failures().any(|f| f.property == broken),
            "{broken:?}: {report}"
        );
        let unbroken = Wrong { factor: 1.0, ..e };
        assert!(
            check(&unbroken, 1.0, 1.0).passed(),
            "{broken:?} control failed"
        );
    }
}

/// Formula errors reach the problem reader under energy.density with
/// line and column; unread or reserved parameter names are refused.
#[test]
fn formula_refusals_name_their_key() {
    let catalog = EnergyCatalog::standard();
    let build = |density: Option<&str>, parameters: &[(&str, f64)], kind: &str| {
        let spec = EnergySpec {
            stiffness: stiffness(),
            intrinsic_curvature: Default::default(),
            parameters: parameters
                .iter()
                .map(|(k, v)| ((*k).to_owned(), *v))
                .collect(),
            density: density.map(str::to_owned),
        };
        catalog.build(kind, &spec).unwrap().unwrap_err()
    };
    let e = build(Some("B1*k1^2 +"), &[], "formula");
    assert_eq!(e.field, "energy.density");
    assert!(e.message.contains("line 1, column 10"), "{}", e.message);
    let e = build(Some("B1*k1^2"), &[("typo", 1.0)], "formula");
    assert_eq!(e.field, "energy.parameters.typo");
    let e = build(Some("B1*k1^2"), &[("k2", 1.0)], "formula");
    assert_eq!(e.field, "energy.parameters.k2");
    let e = build(None, &[], "formula");
    assert_eq!(e.field, "energy.density");
    let e = build(Some("B1*k1^2"), &[], "linear");
    assert_eq!(e.field, "energy.density");
    // A formula in v1..v3 is a Cosserat energy W(s, k, v), no longer refused.
    let spec = EnergySpec {
        stiffness: stiffness(),
        intrinsic_curvature: Default::default(),
        parameters: std::collections::BTreeMap::default(),
        density: Some("B1*k1^2 + (v3 - 1)^2".to_owned()),
    };
    let e = catalog.build("formula", &spec).unwrap().unwrap();
    assert!(e.strain_energy().is_some());
}

/// A program's energy with a Hessian 2 % off is refused by the solver,
/// naming the derivative, instead of converging to a wrong tip; the same
/// energy with the right Hessian solves.
#[test]
fn the_solver_refuses_a_wrong_hand_written_derivative() {
    use cosserat::bvp::{solve, SolveError};
    let text = r#"
[rod]
length = 1.0
[energy]
kind = "wrong"
stiffness = [10.0, 1.0, 10.0]
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [3.0, 0.0, 0.0]
"#;
    for (factor, refused) in [(1.02, true), (1.0, false)] {
        let mut catalog = EnergyCatalog::standard();
        catalog.register("wrong", move |spec| {
            Ok(Arc::new(Wrong {
                right: spec.linear()?,
                broken: Property::Stiffness,
                factor,
            }))
        });
        let p = cosserat::input::Problem::from_str_in(text, &[], &catalog).unwrap();
        match solve(&p.rod, &p.model, &p.options) {
            Err(SolveError::Model(m)) if refused => {
                assert!(m.contains("stiffness H"), "{m}");
            }
            Ok(_) if !refused => {}
            other => panic!("factor {factor}: {:?}", other.map(|e| e.unknowns)),
        }
    }
}

/// The formula's symbolic derivatives (what it runs on) against automatic
/// differentiation of the same formula (num-dual, the `Density` path): two
/// independent derivations, every function of the language, a tapered rod
/// with varying intrinsic curvature.
#[test]
fn symbolic_derivatives_match_automatic_differentiation() {
    use cosserat::model::{AutoDiff, FormulaEnergy};
    let formulas = [
        "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2)",
        "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) + C/4*(k1^2 + k2^2 + k3^2)^2",
        "B1*(cosh(k1) - 1) + B2*exp(k2^2/4) + B3*k3^2*(1 + s^2) + sqrt(1 + k1^2*k2^2)",
        "B2*k2^2 + log(2 + sin(k1)) + cos(k3*s) + tan(k1*k3/4) + tanh(k2)*sinh(k1) + atan(k2*k3)",
        "B1*k1^2 + B2*k2^2 + B3*k3^2 + abs(k2 - 0.1)^3 + (1 + k1^2)^0.75 + (2 + k3^2)^(1 + s)",
        "B1*k1^2 + B2*k2^2 + B3*k3^2 + min(k1^2, k2^2 + 0.3) + max(k3^3, -1 + k1) / C",
    ];
    for text in formulas {
        let e = formula(
            text,
            if text.contains('C') {
                &[("C", 0.8)]
            } else {
                &[]
            },
        );
        let symbolic = e.as_ref();
        let f = cosserat::model::Formula::new(text, &|n| (n == "C").then_some(0.8)).unwrap();
        let ad = AutoDiff::new(FormulaEnergy::new(f, stiffness(), curvature()).unwrap());
        agree(symbolic, &ad, 1e-12);
    }
}

/// Evenness claims: proved per component for a formula, claimed by the
/// built-in energies, and a false claim is caught by the check.
#[test]
fn claimed_evenness_is_proved_or_caught() {
    #[derive(Debug)]
    struct Claims(Arc<dyn StoredEnergy>);
    impl StoredEnergy for Claims {
        fn density(&self, s: f64, k: &Vector3<f64>) -> f64 {
            self.0.density(s, k)
        }
        fn moment(&self, s: f64, k: &Vector3<f64>) -> Vector3<f64> {
            self.0.moment(s, k)
        }
        fn stiffness(&self, s: f64, k: &Vector3<f64>) -> Matrix3<f64> {
            self.0.stiffness(s, k)
        }
        fn moment_rate(&self, s: f64, k: &Vector3<f64>) -> Vector3<f64> {
            self.0.moment_rate(s, k)
        }
        fn stiffness_rate(&self, s: f64, k: &Vector3<f64>) -> Matrix3<f64> {
            self.0.stiffness_rate(s, k)
        }
        fn stiffness_derivative(&self, s: f64, k: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
            self.0.stiffness_derivative(s, k, v)
        }
        fn admits_planar_bending(&self) -> bool {
            false
        }
        fn profile_edits(&self) -> Option<&dyn cosserat::model::ProfileEdits> {
            self.0.profile_edits()
        }
        fn even_components(&self) -> [bool; 3] {
            [true; 3]
        }
        fn name(&self) -> &'static str {
            "claims too much"
        }
    }
    let f = formula("B1*k1^2 + B2*k2^2 + B3*k3^2 + k1*k2^2 + k3^4", &[]);
    assert_eq!(f.even_components(), [false, true, true]);
    let report = check(&Claims(f), 1.0, 1.0);
    assert!(
        report.failures().all(|x| x.property == Property::Evenness) && !report.passed(),
        "{report}"
    );
}
