//! `calib`: the command-line tool.

use clap::Parser;

/// Make industrial robots accurate: fit, evaluate and diagnose kinematic calibrations.
#[derive(Debug, Parser)]
#[command(name = "calib", version, about, arg_required_else_help = true)]
struct Cli {}

fn main() {
    let _cli = Cli::parse();
}
