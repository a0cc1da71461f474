//! `cargo xtask`: the paper's experiments and project automation. `main` only dispatches; each
//! command lives in a file of its own.

mod bench_fit;
mod bench_fit_data;
mod bench_fit_run;
mod bench_fit_sklearn;
mod bench_fit_table;
mod bench_gp;
mod bench_gp_compare;
mod bench_gp_kernels;
mod bench_gp_paper;
mod bench_gp_residuals;
mod bench_gp_sklearn;
mod bench_gp_sweep;
mod bench_identify;
mod bench_memory;
mod blind_check;
mod blind_check_cases;
mod box_plot;
mod cell_check;
mod chart;
mod compensate_check;
mod convert_ur10;
mod deps;
mod deps_features;
mod fuzz;
mod fuzz_inputs;
mod fuzz_seeds;
mod fuzz_worker;
mod hostile;
mod inputs_check;
mod long_tests;
mod msrv;
mod report_browser_check;
mod reproduce_sim;
mod reproduce_sim_params;
mod reproduce_sim_report;
mod simulation;
mod ur10;
mod ur10_placements;
mod urdf_check;

use clap::{Parser, Subcommand};
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
    /// The paper's simulation study (Fig. 1, Table I): writes docs/results/reproduce-sim.md and its box plot.
    ReproduceSim(reproduce_sim::Args),
    /// Time the release `calib` against issue 49's budgets, beside scikit-learn in the same run; print a table.
    BenchFit(Box<bench_fit::Args>),
    /// Time the gp crate (fit, predict, Cholesky vs peak, sparse vs exact, scikit-learn); print a markdown table.
    BenchGp(Box<bench_gp::Args>),
    /// Time the local POE identification against SciPy's least_squares on the same data; print a table.
    BenchIdentify(bench_identify::Args),
    /// Peak memory of `calib simulate` and `calib fit` on a ~68 MB CSV, beside pandas reading it.
    BenchMemory(bench_memory::Args),
    /// Issue 31's table of hostile-but-realistic inputs, run against the release `calib`.
    Hostile(hostile::Args),
    /// Convert the IPA UR10 tracker dataset to SPEC measurement CSV.
    ConvertUr10(convert_ur10::Args),
    /// Diagnose simulated datasets with a hidden effect, without the truth; print the confusion matrix.
    BlindCheck(blind_check::Args),
    /// Every method and the diagnosis on the real UR10 tracker data (Landgraf et al., CASE 2021).
    Ur10(ur10::Args),
    /// The UR10 as RON, DH and URDF on the real tracker data; the calibrated URDF exported and read back.
    UrdfCheck(urdf_check::Args),
    /// Compensated programs executed on the true simulated robot; 10,000 targets timed against SciPy.
    CompensateCheck(compensate_check::Args),
    /// Feed every file reader generated and broken inputs: no panic, crash or hang, bounded memory, located refusals.
    Fuzz(fuzz::Args),
    /// The Rust version Cargo.lock needs, checked against Cargo.toml and the README.
    Msrv(msrv::Args),
    /// The crate graph with lines per crate; fails on a crate above the line budget, a circle of crates or modules, or a crate CI builds alone that would not share the tests' build.
    Deps(deps::Args),
    /// The long tests kept out of CI (`#[ignore]`d, each standing beside a short one): `cargo test --workspace -- --ignored`.
    LongTests(long_tests::Args),
    /// Issue 46: measured signals (a base's tilt, a temperature) as GP inputs on simulated days; print a table.
    InputsCheck(inputs_check::Args),
    /// Issue 26: `calib register` and `calib plan` on the real UR10 and simulated truth; print a table.
    CellCheck(cell_check::Args),
    /// Render calibration reports in headless Chromium: a screenshot each, fail on console messages (not in CI).
    ReportBrowserCheck(report_browser_check::Args),
    /// One fuzz worker (started by `fuzz`).
    #[command(hide = true)]
    FuzzWorker(fuzz_worker::Args),
}

fn main() -> ExitCode {
    // faer's high-level operations (products, SVD, Cholesky) split their work by the global
    // thread count, so their last bits change with it; parallelism comes from our own rayon loops,
    // which write disjoint results in a fixed order. Results are then the same on 1 or 64 threads.
    faer::set_global_parallelism(faer::Par::Seq);
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::ReproduceSim(args) => reproduce_sim::run(args).map_err(|e| format!("{e:#}")),
        Command::BenchFit(args) => bench_fit::run(args).map_err(|e| format!("{e:#}")),
        Command::BenchGp(args) => bench_gp::run(args).map_err(|e| format!("{e:#}")),
        Command::BenchIdentify(args) => bench_identify::run(args).map_err(|e| format!("{e:#}")),
        Command::BenchMemory(args) => bench_memory::run(args).map_err(|e| format!("{e:#}")),
        Command::Hostile(args) => hostile::run(args).map_err(|e| format!("{e:#}")),
        Command::ConvertUr10(args) => convert_ur10::run(args).map_err(|e| format!("{e:#}")),
        Command::BlindCheck(args) => blind_check::run(args).map_err(|e| format!("{e:#}")),
        Command::Ur10(args) => ur10::run(args).map_err(|e| format!("{e:#}")),
        Command::InputsCheck(args) => inputs_check::run(args).map_err(|e| format!("{e:#}")),
        Command::CellCheck(args) => cell_check::run(args).map_err(|e| format!("{e:#}")),
        Command::UrdfCheck(args) => urdf_check::run(args).map_err(|e| format!("{e:#}")),
        Command::CompensateCheck(args) => compensate_check::run(args).map_err(|e| format!("{e:#}")),
        Command::Fuzz(args) => fuzz::run(args).map_err(|e| format!("{e:#}")),
        Command::Msrv(args) => msrv::run(args).map_err(|e| format!("{e:#}")),
        Command::Deps(args) => deps::run(args).map_err(|e| format!("{e:#}")),
        Command::LongTests(args) => long_tests::run(args).map_err(|e| format!("{e:#}")),
        Command::ReportBrowserCheck(args) => report_browser_check::run(args).map_err(|e| format!("{e:#}")),
        Command::FuzzWorker(args) => fuzz_worker::run(args).map_err(|e| format!("{e:#}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
