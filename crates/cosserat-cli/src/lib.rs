//! The `cosserat` command: the command-line grammar ([`cli`], fuzzed in
//! the tests), one module per command, the exit-code table ([`exit`]),
//! signal handling ([`signals`]), charts and the validation runner. The
//! computations are the `cosserat` library's; this crate reads arguments,
//! claims outputs, reports progress and draws. Nothing depends on it.
//!
//! # From a command line to a file
//!
//! `main.rs` parses the arguments into a [`cli::Cli`] and calls [`run`],
//! which hands each subcommand to its module:
//!
//! | command | module | library stages it drives | writes |
//! |---|---|---|---|
//! | `solve`, `stability` | [`solve_command`] | `input::Problem` → `bvp::solve` → `stability::analyze` or `stability::critical_load` | an equilibrium or a stability report (HDF5) |
//! | `continue`, `plot` | [`continue_command`] | `input::Problem`'s `Family` → `continuation::continuation` (or `resume`) | a `Diagram` (HDF5), its chart by [`plot`] |
//! | `optimize` | [`optimize_command`] | `study::arm::ArmProblem` → `ArmOptimum`, its reach map and loading / control paths | the study (HDF5), its chart by [`arm_chart`] (Fig. 5) |
//! | `sweep`, `merge` | [`sweep_command`] | `study::sweep::Sweep` → `study::sweep::run` over `ArmJob` or `SolveJob` | checkpointed records (HDF5), merged shards, charts by [`sweep_figure`] and [`sweep_chart`] (Figs. 6, 7) |
//! | `validate` | [`validate`] | every case of validation/*.toml with every method, against `cosserat::references` | a Markdown report |
//! | `export` | [`export_command`] (reads through [`shape_file`]) | none: the shapes a result file holds | VTK (.vtp, .pvd) or XDMF (.xmf) for ParaView |
//! | `bench` | [`mod@bench`], [`bench_timed`] (accuracy by [`bench_accuracy`], CSV by [`bench_record`]) | `bvp::solve` for every method and order; the `compute_*` functions of `solve`, `stability`, `optimize` and the continuation | a work-precision chart and CSV; timings with accuracy (CSV) |
//!
//! Every command first reads its problem (`cosserat::input::Problem`, the only
//! reader of problem files) and claims its outputs
//! (`cosserat::output::target::claim`: never an input, never a non-regular
//! file, locked), then computes, then writes atomically. Failures map to
//! the exit codes of [`exit`] (0, 1 output, 2 bad input, 3 no result, 130
//! interrupted); [`signals`] turns SIGINT, SIGTERM and SIGHUP into a stop
//! at the next point for the commands that work point by point. The stages
//! themselves, and the data between them, are described in the `cosserat`
//! crate's documentation and docs/ARCHITECTURE.md.

#![warn(missing_docs)]

pub mod arm_chart;
pub mod axis_label;
pub mod bench;
pub mod bench_accuracy;
pub mod bench_record;
pub mod bench_timed;
pub mod chain;
pub mod chart_style;
pub mod cli;
pub mod continue_command;
pub mod curve_command;
pub mod energies;
pub mod exit;
pub mod export_command;
pub mod optimize_command;
pub mod optimize_spatial;
pub mod plot;
pub mod progress;
pub mod shape_file;
pub mod signals;
pub mod solve_command;
pub mod spatial_arm_chart;
pub mod stored_start;
pub mod sweep_chart;
pub mod sweep_command;
pub mod sweep_figure;
pub mod taper_chart;
pub mod taper_command;
pub mod validate;

use std::process::ExitCode;

use cli::{Cli, Command};

/// The `cosserat` command with a program's own energies: every command
/// reads problem files with `catalog` (the standard energies plus the
/// program's, [`cosserat::model::EnergyCatalog::register`]), so a binary
/// with one extra energy is `fn main() -> ExitCode {
/// cosserat_cli::main_with_energies(catalog) }` (examples/own_energy.rs).
pub fn main_with_energies(catalog: cosserat::model::EnergyCatalog) -> ExitCode {
    use clap::Parser;
    run_with_energies(Cli::parse(), catalog)
}

/// [`run`] with the energies of `catalog`; refused (exit 2) if this
/// process already read a problem with another catalog.
pub fn run_with_energies(cli: Cli, catalog: cosserat::model::EnergyCatalog) -> ExitCode {
    if !energies::install(catalog) {
        return exit::fail(
            exit::BAD_INPUT,
            "the energy catalog was already set in this process",
        );
    }
    run(cli)
}

/// Runs a parsed command line; the exit code of the table in [`exit`].
pub fn run(cli: Cli) -> ExitCode {
    signals::install();
    match cli.command {
        Command::Solve {
            problem,
            output,
            method,
            mut set,
            force,
        } => {
            if let Some(m) = method {
                set.push(format!("solver.method=\"{m}\""));
            }
            solve_command::run_solve(&problem, output.as_deref(), &set, force)
        }
        Command::Stability {
            problem,
            output,
            set,
            force,
        } => solve_command::run_stability(&problem, output.as_deref(), &set, force),
        Command::Continue {
            problem,
            output,
            plot,
            resume,
            from,
            point,
            curve,
            set,
            force,
        } => continue_command::run_continue(&continue_command::ContinueArgs {
            path: &problem,
            output: &output,
            plot: plot.as_deref(),
            set: &set,
            force,
            resume,
            from: from.as_deref().map(|f| (f, point.as_deref())),
            curve,
        }),
        Command::Optimize {
            problem,
            output,
            loading_path,
            control_path,
            holding_path,
            plot,
            resume,
            set,
            force,
        } => optimize_command::run_optimize(&optimize_command::OptimizeRun {
            path: problem,
            output,
            loading_path,
            control_path,
            holding_path,
            plot,
            set,
            force,
            resume,
        }),
        Command::Sweep {
            problem,
            output,
            shard,
            threads,
            resume,
            plot,
            set,
            force,
        } => sweep_command::run_sweep(&sweep_command::SweepArgs {
            path: problem,
            output,
            shard,
            threads,
            resume,
            plot,
            set,
            force,
        }),
        Command::Merge {
            inputs,
            output,
            plot,
            force,
        } => sweep_command::run_merge(&inputs, &output, plot.as_deref(), force),
        Command::Export(args) => export_command::run_export(&args),
        Command::Plot {
            diagram,
            output,
            measure,
            force,
        } => continue_command::run_plot(&diagram, &measure, &output, force),
        Command::Bench { which } => bench::run(which),
        Command::CheckEnergy { problem, set } => energies::run_check(&problem, &set),
        Command::Validate(args) => validate::run_cli(&args),
    }
}
