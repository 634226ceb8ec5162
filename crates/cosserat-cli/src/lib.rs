//! The `cosserat` command: the command-line grammar ([`cli`], fuzzed in
//! the tests), one module per command, the exit-code table ([`exit`]),
//! signal handling ([`signals`]), charts and the validation runner. The
//! computations are the `cosserat` library's; this crate reads arguments,
//! claims outputs, reports progress and draws.

#![warn(missing_docs)]

pub mod arm_chart;
pub mod bench;
pub mod cli;
pub mod continue_command;
pub mod exit;
pub mod optimize_command;
pub mod plot;
pub mod signals;
pub mod solve_command;
pub mod sweep_chart;
pub mod sweep_command;
pub mod sweep_figure;
pub mod validate;

use std::process::ExitCode;

use cli::{Cli, Command};

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
            solve_command::run_solve(problem, output, &set, force)
        }
        Command::Stability {
            problem,
            output,
            set,
            force,
        } => solve_command::run_stability(problem, output, &set, force),
        Command::Continue {
            problem,
            output,
            plot,
            resume,
            set,
            force,
        } => continue_command::run_continue(problem, output, plot, &set, force, resume),
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
        } => optimize_command::run_optimize(optimize_command::OptimizeRun {
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
        } => sweep_command::run_sweep(sweep_command::SweepArgs {
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
        Command::Plot {
            diagram,
            output,
            measure,
            force,
        } => continue_command::run_plot(&diagram, &measure, &output, force),
        Command::Bench { which } => bench::run(which),
        Command::Validate(args) => validate::run_cli(args),
    }
}
