//! The energies every command reads problem files with: the standard
//! catalog, or a program's own ([`crate::run_with_energies`]), so that a
//! Rust energy registered by a program is accepted by `energy.kind` in
//! `solve`, `stability`, `continue`, `optimize`, `sweep`, `bench`,
//! `validate` and `check-energy` alike — and `cosserat check-energy`.

use std::path::Path;
use std::process::ExitCode;
use std::sync::OnceLock;

use cosserat::bvp::solve;
use cosserat::input::{Problem, ProblemError};
use cosserat::model::energy_check::{check, check_at, typical_curvature, EnergyCheck};
use cosserat::model::EnergyCatalog;

use crate::exit::{fail, BAD_INPUT};

static CATALOG: OnceLock<EnergyCatalog> = OnceLock::new();

/// Sets the process's catalog; false when one was already in use.
pub fn install(catalog: EnergyCatalog) -> bool {
    CATALOG.set(catalog).is_ok()
}

/// The process's catalog (the standard one unless a program installed
/// its own).
pub fn catalog() -> &'static EnergyCatalog {
    CATALOG.get_or_init(EnergyCatalog::standard)
}

/// A problem file read with the process's catalog.
pub fn read_problem(path: &Path, set: &[String]) -> Result<Problem, ProblemError> {
    Problem::from_path_in(path, set, catalog())
}

/// A problem text read with the process's catalog (sweeps, per point).
pub fn read_problem_text(text: &str, set: &[String]) -> Result<Problem, ProblemError> {
    Problem::from_str_in(text, set, catalog())
}

/// `cosserat check-energy PROBLEM`: the energy's derivatives, symmetry,
/// convexity and planar claim at sampled strains along the rod, then at
/// the strains of the problem's solution where it solves. Exit 0 when
/// every check passes, 2 (bad input) when one fails.
pub fn run_check(path: &Path, set: &[String]) -> ExitCode {
    let problem = match read_problem(path, set) {
        Ok(p) => p,
        Err(e) => return fail(BAD_INPUT, format!("{}: {e}", path.display())),
    };
    let rod = &problem.rod;
    let energy = rod.energy();
    let scale = typical_curvature(rod);
    println!("problem   {}", path.display());
    println!(
        "energy    {} ({})",
        energy.name(),
        if energy.derivatives_trusted() {
            "derivatives exact or verified by the tests"
        } else {
            "hand-written derivatives: the solver checks them at every solve"
        }
    );
    println!("strains   around κ⁰(s), scale {scale:.4e} 1/m");
    let sampled = check(energy.as_ref(), rod.length(), scale);
    print!("sampled   {sampled}");
    let along = along_solution(&problem, scale);
    let passed = sampled.passed() && along.as_ref().is_none_or(EnergyCheck::passed);
    if passed {
        println!("verdict   passed");
        ExitCode::SUCCESS
    } else {
        fail(
            BAD_INPUT,
            "the energy failed its checks (FAILED lines above): correct its derivatives, or \
             its parameters where H is not positive definite (a material instability)",
        )
    }
}

/// The check at the strains of the solution, or None (and why) when the
/// problem does not solve.
fn along_solution(problem: &Problem, scale: f64) -> Option<EnergyCheck> {
    let rod = &problem.rod;
    match solve(rod, &problem.model, &problem.options) {
        Ok(eq) => {
            let at: Vec<_> = eq.samples.iter().map(|x| (x.s, x.curvature)).collect();
            let report = check_at(rod.energy().as_ref(), rod.length(), scale, &at);
            print!("solution  {report}");
            Some(report)
        }
        Err(e) => {
            println!("solution  not checked: the problem does not solve ({e})");
            None
        }
    }
}
