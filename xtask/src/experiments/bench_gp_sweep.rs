//! `cargo xtask bench-gp` (its default): the GP stage from 300 to 100,000 poses as a user runs it.
//!
//! One simulated IRB 4400 campaign (`calib simulate --seed 7`: joint compliance under gravity and
//! the paper's payloads, tracker noise) of `max(sizes) + 3000` poses; for each n, `calib fit
//! --method poe-gp-load` on the first n poses with the exact and with the sparse GP, each in its own
//! process (wall clock and peak resident memory, `VmHWM` sampled every 20 ms), then `calib eval`
//! on the last 3000 poses. scikit-learn (`C·RBF(ARD) + C + White`, one GP per output on 2
//! processes, 1 restart) is given the residuals `poe` leaves on the same first n poses (payload as
//! an input, as `poe-gp-load`'s GP) and is stopped after `--sklearn-timeout-s`, and not started
//! again at larger sizes. An exact fit whose time predicted from the last measured size (n³)
//! exceeds `--exact-budget-s` is skipped and the prediction printed instead.

use anyhow::Context;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::experiments::chart::{Canvas, escape};
use indicatif::{ProgressBar, ProgressStyle};

use super::bench_gp_residuals::{heldout_mm, residuals};
use super::bench_gp_sklearn::{SklearnOptions, available, fit_predict};

/// Options of the sweep.
#[derive(Debug, Clone, clap::Args)]
pub struct SweepArgs {
    /// Training sizes.
    #[arg(long, value_delimiter = ',', default_value = "300,1000,3000,10000,100000")]
    pub sizes: Vec<usize>,
    /// Skip an exact fit predicted (n³ from the last one) to take longer than this.
    #[arg(long, default_value_t = 300.0)]
    pub exact_budget_s: f64,
    /// Stop scikit-learn after this long; skip it where the n³ prediction exceeds it.
    #[arg(long, default_value_t = 300.0)]
    pub sklearn_timeout_s: f64,
    /// Folder for the campaign, the models and the per-size CSVs.
    #[arg(long, default_value = "target/bench-gp-sweep")]
    pub work: PathBuf,
}

/// One measured (or skipped) fit.
#[derive(Debug, Clone)]
enum Cell {
    Measured { seconds: f64, peak_mb: f64, heldout_mm: f64 },
    Skipped(String),
}

impl Cell {
    fn seconds(&self) -> Option<f64> {
        match self {
            Cell::Measured { seconds, .. } => Some(*seconds),
            Cell::Skipped(_) => None,
        }
    }
    fn markdown(&self) -> String {
        match self {
            Cell::Measured { seconds, peak_mb, heldout_mm } => {
                format!("{seconds:.1} | {peak_mb:.0} | {heldout_mm:.4}")
            }
            Cell::Skipped(why) => format!("– | – | {why}"),
        }
    }
}

fn calib_binary(root: &Path) -> anyhow::Result<PathBuf> {
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(["build", "--release", "--quiet", "-p", "calib"])
        .current_dir(root)
        .status()
        .context("cargo build")?;
    if !status.success() {
        anyhow::bail!("cargo build --release -p calib failed");
    }
    let target = std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root.join("target"));
    Ok(target.join("release").join("calib"))
}

