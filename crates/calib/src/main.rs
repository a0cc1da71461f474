//! `calib`: the command-line tool. `main` only parses and dispatches; each subcommand lives in a
//! file of its own and prints through its own functions.

mod args;
mod compensate;
mod diagnose;
mod eval;
mod export;
mod fit;
mod plan;
mod predict;
mod progress;
mod register;
mod report;
mod robot_args;
mod simulate;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Make industrial robots accurate: fit, evaluate and diagnose kinematic calibrations.
#[derive(Debug, Parser)]
#[command(
    name = "calib",
    version,
    about,
    arg_required_else_help = true,
    after_help = "The formats (measurement CSV, robot RON and URDF, model file, the CSV and JSON the commands print) \
                  are those of docs/SPEC.md, version 3."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    Fit(fit::Args),
    Eval(eval::Args),
    Predict(predict::Args),
    Diagnose(diagnose::Args),
    Simulate(simulate::Args),
    Export(export::Args),
    Compensate(compensate::Args),
    Register(register::Args),
    Plan(plan::Args),
    Report(report::Args),
}

fn main() -> ExitCode {
    // faer's high-level operations (products, SVD, Cholesky) split their work by the global
    // thread count, so their last bits change with it; parallelism comes from our own rayon loops,
    // which write disjoint results in a fixed order. Results are then the same on 1 or 64 threads.
    faer::set_global_parallelism(faer::Par::Seq);
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                e.exit();
            }
            // The SPEC asks for one clear line on stderr: clap's first line says what is wrong.
            let rendered = e.render().to_string();
            eprintln!("{}", rendered.lines().next().unwrap_or("error: invalid arguments"));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Fit(args) => fit::run(&args),
        Command::Eval(args) => eval::run(&args),
        Command::Predict(args) => predict::run(&args),
        Command::Diagnose(args) => diagnose::run(&args),
        Command::Simulate(args) => simulate::run(&args),
        Command::Export(args) => export::run(&args),
        Command::Compensate(args) => compensate::run(&args),
        Command::Register(args) => register::run(&args),
        Command::Plan(args) => plan::run(&args),
        Command::Report(args) => report::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
