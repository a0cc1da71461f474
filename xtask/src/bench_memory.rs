//! `cargo xtask bench-memory`: the peak resident memory of `calib simulate` and `calib fit
//! --method poe` on a measurement CSV of about 68 MB (issue 31: 1.63 GB before the identification
//! folded its Jacobian into a QR triangle, the bound is 400 MB), beside pandas reading the same
//! file as a user would (`xtask/scripts/read_csv_pandas.py`; a venv under `target/` with numpy
//! and pandas is made if `python3` lacks them, and the column is skipped, with a note, if that
//! fails).

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Peak memory of reading and fitting a large measurement file.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Full-pose rows to simulate: 242,000 is 65.7 MB of CSV, the 68 MB case.
    #[arg(long, default_value_t = 242_000)]
    rows: usize,
    /// Fail if `calib fit` peaks above this, MB (the bound).
    #[arg(long, default_value_t = 400.0)]
    max_fit_mb: f64,
    /// Leave out the pandas column.
    #[arg(long)]
    no_python: bool,
}

/// One measured run: wall clock and peak resident memory.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    pub seconds: f64,
    pub peak_mb: f64,
}

/// The `calib` binary of the release profile (or the dev one, which this workspace optimises
/// too and which `cargo test` has built already), built if needed.
pub fn calib_binary(release: bool) -> Result<PathBuf> {
    let root = crate::reproduce_sim::workspace_root();
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
    let robot = crate::reproduce_sim::workspace_root().join("fixtures/robots/irb4400.ron");
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

/// A `python3` with pandas: the system's, or a venv under `target/` made for it.
fn python_with_pandas() -> Result<PathBuf> {
    let has_pandas = |python: &Path| {
        Command::new(python).args(["-c", "import pandas"]).stderr(Stdio::null()).status().is_ok_and(|s| s.success())
    };
    let system = PathBuf::from("python3");
    if has_pandas(&system) {
        return Ok(system);
    }
    let venv = crate::reproduce_sim::workspace_root().join("target/bench-memory-venv");
    let python = venv.join("bin/python3");
    if !has_pandas(&python) {
        eprintln!("making {} with numpy and pandas (pip) …", venv.display());
        let made = Command::new("python3").arg("-m").arg("venv").arg(&venv).status()?;
        let pip = venv.join("bin/pip");
        let installed =
            made.success() && Command::new(&pip).args(["install", "--quiet", "numpy", "pandas"]).status()?.success();
        if !installed || !has_pandas(&python) {
            bail!("no python3 with pandas, and pip could not install it into {}", venv.display());
        }
    }
    Ok(python)
}

pub fn run(args: &Args) -> Result<()> {
    let calib = calib_binary(true)?;
    let dir = std::env::temp_dir().join(format!("calib-bench-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let result = table(&calib, &dir, args);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn table(calib: &Path, dir: &Path, args: &Args) -> Result<()> {
    let (simulate, fit, size_mb) = simulate_and_fit(calib, dir, args.rows)?;
    let pandas = if args.no_python {
        Err(anyhow::anyhow!("--no-python"))
    } else {
        python_with_pandas().and_then(|python| {
            let script = crate::reproduce_sim::workspace_root().join("xtask/scripts/read_csv_pandas.py");
            let (measured, out) = run_measured(Command::new(python).arg(script).arg(dir.join("large.csv")))?;
            // The script's own ru_maxrss is exact; the poll is the fallback.
            let own: Option<f64> = out.trim().parse().ok();
            Ok(Measured { peak_mb: own.unwrap_or(measured.peak_mb).max(measured.peak_mb), ..measured })
        })
    };
    println!("{} full-pose rows, {size_mb:.1} MB of CSV ({}):\n", args.rows, dir.join("large.csv").display());
    println!("| step | wall s | peak RSS MB | peak / file size |");
    println!("|---|---:|---:|---:|");
    let line = |what: &str, m: &Measured| {
        println!("| {what} | {:.1} | {:.0} | {:.1}× |", m.seconds, m.peak_mb, m.peak_mb / size_mb);
    };
    line("calib simulate --full-pose (streams its rows)", &simulate);
    line("calib fit --method poe (reads and fits)", &fit);
    match &pandas {
        Ok(p) => {
            line("python3: pandas.read_csv + to_numpy (reads only)", p);
            println!("\ncalib fit / pandas read: {:.2}× the memory", fit.peak_mb / p.peak_mb);
        }
        Err(e) => println!("| pandas.read_csv | – | – | skipped: {e:#} |"),
    }
    if fit.peak_mb > args.max_fit_mb {
        bail!("calib fit peaked at {:.0} MB, above the bound of {} MB", fit.peak_mb, args.max_fit_mb);
    }
    println!("calib fit within {} MB: ok", args.max_fit_mb);
    Ok(())
}
