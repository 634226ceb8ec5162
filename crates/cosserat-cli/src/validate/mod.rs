//! `cosserat validate`: classical benchmarks run against every method.
//!
//! A case is data (`validation/<case>.toml`): a problem file, the
//! overrides to apply (with `{param}` placeholders filled from each point's
//! parameters), the analysis to run, the methods it applies to, and checks
//! — a quantity, a reference with its kind and source, a tolerance. One
//! generic runner runs every point of every case with every method that
//! applies and compares. References are closed forms evaluated in
//! [`mod@reference`] from their formulas, or published values typed with their
//! citation; never the solver's own output. The file format is described
//! in validation/README.md.
//!
//! Submodules: `case` (the case files and their loading and checks),
//! `runner` (one analysis per point and method, and the comparison with
//! the reference) and `report` (the verdicts, the terminal table and the
//! markdown report); this module holds the command.

mod case;
mod report;
mod runner;

pub use case::{
    default_dir, error_of, load_case, load_cases, Case, CaseFile, Check, InputError, Point,
    Reference, Scan, Tolerance,
};
pub use cosserat::references as reference;
pub use report::{counts, markdown, text_table, Row, Status};
pub(crate) use runner::{fill, method_overrides, point_params, tip_quantities};
pub use runner::{run, RunOptions};

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// The methods a case can name: the BVP discretizations, and `fe` for the
/// fixed-shape finite-element analysis (which has no BVP method).
pub const METHODS: [&str; 5] = [
    "shooting",
    "multiple-shooting",
    "collocation-2",
    "collocation-3",
    "fe",
];

/// Arguments of `cosserat validate`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ValidateArgs {
    /// Run only the quick subset (CI).
    #[arg(long)]
    pub quick: bool,
    /// Run only this method: shooting, multiple-shooting, collocation
    /// (both orders), collocation-2, collocation-3 or fe.
    #[arg(long)]
    pub method: Option<String>,
    /// Write the report (Markdown) to this file.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The directory of case files (default: ./validation, else the
    /// crate's own).
    #[arg(long)]
    pub cases: Option<PathBuf>,
    /// Run only the cases whose name contains this.
    #[arg(long)]
    pub case: Option<String>,
}

/// `cosserat validate`: exit 0 when every row passes (or is informational
/// or skipped), 3 when one fails (a result below the asked quality), 2 on
/// bad input, 1 when the report cannot be written.
pub fn run_cli(args: &ValidateArgs) -> ExitCode {
    let dir = args.cases.clone().unwrap_or_else(default_dir);
    let cases = match load_cases(&dir) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let opts = RunOptions {
        quick: args.quick,
        method: args.method.clone(),
        case: args.case.clone(),
    };
    let start = Instant::now();
    let rows = match run(&cases, &opts) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    print!("{}", text_table(&rows));
    let [pass, fail, info, skip] = counts(&rows);
    println!(
        "validate  {pass} pass, {fail} fail, {info} informational, {skip} skipped in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    if let Some(out) = &args.output {
        if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
            let _ = std::fs::create_dir_all(parent);
        }
        let report = markdown(&cases, &rows, &opts);
        if let Err(e) =
            cosserat::output::target::replace_atomically(out, |tmp| std::fs::write(tmp, &report))
        {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
        println!("written   {}", out.display());
    }
    if rows.is_empty() {
        eprintln!("error: no case matched");
        return ExitCode::from(2);
    }
    if fail > 0 {
        ExitCode::from(3)
    } else {
        ExitCode::SUCCESS
    }
}
