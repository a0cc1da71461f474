//! `cargo xtask`: the paper's experiments and project automation. `main` only dispatches; each
//! command lives in a file of its own.

use clap::Parser;

/// Project automation for the calib workspace.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask", arg_required_else_help = true)]
struct Cli {}

fn main() {
    let _cli = Cli::parse();
}
