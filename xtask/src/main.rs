//! `cargo xtask`: the project's own checks (`checks`: is the code still right?) and the paper's
//! experiments and benchmarks (`experiments`: what does it measure?). `main` only dispatches; each
//! command lives in a file of its own under one of the two.

mod calib_runs;
mod checks;
mod experiments;
mod simulation;

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Project automation for the calib workspace.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask", arg_required_else_help = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    #[command(flatten)]
    Experiment(experiments::Command),
    #[command(flatten)]
    Check(checks::Command),
}

/// The workspace root, so that the defaults work from any directory.
pub(crate) fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

fn main() -> ExitCode {
    // faer's high-level operations (products, SVD, Cholesky) split their work by the global
    // thread count, so their last bits change with it; parallelism comes from our own rayon loops,
    // which write disjoint results in a fixed order. Results are then the same on 1 or 64 threads.
    faer::set_global_parallelism(faer::Par::Seq);
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Experiment(command) => command.run(),
        Command::Check(command) => command.run(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
