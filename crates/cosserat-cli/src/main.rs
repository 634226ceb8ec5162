//! The `cosserat` command (see the crate `cosserat_cli`).

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    cosserat_cli::run(cosserat_cli::cli::Cli::parse())
}
