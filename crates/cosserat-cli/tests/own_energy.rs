//! A program's own energy in the standard commands (issue 17, item 5):
//! the example binary's catalog (examples/own_energy.rs, an energy with no
//! hand-written derivative) drives `solve`, `check-energy`, `continue` and
//! `sweep` through the library entry point `run_with_energies`. The rod,
//! rolled up by an end couple C instead of the tip force, has uniform curvature with
//! B/a sinh(a κ) = C, so κ = asinh(a C/B)/a — the closed form the
//! solution is checked against.

#[path = "../examples/own_energy.rs"]
mod own_energy;

mod common;

use std::process::ExitCode;

use clap::Parser;
use cosserat_cli::cli::Cli;

const PROBLEM: &str = r#"
[rod]
length = 1.0
[energy]
kind = "hyperbolic"
stiffness = [1.0, 1.0, 1.0]
[energy.parameters]
stiffening = 0.5
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [1.0, 0.0, 0.0]
[continuation]
parameter = "loads.tip_force[0]"
start = 0.5
bounds = [0.0, 4.0]
step = 0.1
max_step = 0.5
[sweep]
axes = [{ key = "energy.parameters.stiffening", values = [0.25, 0.5] }]
"#;

/// The two tests run one after the other: the first writes HDF5 files in
/// this process (the C library opens them without close-on-exec), and a
/// child the second spawns meanwhile would inherit that descriptor and its
/// file lock, so the first could not reopen its own file.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn run(args: &[&str]) -> ExitCode {
    cosserat_cli::run(Cli::parse_from(
        std::iter::once("cosserat").chain(args.iter().copied()),
    ))
}

#[test]
fn a_programs_energy_runs_through_every_command() {
    let _serial = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    assert!(cosserat_cli::energies::install(own_energy::catalog()));
    let dir = common::run::scratch("own_energy", "files");
    std::fs::create_dir_all(&dir).unwrap();
    let problem = dir.join("roll_up.toml");
    std::fs::write(&problem, PROBLEM).unwrap();
    let p = problem.to_str().unwrap();

    let solution = dir.join("solution.h5");
    let roll_up = [
        "--set",
        "loads.tip_force=[0, 0, 0]",
        "--set",
        "loads.tip_couple=[0, 4, 0]",
    ];
    let mut args = vec!["solve", p, "-o", solution.to_str().unwrap(), "--force"];
    args.extend(roll_up);
    assert_eq!(run(&args), ExitCode::SUCCESS);
    let file = common::h5::open(&solution);
    let curvature = common::h5::read_f64(file.group("solution").unwrap(), "curvature");
    let exact = (0.5f64 * 4.0).asinh() / 0.5;
    for k in curvature.chunks(3) {
        assert!((k[1] - exact).abs() < 1e-9, "κ2 = {} vs {exact}", k[1]);
    }

    assert_eq!(run(&["check-energy", p]), ExitCode::SUCCESS);
    let diagram = dir.join("diagram.h5");
    assert_eq!(
        run(&["continue", p, "-o", diagram.to_str().unwrap(), "--force"]),
        ExitCode::SUCCESS
    );
    let sweep = dir.join("sweep.h5");
    assert_eq!(
        run(&["sweep", p, "-o", sweep.to_str().unwrap(), "--force"]),
        ExitCode::SUCCESS
    );
    // The standard catalog does not know the energy: a named refusal.
    let refused = common::run::run(&["solve", p]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(common::run::stderr(&refused).contains("hyperbolic"));
}

/// `check-energy` on the standard binary: a formula energy passes; one
/// whose Hessian loses definiteness at the loaded strains fails, naming
/// the material instability (exit 2).
#[test]
fn check_energy_reports_a_material_instability() {
    let _serial = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let dir = common::run::scratch("own_energy", "check");
    std::fs::create_dir_all(&dir).unwrap();
    let file = |name: &str, density: &str| {
        let path = dir.join(name);
        let text = format!(
            "[rod]\nlength = 1.0\n[energy]\nkind = \"formula\"\ndensity = \"{density}\"\n\
             stiffness = [10.0, 1.0, 10.0]\n[clamp]\nd1 = [1.0, 0.0, 0.0]\nd3 = [0.0, 0.0, 1.0]\n\
             [loads]\ntip_force = [3.0, 0.0, 0.0]\n"
        );
        std::fs::write(&path, text).unwrap();
        path
    };
    let good = file("good.toml", "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) + k2^4/8");
    let out = common::run::run(&["check-energy", good.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", common::run::stderr(&out));
    let soft = file(
        "softening.toml",
        "0.5*(B1*k1^2 + B2*k2^2 + B3*k3^2) - k2^4/4",
    );
    let out = common::run::run(&["check-energy", soft.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("FAILED positive definite H"), "{stdout}");
}
