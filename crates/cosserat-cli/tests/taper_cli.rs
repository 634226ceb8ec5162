//! `cosserat optimize` of a tapered arm (problems/longest_arm_tapered.toml,
//! issue 20): the command runs from the shipped file (a short search, set
//! smaller here), writes the design with its section, and refuses what a
//! tapered arm cannot take, each by its key.

mod common;

use common::h5::{open, read_f64};
use common::problems::{refusal, shipped, shipped_text};
use common::run::{run, scratch, stderr};
use cosserat::output::schema::UNDESCRIBED;

/// The shipped file, with a lighter search and mesh: the design beats the
/// prismatic start, its section has unit volume above the bound, and every
/// dataset is described. Release only (a minute of search in debug).
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn tapered_optimize_writes_the_design() {
    let dir = scratch("taper_cli", "run");
    let out = dir.join("arm.h5");
    let chart = dir.join("arm.png");
    let o = run(&[
        "optimize",
        &shipped("longest_arm_tapered"),
        "--set",
        "arm.samples=60",
        "--set",
        "arm.iterations=150",
        "--set",
        "arm.elements=20",
        "-o",
        out.to_str().unwrap(),
        "--plot",
        chart.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(chart.exists());
    let file = open(&out);
    let g = file.group("optimum").unwrap();
    let reach = read_f64(g, "reach")[0];
    let prismatic = read_f64(file.group("prismatic").unwrap(), "reach")[0];
    assert!(reach > prismatic, "{reach} vs {prismatic}");
    // γ of the designed rod (the fixed-shape pencil of its exact stiffness
    // B_i A²) against the search's own (A² at the quadrature points): the
    // same matrices, equal to rounding.
    let (gamma, check) = (read_f64(g, "load_factor")[0], read_f64(g, "gamma_crit")[0]);
    assert!((gamma / check - 1.0).abs() < 1e-10, "{gamma} vs {check}");
    // The joint ascent met its tolerance, and the optimum was polished
    // again on 2N and 4N elements (R* falling towards its limit).
    assert_eq!(g.attrs.text("ascent").unwrap(), "converged");
    let pg = read_f64(g, "projected_gradient")[0];
    assert!(
        pg <= cosserat::study::arm::taper::ASCENT_TOLERANCE * reach,
        "{pg}"
    );
    let meshes = read_f64(g, "reach_meshes");
    assert_eq!(meshes.len(), 3);
    // R* on N by the ascent's evaluation (the gradient's pencil) and by the
    // design's (the section's pencil): the same eigenvalue to rounding.
    assert!(
        (meshes[0] / reach - 1.0).abs() < 1e-12,
        "{meshes:?} vs {reach}"
    );
    let a = read_f64(g, "section");
    let h = 1.0 / (a.len() - 1) as f64;
    let volume = a.iter().sum::<f64>() * h - 0.5 * h * (a[0] + a[a.len() - 1]);
    assert!((volume - 1.0).abs() < 1e-9, "{volume}");
    assert!(a.iter().all(|v| *v >= 0.2 - 1e-12));
    // The loading path decides (its start once stalled at the spline's
    // noise floor: undecided).
    let verdict = g.attrs.text("loading_path").unwrap();
    assert!(
        ["reaches_design", "loses_stability", "other_equilibrium"].contains(&verdict),
        "{verdict}"
    );
    for (_, ds) in g.datasets() {
        assert_ne!(
            ds.attrs.text("description").unwrap(),
            UNDESCRIBED,
            "{}",
            ds.path()
        );
    }
}

/// Each refusal names its key.
#[test]
fn tapered_arm_refusals_name_their_keys() {
    let text = shipped_text("longest_arm_tapered");
    let cases: [(&[&str], &str); 5] = [
        (&["arm.order=1"], "arm.order"),
        (
            &["arm.taper={knots=60, min_section=0.2}"],
            "arm.taper.knots",
        ),
        (&["arm.taper={knots=11, min_section=0.0}"], "arm.taper"),
        (&["arm.max_curvature=3.0"], "arm.taper"),
        (&["arm.map_samples=10"], "arm.map_samples"),
    ];
    for (set, key) in cases {
        let e = refusal(&text, set);
        assert!(e.contains(key), "{set:?}: {e}");
    }
}
