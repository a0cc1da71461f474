//! `cargo xtask long-tests`: the tests kept out of CI (`#[ignore = "long …: cargo xtask long-tests"]`), each of which
//! proves at full size what a short test of the suite proves in seconds (CI within 20
//! minutes on the 2-core machine). A person runs them before a change that touches what they
//! guard; `docs/results/ci-time.md` lists them with the short test that stands for each.

use anyhow::{Context, Result, ensure};
use std::process::Command;

/// Run the ignored (long) tests of the workspace: `cargo test --workspace -- --ignored`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Only the tests whose names contain this (passed to the test harness as its filter).
    filter: Option<String>,
    /// Build and run them in the release profile (the dev profile, which CI's tests use, by default).
    #[arg(long)]
    release: bool,
}

pub fn run(args: &Args) -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let mut command = Command::new(&cargo);
    command.current_dir(crate::workspace_root()).args(["test", "--workspace"]);
    if args.release {
        command.arg("--release");
    }
    command.args(["--", "--ignored"]);
    command.args(args.filter.as_slice());
    let status = command.status().with_context(|| format!("running {cargo} test"))?;
    ensure!(status.success(), "the long tests failed ({status})");
    Ok(())
}
