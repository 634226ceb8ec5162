//! `cosserat stability`: the printed report and the HDF5 contract.
mod common;

use std::path::{Path, PathBuf};

use common::problems::shipped;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_cosserat");

/// `cosserat stability` on the shipped problem `name`, writing `out`.
fn stability(name: &str, out: &Path) -> (bool, String, String) {
    run(&["stability", &shipped(name), "-o", out.to_str().unwrap()])
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cosserat-stab-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run(args: &[&str]) -> (bool, String, String) {
    let o = Command::new(BIN).args(args).output().unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn fixed_shape_writes_the_critical_load() {
    let dir = scratch("ltb");
    let out = dir.join("ltb.h5");
    let (ok, stdout, stderr) = stability("timoshenko_ltb", &out);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("γ_crit"), "{stdout}");
    let f = common::h5::open(&out);
    let g = f.group("stability").unwrap();
    let gamma = g.dataset("critical_load").unwrap().float().unwrap();
    assert!((gamma - 4.0126).abs() < 1e-4, "{gamma}");
    let oop = g.group("out_of_plane").unwrap();
    let mode = oop.dataset("null_vector").unwrap();
    assert_eq!(mode.shape()[0], 1);
    assert_eq!(mode.shape()[2], 3);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn equilibrium_writes_blocks_and_morse_index() {
    let dir = scratch("cantilever");
    let out = dir.join("c.h5");
    let (ok, stdout, stderr) = stability("cantilever_tip_load", &out);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("verdict   stable"), "{stdout}");
    let f = common::h5::open(&out);
    assert!(f.group("solution").is_ok());
    let g = f.group("stability").unwrap();
    let values = g.dataset("eigenvalues").unwrap().floats().unwrap().to_vec();
    assert_eq!(values.len(), 4);
    assert!(values.windows(2).all(|w| w[0] <= w[1]) && values[0] > 0.0);
    let vectors = g.dataset("eigenvectors").unwrap();
    assert_eq!(vectors.shape()[0], 4);
    assert_eq!(g.dataset("morse_index").unwrap().count().unwrap(), 0);
    for block in ["in_plane", "out_of_plane"] {
        let b = g.group(block).unwrap();
        assert_eq!(
            b.dataset("eigenvalues")
                .unwrap()
                .floats()
                .unwrap()
                .to_vec()
                .len(),
            4
        );
        assert_eq!(b.dataset("morse_index").unwrap().count().unwrap(), 0);
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn unstable_column_is_reported_unstable() {
    // The straight column beyond the Euler load π²/4: Morse index 2
    // (B1 = B2), reported, exit 0.
    let dir = scratch("column");
    let file = dir.join("column.toml");
    let text = include_str!("../../../problems/euler_column.toml")
        .replace(
            "[shape]\nturning_angle = 0.0",
            "[solver]\nstrategy = \"direct\"",
        )
        .replace("[0.0, 0.0, -1.0]", "[0.0, 0.0, -3.0]");
    std::fs::write(&file, text).unwrap();
    let (ok, stdout, stderr) = run(&["stability", file.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("verdict   unstable"), "{stdout}");
    assert!(stdout.contains("morse     2"), "{stdout}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_stability_options_are_named() {
    let o = Command::new(BIN)
        .args([
            "stability",
            &shipped("euler_column"),
            "--set",
            "stability.order=7",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("stability.order"));
}