/// Runs `command` to completion; its wall clock and its peak resident memory in MB.
fn run_measured(command: &mut Command) -> anyhow::Result<(f64, f64)> {
    let start = Instant::now();
    let mut child = command.stdout(Stdio::null()).stderr(Stdio::piped()).spawn().context("spawn")?;
    let status_path = format!("/proc/{}/status", child.id());
    let mut peak_kb = 0.0f64;
    let status = loop {
        if let Ok(text) = std::fs::read_to_string(&status_path)
            && let Some(line) = text.lines().find(|l| l.starts_with("VmHWM:"))
        {
            let kb: f64 = line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or(0.0);
            peak_kb = peak_kb.max(kb);
        }
        match child.try_wait()? {
            Some(status) => break status,
            None => std::thread::sleep(Duration::from_millis(20)),
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    if !status.success() {
        let mut err = String::new();
        if let Some(mut e) = child.stderr.take() {
            let _ = std::io::Read::read_to_string(&mut e, &mut err);
        }
        anyhow::bail!("{command:?} failed: {}", err.lines().last().unwrap_or(""));
    }
    Ok((seconds, peak_kb / 1024.0))
}

fn heldout_of(calib: &Path, model: &Path, test: &Path) -> anyhow::Result<f64> {
    let out = Command::new(calib)
        .args(["eval", "--json", "--model"])
        .arg(model)
        .arg("--data")
        .arg(test)
        .stderr(Stdio::null())
        .output()?;
    let report: model::EvalReport = serde_json::from_slice(&out.stdout).context("calib eval --json")?;
    Ok(report.errors.mean_position_error_mm)
}

/// The first `n` data rows of `csv` (header kept) written to `out`.
fn head_rows(csv: &str, n: usize, out: &Path) -> anyhow::Result<()> {
    let mut lines = csv.lines();
    let header = lines.next().unwrap_or_default();
    let mut text = String::with_capacity(csv.len());
    text.push_str(header);
    text.push('\n');
    for line in lines.take(n) {
        text.push_str(line);
        text.push('\n');
    }
    std::fs::write(out, text).with_context(|| out.display().to_string())
}

/// The last `n` data rows of `csv` (header kept) written to `out`.
fn tail_rows(csv: &str, n: usize, out: &Path) -> anyhow::Result<()> {
    let mut lines: Vec<&str> = csv.lines().collect();
    let header = lines.remove(0);
    let start = lines.len().saturating_sub(n);
    let mut text = format!("{header}\n");
    for line in &lines[start..] {
        text.push_str(line);
        text.push('\n');
    }
    std::fs::write(out, text).with_context(|| out.display().to_string())
}

/// Least-squares slope of `ln t` against `ln n` over the measured cells.
fn slope(sizes: &[usize], cells: &[Cell]) -> Option<f64> {
    let points: Vec<(f64, f64)> =
        sizes.iter().zip(cells).filter_map(|(n, c)| c.seconds().map(|t| ((*n as f64).ln(), t.ln()))).collect();
    if points.len() < 2 {
        return None;
    }
    let k = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / k, points.iter().map(|p| p.1).sum::<f64>() / k);
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some(sxy / sxx)
}

/// The n³ (exact) or n (sparse) prediction from the last measured cell.
fn predicted(sizes: &[usize], cells: &[Cell], n: usize, power: i32) -> Option<f64> {
    sizes.iter().zip(cells).rev().find_map(|(m, c)| c.seconds().map(|t| t * (n as f64 / *m as f64).powi(power)))
}

/// Runs the sweep; returns the markdown (with the SVG written beside `svg_path`).
pub fn run(args: &SweepArgs, svg_path: Option<&Path>) -> anyhow::Result<String> {
    let sweep = prepare(args)?;
    let with_sklearn = available();

    let bar = ProgressBar::new((args.sizes.len() * 3) as u64);
    bar.set_style(
        ProgressStyle::with_template("bench-gp sweep {msg} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let (mut exact, mut sparse, mut sklearn) = (Vec::new(), Vec::new(), Vec::new());
    for &n in &args.sizes {
        let train = sweep.work.join(format!("train-{n}.csv"));
        head_rows(&sweep.csv, n, &train)?;
        for (gp, cells, power) in [("exact", &mut exact, 3), ("sparse", &mut sparse, 1)] {
            bar.set_message(format!("n = {n}, {gp}"));
            let cell = fit_gp(&sweep, args, cells, n, gp, power, &train)?;
            bar.suspend(|| eprintln!("n = {n}, {gp}: {}", cell.markdown()));
            cells.push(cell);
            bar.inc(1);
        }
        bar.set_message(format!("n = {n}, scikit-learn"));
        let cell = if with_sklearn {
            fit_sklearn(&sweep, args, &sklearn, n, &train)?
        } else {
            Cell::Skipped("scikit-learn not importable".into())
        };
        bar.suspend(|| eprintln!("n = {n}, scikit-learn: {}", cell.markdown()));
        sklearn.push(cell);
        bar.inc(1);
    }
    bar.finish_and_clear();

    let md = table(&args.sizes, &exact, &sparse, &sklearn);
    if let Some(path) = svg_path {
        let series =
            [("exact GP", &exact, "#1f77b4"), ("sparse GP", &sparse, "#2ca02c"), ("scikit-learn", &sklearn, "#d62728")];
        let svg = plot(&args.sizes, &series);
        std::fs::write(path, svg).with_context(|| path.display().to_string())?;
    }
    Ok(md)
}

/// What every size shares: the binary, the robot, the campaign and its last rows to test on.
struct Sweep {
    calib: PathBuf,
    robot: PathBuf,
    work: PathBuf,
    /// The campaign's CSV text.
    csv: String,
    /// The test rows' file.
    test: PathBuf,
    description: robot::RobotDescription,
    read_options: measurements::ReadOptions,
    test_set: measurements::MeasurementSet,
}

/// Builds `calib`, simulates the campaign (unless the work folder has it) and writes its test rows.
fn prepare(args: &SweepArgs) -> anyhow::Result<Sweep> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().context("no workspace root")?.to_path_buf();
    let calib = calib_binary(&root)?;
    let robot = root.join("fixtures/robots/irb4400.ron");
    let work = if args.work.is_absolute() { args.work.clone() } else { root.join(&args.work) };
    std::fs::create_dir_all(&work).with_context(|| work.display().to_string())?;
    let largest = *args.sizes.iter().max().context("no sizes")?;
    let test_rows = 3000;
    let campaign = work.join(format!("campaign-{}.csv", largest + test_rows));
    if !campaign.exists() {
        eprintln!("simulating {} poses …", largest + test_rows);
        let status = Command::new(&calib)
            .args(["simulate", "--seed", "7", "--rows", &(largest + test_rows).to_string(), "--robot"])
            .arg(&robot)
            .arg("--out")
            .arg(&campaign)
            .stdout(Stdio::null())
            .status()?;
        if !status.success() {
            anyhow::bail!("calib simulate failed");
        }
    }
    let csv = std::fs::read_to_string(&campaign).with_context(|| campaign.display().to_string())?;
    let test = work.join("test.csv");
    tail_rows(&csv, test_rows, &test)?;
    let description = robot::RobotDescription::read(&robot)?;
    let read_options = measurements::ReadOptions::for_joints(description.joint_kinds());
    let test_set = measurements::read_measurements(&test, &read_options)?;
    Ok(Sweep { calib, robot, work, csv, test, description, read_options, test_set })
}

/// `calib fit --gp GP` on the first `n` rows (`train`), or skipped where the exact GP's time
/// predicted from `cells` (the smaller sizes, as n^`power`) exceeds the budget.
fn fit_gp(
    sweep: &Sweep,
    args: &SweepArgs,
    cells: &[Cell],
    n: usize,
    gp: &str,
    power: i32,
    train: &Path,
) -> anyhow::Result<Cell> {
    let guess = predicted(&args.sizes, cells, n, power);
    let memory_gb = 3.0 * (n as f64).powi(2) * 8.0 / 1e9;
    Ok(match guess {
        Some(t) if gp == "exact" && t > args.exact_budget_s => {
            Cell::Skipped(format!("skipped: predicted {t:.0} s, {memory_gb:.1} GB"))
        }
        _ => {
            let model = sweep.work.join(format!("model-{gp}-{n}.ron"));
            let mut command = Command::new(&sweep.calib);
            command
                .args(["fit", "--method", "poe-gp-load", "--gp", gp, "--robot"])
                .arg(&sweep.robot)
                .arg("--data")
                .arg(train)
                .arg("--out")
                .arg(&model);
            let (seconds, peak_mb) = run_measured(&mut command)?;
            Cell::Measured { seconds, peak_mb, heldout_mm: heldout_of(&sweep.calib, &model, &sweep.test)? }
        }
    })
}

/// scikit-learn on the residuals `poe` leaves on the first `n` rows, unless a smaller size was
/// already stopped.
fn fit_sklearn(sweep: &Sweep, args: &SweepArgs, sklearn: &[Cell], n: usize, train: &Path) -> anyhow::Result<Cell> {
    let guess = predicted(&args.sizes, sklearn, n, 3);
    if sklearn.iter().any(|c: &Cell| c.seconds().is_none()) {
        // A smaller size was already stopped: this one would be too.
        return Ok(Cell::Skipped(format!("skipped: predicted {:.0} s", guess.unwrap_or(f64::INFINITY))));
    }
    let train_set = measurements::read_measurements(train, &sweep.read_options)?;
    let r = residuals(format!("n = {n}"), &sweep.description, &train_set, &sweep.test_set, true)?;
    let options = SklearnOptions {
        linear: false,
        isotropic: false,
        restarts: 1,
        independent: true,
        processes: 2,
        timeout: Duration::from_secs_f64(args.sklearn_timeout_s),
    };
    Ok(match fit_predict(&r.train.inputs, &r.train.outputs, &r.test.inputs, &options)? {
        Some(s) => {
            Cell::Measured { seconds: s.fit_s, peak_mb: s.peak_bytes / 1e6, heldout_mm: heldout_mm(&s.mean, &r.test) }
        }
        None => Cell::Skipped(format!("stopped after {:.0} s", args.sklearn_timeout_s)),
    })
}

/// The markdown table of every size and the log–log slopes.
fn table(sizes: &[usize], exact: &[Cell], sparse: &[Cell], sklearn: &[Cell]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "| n | exact: fit (s) | peak (MB) | held out (mm) | sparse: fit (s) | peak (MB) | held out (mm) | scikit-learn: fit (s) | peak (MB) | held out (mm) |"
    );
    let _ = writeln!(md, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (i, n) in sizes.iter().enumerate() {
        let _ =
            writeln!(md, "| {n} | {} | {} | {} |", exact[i].markdown(), sparse[i].markdown(), sklearn[i].markdown());
    }
    let fmt = |s: Option<f64>| s.map_or("–".to_owned(), |v| format!("{v:.2}"));
    let _ = writeln!(
        md,
        "\nLog–log slope of fit time against n (least squares over the measured sizes): exact {}, sparse {}, \
         scikit-learn {}.",
        fmt(slope(sizes, exact)),
        fmt(slope(sizes, sparse)),
        fmt(slope(sizes, sklearn))
    );
    md
}

/// Fit time against n, both axes logarithmic, one polyline per method.
fn plot(sizes: &[usize], series: &[(&str, &Vec<Cell>, &str)]) -> String {
    const CANVAS: Canvas = Canvas { width: 680.0, height: 420.0, left: 70.0, right: 150.0, top: 40.0, bottom: 50.0 };
    let times: Vec<f64> = series.iter().flat_map(|(_, c, _)| c.iter().filter_map(Cell::seconds)).collect();
    let t_lo = times.iter().copied().fold(f64::INFINITY, f64::min).clamp(1e-3, 1e6).log10().floor();
    let t_hi = times.iter().copied().fold(0.0, f64::max).max(1e-2).log10().ceil().max(t_lo + 1.0);
    let n_lo = (*sizes.iter().min().unwrap_or(&1) as f64).log10().floor();
    let n_hi = (*sizes.iter().max().unwrap_or(&10) as f64).log10().ceil().max(n_lo + 1.0);
    let (pw, ph) = (CANVAS.plot_width(), CANVAS.plot_height());
    let x = |n: f64| CANVAS.left + (n.log10() - n_lo) / (n_hi - n_lo) * pw;
    let y = |t: f64| CANVAS.top + ph - (t.log10() - t_lo) / (t_hi - t_lo) * ph;
    let mut svg = CANVAS.open("GP fit time against training poses (log–log)");
    let ticks: Vec<f64> = ((t_lo as i32)..=(t_hi as i32)).map(|e| 10f64.powi(e)).collect();
    CANVAS.y_grid(&mut svg, &ticks, &y);
    CANVAS.frame(&mut svg, "calib fit wall clock (s)");
    for e in (n_lo as i32)..=(n_hi as i32) {
        let _ = write!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            x(10f64.powi(e)),
            CANVAS.top + ph + 18.0,
            escape(&format!("{}", 10u64.pow(e.max(0) as u32)))
        );
    }
    let _ = write!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">training poses n</text>"#,
        CANVAS.left + pw / 2.0,
        CANVAS.height - 10.0
    );
    for (k, (name, cells, colour)) in series.iter().enumerate() {
        let points: Vec<(f64, f64)> =
            sizes.iter().zip(cells.iter()).filter_map(|(n, c)| c.seconds().map(|t| (x(*n as f64), y(t)))).collect();
        let list: Vec<String> = points.iter().map(|(a, b)| format!("{a:.1},{b:.1}")).collect();
        let _ =
            write!(svg, r#"<polyline fill="none" stroke="{colour}" stroke-width="2" points="{}"/>"#, list.join(" "));
        for (px, py) in &points {
            let _ = write!(svg, r#"<circle cx="{px:.1}" cy="{py:.1}" r="3" fill="{colour}"/>"#);
        }
        let ly = CANVAS.top + 16.0 + 18.0 * k as f64;
        let lx = CANVAS.left + pw + 12.0;
        let _ = write!(
            svg,
            r#"<line x1="{lx:.1}" y1="{ly:.1}" x2="{:.1}" y2="{ly:.1}" stroke="{colour}" stroke-width="2"/><text x="{:.1}" y="{:.1}">{}</text>"#,
            lx + 18.0,
            lx + 24.0,
            ly + 4.0,
            escape(name)
        );
    }
    svg.push_str("</svg>");
    svg
}
