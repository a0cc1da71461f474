//! The `calib` binary built and run as a user runs it, measured: wall clock and peak resident
//! memory. Shared by a check (`hostile --with-memory` holds `calib fit` to its memory bound) and
//! by the benchmarks (`bench-memory`, `bench-fit`), so that both measure the same way.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One measured run: wall clock and peak resident memory.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    pub seconds: f64,
    pub peak_mb: f64,
}

/// The `calib` binary of the release profile (or the dev one, which this workspace optimises
/// too and which `cargo test` has built already), built if needed.
pub fn calib_binary(release: bool) -> Result<PathBuf> {
    let root = crate::workspace_root();
    let profile: &[&str] = if release { &["--release"] } else { &[] };
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .arg("build")
        .args(profile)
        .args(["--quiet", "-p", "calib"])
        .current_dir(&root)
        .status()
        .context("cargo build --release -p calib")?;
    if !status.success() {
        bail!("cargo build --release -p calib failed");
    }
    let target = std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root.join("target"));
    Ok(target.join(if release { "release" } else { "debug" }).join("calib"))
}

/// Runs `command` to completion, polling the child's high-water mark (`VmHWM`, which only
/// grows, so a poll every 5 ms misses at most the last 5 ms of growth); its stdout on success.
pub fn run_measured(command: &mut Command) -> Result<(Measured, String)> {
    let start = Instant::now();
    let mut child =
        command.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().with_context(|| format!("spawn {command:?}"))?;
    let status_path = format!("/proc/{}/status", child.id());
    let mut peak_kb = 0.0f64;
    // Drain stdout on a thread so that a chatty child never blocks on a full pipe.
    let mut stdout = child.stdout.take().context("child stdout")?;
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut stdout, &mut text);
        text
    });
    let status = loop {
        if let Ok(text) = std::fs::read_to_string(&status_path)
            && let Some(line) = text.lines().find(|l| l.starts_with("VmHWM:"))
        {
            let kb: f64 = line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or(0.0);
            peak_kb = peak_kb.max(kb);
        }
        if let Some(status) = child.try_wait()? {
            break status;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let seconds = start.elapsed().as_secs_f64();
    let out = reader.join().unwrap_or_default();
    if !status.success() {
        let mut err = String::new();
        if let Some(mut e) = child.stderr.take() {
            let _ = std::io::Read::read_to_string(&mut e, &mut err);
        }
        bail!("{command:?} failed: {}", err.trim());
    }
    Ok((Measured { seconds, peak_mb: peak_kb / 1024.0 }, out))
}

/// `calib simulate` of `rows` full-pose IRB 4400 rows into `csv`, then `calib fit --method poe`
/// on it: both measured, and the file's size in MB.
pub fn simulate_and_fit(calib: &Path, dir: &Path, rows: usize) -> Result<(Measured, Measured, f64)> {
    let robot = crate::workspace_root().join("fixtures/robots/irb4400.ron");
    let csv = dir.join("large.csv");
    let (simulate, _) =
        run_measured(Command::new(calib).arg("simulate").arg("--robot").arg(&robot).arg("--out").arg(&csv).args([
            "--rows",
            &rows.to_string(),
            "--full-pose",
        ]))?;
    let size_mb = std::fs::metadata(&csv)?.len() as f64 / 1e6;
    let (fit, _) = run_measured(
        Command::new(calib)
            .arg("fit")
            .arg("--robot")
            .arg(&robot)
            .arg("--data")
            .arg(&csv)
            .args(["--method", "poe", "--out"])
            .arg(dir.join("large.ron")),
    )?;
    Ok((simulate, fit, size_mb))
}
