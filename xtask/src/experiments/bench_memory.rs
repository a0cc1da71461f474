//! `cargo xtask bench-memory`: the peak resident memory of `calib simulate` and `calib fit
//! --method poe` on a measurement CSV of about 68 MB (the bound is 400 MB; the identification
//! folds its Jacobian into a QR triangle so that its memory does not grow with the rows), beside
//! pandas reading the same file as a user would (`xtask/scripts/read_csv_pandas.py`; a venv under
//! `target/` with numpy and pandas is made if `python3` lacks them, and the column is skipped, with
//! a note, if that fails).

use crate::calib_runs::{Measured, calib_binary, run_measured, simulate_and_fit};
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Peak memory of reading and fitting a large measurement file.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Full-pose rows to simulate: 242,000 is 65.7 MB of CSV, the 68 MB case.
    #[arg(long, default_value_t = 242_000)]
    rows: usize,
    /// Fail if `calib fit` peaks above this, MB (the memory bound).
    #[arg(long, default_value_t = 400.0)]
    max_fit_mb: f64,
    /// Leave out the pandas column.
    #[arg(long)]
    no_python: bool,
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
    let venv = crate::workspace_root().join("target/bench-memory-venv");
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
            let script = crate::workspace_root().join("xtask/scripts/read_csv_pandas.py");
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
