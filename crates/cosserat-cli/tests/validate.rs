//! The quick validation set through the library API: every case passes,
//! and the runner's formula names evaluate the closed forms they name.
use std::collections::BTreeMap;
use std::path::Path;

use cosserat_cli::validate::{self, reference, RunOptions, Status};

fn cases_dir() -> &'static Path {
    Path::new(concat!(
        concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
        "/validation"
    ))
}

#[test]
fn quick_set_passes() {
    let cases = validate::load_cases(cases_dir()).expect("case files");
    let opts = RunOptions {
        quick: true,
        ..Default::default()
    };
    let rows = validate::run(&cases, &opts).expect("valid cases");
    assert!(rows.len() >= 20, "only {} rows", rows.len());
    let failed: Vec<String> = rows
        .iter()
        .filter(|r| r.status == Status::Fail)
        .map(|r| {
            format!(
                "{} {} {} {}: reference {}, computed {:?} ({})",
                r.case, r.point, r.method, r.quantity, r.reference, r.computed, r.message
            )
        })
        .collect();
    assert!(failed.is_empty(), "failing rows:\n{}", failed.join("\n"));
    // Every BVP method ran.
    for m in [
        "shooting",
        "multiple-shooting",
        "collocation-2",
        "collocation-3",
        "fe",
    ] {
        assert!(rows.iter().any(|r| r.method == m), "no row for {m}");
    }
    let report = validate::markdown(&cases, &rows, &opts);
    assert!(report.contains("| case | point | method |"));
}

#[test]
fn runner_formulas_evaluate_the_closed_forms() {
    // The runner's closed forms are `cosserat::references` (one copy, tested
    // against published values in crates/cosserat/tests/references.rs); a
    // case file's formula name evaluates the function it names.
    let with = |name: &str, value: f64| BTreeMap::from([(name.to_string(), value)]);
    for k in [0.5, 1.0, 2.0, 3.0, 5.0, 10.0] {
        let (x, z, angle) = reference::cantilever_tip(k);
        let at = |formula| reference::evaluate(formula, &with("k", k)).unwrap();
        assert_eq!(at("cantilever_tip_x"), x);
        assert_eq!(at("cantilever_tip_z"), z);
        assert_eq!(at("cantilever_tip_angle"), angle);
    }
    let j = reference::bessel_first_zero(-0.25, 1.0, 3.0);
    let chi = reference::evaluate("timoshenko_chi", &BTreeMap::new()).unwrap();
    assert!((chi - (2.0 * j).sqrt()).abs() < 1e-14);
    for tau in [0.0, 2.0, 5.0] {
        let a = reference::greenhill_clamped(tau);
        let b = reference::evaluate("greenhill_clamped", &with("twist", tau)).unwrap();
        assert!((b - a).abs() < 1e-10 * a);
    }
}

#[test]
fn bad_input_is_an_input_error() {
    let dir = std::env::temp_dir().join(format!("cosserat-validate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join("bad.toml");
    std::fs::write(
        &case,
        r#"
title = "bad"
problem = "nowhere.toml"
analysis = "solve"
methods = ["shooting"]
[[point]]
label = "p"
[[check]]
quantity = "tip_x"
reference = { kind = "closed-form", formula = "no_such_formula", source = "none" }
tolerance = { relative = 1e-8 }
"#,
    )
    .unwrap();
    let err = validate::load_case(&case).unwrap_err();
    assert!(err.to_string().contains("no_such_formula"), "{err}");
    let cases = validate::load_cases(cases_dir()).unwrap();
    let opts = RunOptions {
        method: Some("euler".into()),
        ..Default::default()
    };
    assert!(validate::run(&cases, &opts).is_err());
    std::fs::remove_dir_all(&dir).ok();
}
