//! The paper's experiments and the benchmarks: each measures (errors, times, memory) and prints
//! or writes a table, most of them for `docs/results/`; several need the real UR10 data beside
//! the repository, SciPy or scikit-learn. A number that changes here is a result to explain, not
//! by itself a defect (the checks in `crate::checks` say what is).
//!
//! Nothing here imports `crate::checks`; what both sides need lives at the crate root.

pub mod bench_fit;
pub mod bench_fit_data;
pub mod bench_fit_run;
pub mod bench_fit_sklearn;
pub mod bench_fit_table;
pub mod bench_gp;
pub mod bench_gp_compare;
pub mod bench_gp_kernels;
pub mod bench_gp_paper;
pub mod bench_gp_residuals;
pub mod bench_gp_sklearn;
pub mod bench_gp_sweep;
pub mod bench_identify;
pub mod bench_memory;
pub mod box_plot;
pub mod cell_check;
pub mod chart;
pub mod compensate_check;
pub mod convert_ur10;
pub mod inputs_check;
pub mod reproduce_sim;
pub mod reproduce_sim_params;
pub mod reproduce_sim_report;
pub mod ur10;
pub mod ur10_placements;
pub mod urdf_check;

/// The experiments' and benchmarks' commands.
#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// The paper's simulation study (Fig. 1, Table I): writes docs/results/reproduce-sim.md and its box plot.
    ReproduceSim(reproduce_sim::Args),
    /// Time the release `calib` against the fit's time budgets, beside scikit-learn in the same run; print a table.
    BenchFit(Box<bench_fit::Args>),
    /// Time the gp crate (fit, predict, Cholesky vs peak, sparse vs exact, scikit-learn); print a markdown table.
    BenchGp(Box<bench_gp::Args>),
    /// Time the local POE identification against SciPy's least_squares on the same data; print a table.
    BenchIdentify(bench_identify::Args),
    /// Peak memory of `calib simulate` and `calib fit` on a ~68 MB CSV, beside pandas reading it.
    BenchMemory(bench_memory::Args),
    /// Convert the IPA UR10 tracker dataset to SPEC measurement CSV.
    ConvertUr10(convert_ur10::Args),
    /// Every method and the diagnosis on the real UR10 tracker data (Landgraf et al., CASE 2021).
    Ur10(ur10::Args),
    /// The UR10 as RON, DH and URDF on the real tracker data; the calibrated URDF exported and read back.
    UrdfCheck(urdf_check::Args),
    /// Compensated programs executed on the true simulated robot; 10,000 targets timed against SciPy.
    CompensateCheck(compensate_check::Args),
    /// Measured signals (a base's tilt, a temperature) as GP inputs on simulated days; print a table.
    InputsCheck(inputs_check::Args),
    /// `calib register` and `calib plan` on the real UR10 and simulated truth; print a table.
    CellCheck(cell_check::Args),
}

impl Command {
    /// Runs the experiment.
    pub fn run(&self) -> anyhow::Result<()> {
        match self {
            Command::ReproduceSim(args) => reproduce_sim::run(args),
            Command::BenchFit(args) => bench_fit::run(args),
            Command::BenchGp(args) => bench_gp::run(args),
            Command::BenchIdentify(args) => bench_identify::run(args),
            Command::BenchMemory(args) => bench_memory::run(args),
            Command::ConvertUr10(args) => convert_ur10::run(args),
            Command::Ur10(args) => ur10::run(args),
            Command::UrdfCheck(args) => urdf_check::run(args),
            Command::CompensateCheck(args) => compensate_check::run(args),
            Command::InputsCheck(args) => inputs_check::run(args),
            Command::CellCheck(args) => cell_check::run(args),
        }
    }
}
