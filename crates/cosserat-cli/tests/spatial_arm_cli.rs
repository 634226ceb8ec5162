//! `cosserat optimize` of the shipped spatial arm (issue 20), made cheap
//! by `--set`: the HDF5 file holds the design, the 3-D shapes, γ_crit, the
//! mesh check and the loading-path verdict, every dataset described; the
//! spatial reach is never below the planar one it was seeded with; the
//! planar-only flags are refused by name.
mod common;

use common::problems::shipped;
use common::run::{run, scratch, stderr};

const CHEAP: [&str; 8] = [
    "--set",
    "arm.samples=8",
    "--set",
    "arm.iterations=40",
    "--set",
    "arm.elements=12",
    "--set",
    "arm.starts=1",
];

/// Release only: the debug build's continuation of the loading path is
/// slow for CI's budget (the library's tests check the numbers in debug).
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn spatial_optimum_file_holds_design_shapes_and_verdict() {
    let dir = scratch("spatial", "file");
    let out = dir.join("spatial.h5");
    let chart = dir.join("spatial.svg");
    let file = shipped("longest_arm_spatial");
    let mut args = vec![
        "optimize",
        &file,
        "-o",
        out.to_str().unwrap(),
        "--plot",
        chart.to_str().unwrap(),
    ];
    args.extend_from_slice(&CHEAP);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let f = common::h5::open(&out);
    let g = f.group("spatial").unwrap();
    let reach = g.dataset("reach").unwrap().float().unwrap();
    let gamma = g.dataset("gamma_crit").unwrap().float().unwrap();
    let chord = common::h5::read_f64(g, "loaded_shape");
    let tip = &chord[chord.len() - 3..];
    // R̂ = √γ |chord| and the shapes are scaled by √γ: |tip| = R̂.
    let tip_norm = tip.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(
        (tip_norm - reach).abs() < 1e-6 * reach,
        "{tip_norm} vs {reach}"
    );
    assert!(gamma > 0.0 && reach > 0.0);
    assert_eq!(common::h5::read_f64(g, "unloaded_shape").len(), chord.len());
    assert_eq!(
        common::h5::read_f64(g, "intrinsic_curvature").len(),
        chord.len()
    );
    let verdict = g.attrs.text("loading_path").unwrap();
    assert!(
        ["reaches", "misses", "undecided"].contains(&verdict),
        "{verdict}"
    );
    for (path, description) in described(&out) {
        assert_ne!(description, "undescribed", "{path}");
    }
    // The spatial search is seeded with the planar optimum, which stdout
    // prints to six decimals: the planar R* is at least the printed value
    // less half its last unit.
    let planar: f64 = field(&text, "planar    R* = ");
    assert!(
        reach >= planar - 0.5e-6,
        "spatial {reach} < planar {planar} (printed to 1e-6)"
    );
    assert!(std::fs::metadata(&chart).unwrap().len() > 1000);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn planar_only_flags_are_refused_for_spatial_arms() {
    let dir = scratch("spatial", "flags");
    let file = shipped("longest_arm_spatial");
    let path = dir.join("c.h5");
    let o = run(&["optimize", &file, "--control-path", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--control-path"), "{}", stderr(&o));
    assert!(!path.exists());
    std::fs::remove_dir_all(dir).unwrap();
}

fn field(text: &str, prefix: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no `{prefix}` in {text}"));
    line[prefix.len()..]
        .split(|c: char| c == ',' || c.is_whitespace())
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

/// (dataset path, description) of every dataset.
fn described(path: &std::path::Path) -> Vec<(String, String)> {
    fn walk(g: &cosserat::output::store::Group, out: &mut Vec<(String, String)>) {
        for (_, ds) in g.datasets() {
            let d = ds.attrs.text("description").unwrap_or("missing").to_owned();
            out.push((ds.path().to_owned(), d));
        }
        for (_, sub) in g.groups() {
            walk(sub, out);
        }
    }
    let mut out = vec![];
    walk(&common::h5::open(path), &mut out);
    out
}

/// A spatial arm with a tapered section is refused by name (the section's
/// optimizer works on planar shapes), before any work and with nothing
/// written.
#[test]
fn a_tapered_spatial_arm_is_refused_by_name() {
    let dir = scratch("spatial", "taper");
    let text = std::fs::read_to_string(shipped("longest_arm_spatial")).unwrap();
    let text = text.replacen(
        "[arm]\n",
        "[arm]\ntaper = { knots = 5, min_section = 0.2 }\n",
        1,
    );
    let file = dir.join("tapered_spatial.toml");
    std::fs::write(&file, text).unwrap();
    let out = dir.join("out.h5");
    let o = run(&[
        "optimize",
        file.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("arm.taper"), "{}", stderr(&o));
    assert!(!out.exists());
    std::fs::remove_dir_all(dir).unwrap();
}
