//! The project's own checks: each answers "is the code still right?" with a pass or a fail,
//! runs on a fresh clone with nothing beside it (no real UR10 data, no Python), and writes no
//! numbers to `docs/results/`. CI runs most of them (`.ci/run`); a failure is a defect to fix.
//!
//! Nothing here imports `crate::experiments`: a check must not change because a benchmark did.
//! What both sides need lives beside them at the crate root (`simulation`, `calib_runs`).

pub mod blind_check;
pub mod blind_check_cases;
pub mod deps;
pub mod deps_features;
pub mod fuzz;
pub mod fuzz_inputs;
pub mod fuzz_seeds;
pub mod fuzz_worker;
pub mod hostile;
pub mod long_tests;
pub mod msrv;
pub mod report_browser_check;

/// The checks' commands.
#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// The crate graph with lines per crate; fails on a crate above the line budget, a circle of crates or modules, an xtask check and experiment importing one another, or a crate CI builds alone that would not share the tests' build.
    Deps(deps::Args),
    /// The Rust version Cargo.lock needs, checked against Cargo.toml and the README.
    Msrv(msrv::Args),
    /// Feed every file reader generated and broken inputs: no panic, crash or hang, bounded memory, located refusals.
    Fuzz(fuzz::Args),
    /// The table of hostile-but-realistic inputs (nothing lost, no fit that looks right and is not), run against the release `calib`.
    Hostile(hostile::Args),
    /// Diagnose simulated datasets with a hidden effect, without the truth; print the confusion matrix.
    BlindCheck(blind_check::Args),
    /// The long tests kept out of CI (`#[ignore]`d, each standing beside a short one): `cargo test --workspace -- --ignored`.
    LongTests(long_tests::Args),
    /// Render calibration reports in headless Chromium: a screenshot each, fail on console messages (not in CI).
    ReportBrowserCheck(report_browser_check::Args),
    /// One fuzz worker (started by `fuzz`).
    #[command(hide = true)]
    FuzzWorker(fuzz_worker::Args),
}

impl Command {
    /// Runs the check.
    pub fn run(&self) -> anyhow::Result<()> {
        match self {
            Command::Deps(args) => deps::run(args),
            Command::Msrv(args) => msrv::run(args),
            Command::Fuzz(args) => fuzz::run(args),
            Command::Hostile(args) => hostile::run(args),
            Command::BlindCheck(args) => blind_check::run(args),
            Command::LongTests(args) => long_tests::run(args),
            Command::ReportBrowserCheck(args) => report_browser_check::run(args),
            Command::FuzzWorker(args) => fuzz_worker::run(args),
        }
    }
}
