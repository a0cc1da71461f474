//! `cargo xtask report-browser-check`: render calibration reports (`calib report`) in headless
//! Chromium, take a screenshot of each, and fail on anything the page logs to the console. Not
//! run by CI (it needs Chromium: `apt-get install -y chromium`).
//!
//! The page has no script, so any console message at all (a failed resource load, a parse
//! error) is a defect: Chromium with `--enable-logging=stderr` writes each as a line containing
//! `CONSOLE`, and the check fails on the first. A missing or empty screenshot fails it too.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Render HTML reports in headless Chromium; save a screenshot of each; fail on console messages.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The reports (from `calib report --out`).
    #[arg(required = true)]
    html: Vec<PathBuf>,
    /// Folder for the screenshots (`<report name>.png`).
    #[arg(long, default_value = "target/report-shots")]
    shots: PathBuf,
    /// The Chromium binary.
    #[arg(long, default_value = "/usr/bin/chromium")]
    chromium: PathBuf,
    /// Window size, `WIDTH,HEIGHT` pixels: the page's 1120-pixel column with a margin, and the
    /// first screens of it.
    #[arg(long, default_value = "1280,2400")]
    window_size: String,
}

pub fn run(args: &Args) -> Result<()> {
    if !args.chromium.exists() {
        bail!("{} not found: install it with `apt-get install -y chromium`", args.chromium.display());
    }
    std::fs::create_dir_all(&args.shots).with_context(|| format!("making {}", args.shots.display()))?;
    let mut failures = Vec::new();
    for html in &args.html {
        match check(args, html) {
            Ok(shot) => println!("ok    {} -> {}", html.display(), shot.display()),
            Err(e) => {
                println!("FAIL  {}: {e:#}", html.display());
                failures.push(html.display().to_string());
            }
        }
    }
    if !failures.is_empty() {
        bail!("{} report(s) failed in the browser: {}", failures.len(), failures.join(", "));
    }
    Ok(())
}

/// Renders one report; returns its screenshot's path.
fn check(args: &Args, html: &Path) -> Result<PathBuf> {
    let page = std::fs::canonicalize(html).with_context(|| format!("reading {}", html.display()))?;
    let stem = page.file_stem().map_or_else(|| "report".into(), |s| s.to_string_lossy().into_owned());
    let shot = std::fs::canonicalize(&args.shots)?.join(format!("{stem}.png"));
    // A fresh profile each time: no cache, no state from an earlier run.
    let profile = std::env::temp_dir().join(format!("calib-report-chromium-{}-{stem}", std::process::id()));
    std::fs::create_dir_all(&profile)?;
    let _ = std::fs::remove_file(&shot);
    let output = Command::new(&args.chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("--window-size={}", args.window_size))
        .arg(format!("file://{}", page.display()))
        .output()
        .with_context(|| format!("running {}", args.chromium.display()))?;
    let _ = std::fs::remove_dir_all(&profile);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let console: Vec<&str> = stderr.lines().filter(|l| l.contains("CONSOLE") || l.contains("Uncaught")).collect();
    if !console.is_empty() {
        bail!("the page logged to the console:\n{}", console.join("\n"));
    }
    if !output.status.success() {
        bail!("chromium exited with {}:\n{stderr}", output.status);
    }
    let size = std::fs::metadata(&shot).map(|m| m.len()).unwrap_or(0);
    if size == 0 {
        bail!("no screenshot was written to {}:\n{stderr}", shot.display());
    }
    Ok(shot)
}
