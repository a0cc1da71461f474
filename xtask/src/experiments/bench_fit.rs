//! `cargo xtask bench-fit`: how long a person waits for `calib`, against its time budgets and
//! beside what a user would run instead, on the same rows in the same run. Prints a markdown
//! table.
//!
//! Each row runs the release `calib` binary (`--calib`, or built here) as a user does: `calib fit
//! … --json` then `calib eval --json` on the held-out rows, or `calib diagnose --json`; the median
//! of `--runs` runs, with CPU time and peak memory. `--calib-base` runs a second binary the same
//! way, interleaved, for a before/after comparison in one table. Beside the `poe-gp` rows, the
//! scikit-learn GP on the same residuals (`bench_fit_sklearn`), once per row. Rows whose UR10 data are absent say
//! so; a failed command fails the run after the table is printed.

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use measurements::MeasurementSet;
use robot::RobotDescription;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use super::bench_fit_data::{Files, even_odd, position_only, read_csv, simulate, spread, ur10_series, write_pair};
use super::bench_fit_run::{heldout_of_eval, measure, phases_of_fit};
use super::bench_fit_sklearn::{PipelineOptions, SklearnKernel, SklearnSide, python_env, sklearn_pipeline};
use super::bench_fit_table::{Budget, Measured, Outcome, Row, Run, RunResult, Side, table};

/// Time `calib fit` and `calib diagnose` on the UR10 and simulated data against the
/// time budgets, beside scikit-learn; print a markdown table.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Only these rows, comma separated [default: all].
    #[arg(long, value_enum, value_delimiter = ',')]
    pub only: Vec<RowKey>,
    /// The IPA UR10 data set (a folder holding Series_B and Series_C, converted here as `cargo
    /// xtask convert-ur10 --full-pose` does), or a folder of converted SPEC CSVs (`C.csv` or
    /// `ur10_C.csv`, or `C_even.csv` with `C_odd.csv`; the same for B). Rows whose series is
    /// absent say so.
    #[arg(long, default_value = "../shared/data/ipa-ur10")]
    pub data: PathBuf,
    /// The `calib` binary to time [default: this checkout's, built with `cargo build --release`].
    #[arg(long)]
    pub calib: Option<PathBuf>,
    /// A second `calib` binary (say, before a change) run the same way, interleaved: its columns
    /// and the ratio beside the first's.
    #[arg(long)]
    pub calib_base: Option<PathBuf>,
    /// Runs of each command; the table gives the median.
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// No further run of a row once its runs so far took this many seconds (every binary's
    /// together): a slow row is measured fewer times, as the table's `runs` says.
    #[arg(long, default_value_t = 300.0)]
    pub repeat_limit_s: f64,
    /// A smoke run: sets cut to a few hundred rows, one run, scikit-learn without restarts, no
    /// verdicts.
    #[arg(long)]
    pub quick: bool,
    /// The Python with NumPy, SciPy and scikit-learn [default: $CALIB_PYTHON, target/pyenv, or
    /// python3; target/pyenv is made with pip if none imports scikit-learn].
    #[arg(long)]
    pub python: Option<PathBuf>,
    /// Leave out scikit-learn.
    #[arg(long)]
    pub skip_sklearn: bool,
    /// Also time SciPy's `least_squares` identifying the same rows before scikit-learn's GP
    /// (noted, not in the ratio).
    #[arg(long)]
    pub scipy_identify: bool,
    /// Stop a scikit-learn GP fit after this many seconds (its ratio is then a lower bound).
    #[arg(long, default_value_t = 3600.0)]
    pub sklearn_timeout_s: f64,
    /// Seed of the paper's setting (`calib simulate --robot irb4400.ron --rows 600 --seed SEED`;
    /// `bench-gp --paper`'s first seed).
    #[arg(long, default_value_t = 1)]
    pub paper_seed: u64,
    /// Also write the table to this file.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The rows, in the order they run and print.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RowKey {
    /// UR10 C even → odd, `poe-gp`, beside scikit-learn.
    CPoeGp,
    /// UR10 C even → odd, position only, `poe-gp`, beside scikit-learn.
    CPoeGpPosition,
    /// UR10 C even → odd, `poe --effects auto`.
    CPoeAuto,
    /// UR10 C even → odd, `poe-gp --effects auto`.
    CPoeGpAuto,
    /// `calib diagnose` on UR10 C's even rows.
    CDiagnose,
    /// UR10 B even → odd, `poe-gp`, beside scikit-learn.
    BPoeGp,
    /// UR10 B even → odd, `poe-gp --effects auto`.
    BPoeGpAuto,
    /// All of UR10 C, `poe-gp --effects auto`, tested on all of B.
    CAllPoeGpAuto,
    /// 100,000 simulated IRB 4400 poses (`calib simulate --rows 103000 --seed 7`), `poe-gp --gp
    /// sparse`, tested on the last 3,000.
    #[value(name = "sim-100k")]
    Sim100k,
    /// The paper's setting: a simulated IRB 4400 campaign, 300 poses to train, the next 300 to
    /// test, `poe-gp-load`, beside scikit-learn's Eq. 5 kernel.
    Paper,
}

/// What a row runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Work {
    /// `calib fit --method METHOD [--effects auto] [--gp sparse]`, then `calib eval`.
    Fit { method: &'static str, auto: bool, sparse: bool },
    /// `calib diagnose`.
    Diagnose,
}

/// The data a row is fitted on and tested with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Data {
    /// A UR10 series' even rows, tested on its odd rows.
    EvenOdd { series: &'static str, position_only: bool },
    /// All of C, tested on all of B.
    AllCOnB,
    /// `calib simulate --robot irb4400.ron --rows TRAIN+TEST --seed SEED`, first rows and rest.
    Simulated { name: &'static str, train: usize, test: usize, seed: Option<u64> },
}

impl RowKey {
    fn all() -> &'static [RowKey] {
        <RowKey as clap::ValueEnum>::value_variants()
    }

    /// The row's name in the table.
    pub fn label(self) -> &'static str {
        match self {
            RowKey::CPoeGp => "UR10 C even → odd, `poe-gp`",
            RowKey::CPoeGpPosition => "UR10 C even → odd, position only, `poe-gp`",
            RowKey::CPoeAuto => "UR10 C even → odd, `poe --effects auto`",
            RowKey::CPoeGpAuto => "UR10 C even → odd, `poe-gp --effects auto`",
            RowKey::CDiagnose => "UR10 C even, `diagnose`",
            RowKey::BPoeGp => "UR10 B even → odd, `poe-gp`",
            RowKey::BPoeGpAuto => "UR10 B even → odd, `poe-gp --effects auto`",
            RowKey::CAllPoeGpAuto => "UR10 all of C → all of B, `poe-gp --effects auto`",
            RowKey::Sim100k => "10⁵ simulated IRB 4400 poses, `poe-gp --gp sparse`",
            RowKey::Paper => "the paper's setting (simulated IRB 4400), `poe-gp-load`",
        }
    }

    /// The time budget for the row, on the 2-core machine.
    pub fn budget(self) -> Option<Budget> {
        match self {
            RowKey::CPoeGp | RowKey::CPoeGpPosition => Some(Budget::SpeedupAtLeast(40.0)),
            RowKey::CPoeAuto => Some(Budget::WallAtMost(8.0)),
            RowKey::CPoeGpAuto => Some(Budget::WallAtMost(25.0)),
            RowKey::CDiagnose => Some(Budget::WallAtMost(2.0)),
            RowKey::CAllPoeGpAuto => Some(Budget::WallAtMost(120.0)),
            RowKey::Sim100k => Some(Budget::WallAtMost(20.0)),
            RowKey::Paper => Some(Budget::GpStageSpeedupAtLeast(80.0)),
            RowKey::BPoeGp | RowKey::BPoeGpAuto => None,
        }
    }

    fn work(self) -> Work {
        let fit = |method, auto| Work::Fit { method, auto, sparse: false };
        match self {
            RowKey::CPoeAuto => fit("poe", true),
            RowKey::CPoeGp | RowKey::CPoeGpPosition | RowKey::BPoeGp => fit("poe-gp", false),
            RowKey::CPoeGpAuto | RowKey::BPoeGpAuto | RowKey::CAllPoeGpAuto => fit("poe-gp", true),
            RowKey::Sim100k => Work::Fit { method: "poe-gp", auto: false, sparse: true },
            RowKey::Paper => fit("poe-gp-load", false),
            RowKey::CDiagnose => Work::Diagnose,
        }
    }

    fn data(self) -> Data {
        let c = |position_only| Data::EvenOdd { series: "C", position_only };
        match self {
            RowKey::CPoeGp | RowKey::CPoeAuto | RowKey::CPoeGpAuto | RowKey::CDiagnose => c(false),
            RowKey::CPoeGpPosition => c(true),
            RowKey::BPoeGp | RowKey::BPoeGpAuto => Data::EvenOdd { series: "B", position_only: false },
            RowKey::CAllPoeGpAuto => Data::AllCOnB,
            RowKey::Sim100k => Data::Simulated { name: "irb100k", train: 100_000, test: 3_000, seed: Some(7) },
            RowKey::Paper => Data::Simulated { name: "paper", train: 300, test: 300, seed: None },
        }
    }

    /// scikit-learn's kernel beside the row, if it has the pipeline.
    fn sklearn(self) -> Option<SklearnKernel> {
        match self {
            RowKey::CPoeGp | RowKey::CPoeGpPosition | RowKey::BPoeGp => Some(SklearnKernel::Ard),
            RowKey::Paper => Some(SklearnKernel::Eq5),
            _ => None,
        }
    }
}

/// The rows `--only` selects, in the table's order, each once.
fn selected(only: &[RowKey]) -> Vec<RowKey> {
    RowKey::all().iter().copied().filter(|k| only.is_empty() || only.contains(k)).collect()
}

/// `--quick`'s cap on a set's rows: every set spread over at most this many (the 10⁵ poses over
/// [`QUICK_SIMULATED`]), enough to run every stage of every row.
const QUICK_ROWS: usize = 150;
/// `--quick`'s 10⁵-pose row: training and test poses (still the sparse GP: `--gp sparse`).
const QUICK_SIMULATED: (usize, usize) = (1_000, 300);

/// Where a row's data come from, made once per set into the work folder.
struct Inputs<'a> {
    args: &'a Args,
    calib: PathBuf,
    work: PathBuf,
    ur10: RobotDescription,
    irb: RobotDescription,
    /// Series C and B, read once (`None` inside: absent).
    c: Option<Option<MeasurementSet>>,
    b: Option<Option<MeasurementSet>>,
}

impl Inputs<'_> {
    fn robot_path(&self, key: RowKey) -> PathBuf {
        let file = if matches!(key.data(), Data::Simulated { .. }) { "irb4400.ron" } else { "ur10.ron" };
        crate::workspace_root().join("fixtures/robots").join(file)
    }

    fn robot(&self, key: RowKey) -> &RobotDescription {
        if matches!(key.data(), Data::Simulated { .. }) { &self.irb } else { &self.ur10 }
    }

    fn series(&mut self, name: &str) -> anyhow::Result<Option<MeasurementSet>> {
        let (dir, robot) = (self.args.data.clone(), &self.ur10);
        let slot = if name == "C" { &mut self.c } else { &mut self.b };
        if slot.is_none() {
            *slot = Some(ur10_series(&dir, robot, name)?);
        }
        Ok(slot.clone().flatten())
    }

    /// The row's training and test files, or why its data are absent.
    fn files(&mut self, key: RowKey) -> anyhow::Result<Result<Files, String>> {
        let cap = self.args.quick.then_some(QUICK_ROWS);
        let absent = |series: &str| format!("no UR10 series {series} in {}", self.args.data.display());
        let work = self.work.clone();
        Ok(match key.data() {
            Data::EvenOdd { series, position_only: drop } => match self.series(series)? {
                None => Err(absent(series)),
                Some(set) => {
                    let set = if drop { position_only(&set) } else { set };
                    let (even, odd) = even_odd(&set);
                    let name = format!("{series}{}", if drop { "_position" } else { "" });
                    Ok(write_pair(&work, &name, &spread(&even, cap), &spread(&odd, cap))?)
                }
            },
            Data::AllCOnB => match (self.series("C")?, self.series("B")?) {
                (Some(c), Some(b)) => {
                    Ok(write_pair(&work, "C_all", &spread(&c, cap.map(|c| 2 * c)), &spread(&b, cap))?)
                }
                (None, _) => Err(absent("C")),
                (_, None) => Err(absent("B")),
            },
            Data::Simulated { name, train, test, seed } => {
                let sizes = match (self.args.quick, key) {
                    (true, RowKey::Sim100k) => QUICK_SIMULATED,
                    (true, _) => (QUICK_ROWS, QUICK_ROWS),
                    (false, _) => (train, test),
                };
                let seed = seed.unwrap_or(self.args.paper_seed);
                Ok(simulate(&self.calib, &self.robot_path(key), &work, name, sizes, seed)?)
            }
        })
    }
}

/// The arguments of the row's timed command (after the binary).
fn command_args(key: RowKey, robot: &Path, files: &Files, model: &Path) -> Vec<String> {
    let path = |p: &Path| p.display().to_string();
    let mut args = vec![String::new(), "--robot".into(), path(robot), "--data".into(), path(&files.train)];
    match key.work() {
        Work::Diagnose => args[0] = "diagnose".into(),
        Work::Fit { method, auto, sparse } => {
            args[0] = "fit".into();
            args.extend(["--method".into(), method.into()]);
            if auto {
                args.extend(["--effects".into(), "auto".into()]);
            }
            if sparse {
                args.extend(["--gp".into(), "sparse".into()]);
            }
            args.extend(["--out".into(), path(model)]);
        }
    }
    args.push("--json".into());
    args
}

/// One run of `calib` on a row: the command timed, then the held-out evaluation.
fn one_run(
    calib: &Path,
    key: RowKey,
    robot: &Path,
    files: &Files,
    work: &Path,
    tick: &dyn Fn(f64),
) -> anyhow::Result<RunResult> {
    let model = work.join("model.ron");
    let _ = std::fs::remove_file(&model);
    let (cost, out) = measure(Command::new(calib).args(command_args(key, robot, files, &model)), tick)?;
    if key.work() == Work::Diagnose {
        return Ok(RunResult { cost, heldout: None, phases: Vec::new() });
    }
    let phases = phases_of_fit(&out)?;
    let eval = Command::new(calib)
        .arg("eval")
        .arg("--model")
        .arg(&model)
        .arg("--data")
        .arg(&files.test)
        .arg("--json")
        .output()
        .with_context(|| format!("{} eval", calib.display()))?;
    if !eval.status.success() {
        anyhow::bail!("{} eval: {}", calib.display(), String::from_utf8_lossy(&eval.stderr).trim());
    }
    let heldout = heldout_of_eval(&String::from_utf8_lossy(&eval.stdout), &files.test)?;
    Ok(RunResult { cost, heldout: Some(heldout), phases })
}

/// The interpreter of the scikit-learn side, or why it does not run.
fn python(args: &Args) -> Result<PathBuf, String> {
    if args.skip_sklearn {
        return Err("--skip-sklearn".into());
    }
    python_env(args.python.as_deref())
}

/// One row: its files, `runs` runs of each binary (alternating which goes first), and the
/// scikit-learn pipeline once.
fn measure_row(
    key: RowKey,
    inputs: &mut Inputs,
    binaries: &[(&str, &Path)],
    python: &Result<PathBuf, String>,
    bar: &ProgressBar,
) -> anyhow::Result<Outcome> {
    bar.set_message(format!("{}: preparing the data", key.label()));
    let files = match inputs.files(key)? {
        Ok(files) => files,
        Err(why) => return Ok(Outcome::Skipped(why)),
    };
    let results = timed_runs(key, inputs, binaries, &files, bar);
    let mut sides =
        results.into_iter().map(|r| r.and_then(|runs| Side::from_runs(&runs).ok_or_else(|| "no run".into())));
    let calib = sides.next().unwrap_or_else(|| Err("no binary".into()));
    let base = sides.next();
    let sklearn = key.sklearn().map(|kernel| sklearn_side(key, kernel, inputs, &files, python, bar));
    let data =
        format!("{} / {}, {}", files.rows.0, files.rows.1, if files.full_pose { "full pose" } else { "position only" });
    Ok(Outcome::Measured(Box::new(Measured { data, calib, base, sklearn })))
}

/// `runs` runs of each binary on the row's files, alternating which goes first, until
/// `--repeat-limit-s` is spent; a binary that fails runs no more.
fn timed_runs(
    key: RowKey,
    inputs: &Inputs,
    binaries: &[(&str, &Path)],
    files: &Files,
    bar: &ProgressBar,
) -> Vec<Result<Vec<RunResult>, String>> {
    let args = inputs.args;
    let robot = inputs.robot_path(key);
    let runs = if args.quick { 1 } else { args.runs.max(1) };
    let mut results: Vec<Result<Vec<RunResult>, String>> = vec![Ok(Vec::new()); binaries.len()];
    let mut spent_s = 0.0;
    for run in 0..runs {
        if run > 0 && spent_s >= args.repeat_limit_s {
            bar.suspend(|| {
                eprintln!("  {spent_s:.0} s spent: no more runs (--repeat-limit-s {})", args.repeat_limit_s)
            });
            break;
        }
        for turn in 0..binaries.len() {
            // Alternate which binary goes first, so neither always runs after the other's caches.
            let which = (turn + run) % binaries.len();
            let (name, calib) = binaries[which];
            let Ok(done) = &mut results[which] else { continue };
            let message = |s: f64| format!("{}: {name} run {}/{runs}, {s:.0} s", key.label(), run + 1);
            let tick = |s: f64| bar.set_message(message(s));
            match one_run(calib, key, &robot, files, &inputs.work, &tick) {
                Ok(result) => {
                    spent_s += result.cost.wall_s;
                    bar.suspend(|| eprintln!("  {}", message(result.cost.wall_s)));
                    done.push(result);
                }
                Err(e) => {
                    bar.suspend(|| eprintln!("  {name} failed: {e:#}"));
                    results[which] = Err(format!("{e:#}"));
                }
            }
        }
    }
    results
}

/// The scikit-learn pipeline once on the row's files (skipped without its interpreter), with the
/// kernel's text.
fn sklearn_side(
    key: RowKey,
    kernel: SklearnKernel,
    inputs: &Inputs,
    files: &Files,
    python: &Result<PathBuf, String>,
    bar: &ProgressBar,
) -> (String, SklearnSide) {
    let args = inputs.args;
    let restarts = kernel.restarts(args.quick);
    let side = match python {
        Err(why) => SklearnSide::Skipped(why.clone()),
        Ok(python) => {
            bar.set_message(format!("{}: scikit-learn (stopped after {} s)", key.label(), args.sklearn_timeout_s));
            let options = PipelineOptions {
                python: python.clone(),
                kernel,
                restarts,
                with_payload: matches!(key.work(), Work::Fit { method: "poe-gp-load", .. }),
                timeout: Duration::from_secs_f64(args.sklearn_timeout_s),
                scipy_identify: args.scipy_identify,
            };
            let robot = inputs.robot(key);
            let run =
                || sklearn_pipeline(robot, &read_csv(&files.train, robot)?, &read_csv(&files.test, robot)?, &options);
            run().unwrap_or_else(|e| SklearnSide::Skipped(format!("failed: {e:#}")))
        }
    };
    bar.suspend(|| eprintln!("  scikit-learn: {}", side.note()));
    (kernel.text(restarts), side)
}

/// `/proc/loadavg`'s 1, 5 and 15 minute averages.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// The binary to time and how it was found: `--calib`, or this checkout's release build.
fn calib_binary(args: &Args) -> anyhow::Result<(PathBuf, String)> {
    if let Some(path) = &args.calib {
        anyhow::ensure!(path.is_file(), "--calib {}: no such file", path.display());
        return Ok((path.clone(), path.display().to_string()));
    }
    eprintln!("bench-fit: cargo build --release -p calib …");
    let path = crate::calib_runs::calib_binary(true)?;
    let root = crate::workspace_root();
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .current_dir(&root)
            .output()
            .ok()
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
    };
    let commit = git(&["rev-parse", "--short", "HEAD"]).unwrap_or_default();
    let dirty = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
    let at = format!("{commit}{}", if dirty { " with uncommitted changes" } else { "" });
    Ok((path.clone(), format!("{} (release, built from {at})", path.display())))
}

/// Each selected row in turn, under a spinner; the rows measured, and the error that stopped
/// them (named by its row) if one did.
fn measure_rows(
    keys: &[RowKey],
    inputs: &mut Inputs,
    binaries: &[(&str, &Path)],
    python: &Result<PathBuf, String>,
) -> (Vec<Row>, anyhow::Result<()>) {
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}").unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(250));
    let mut rows = Vec::new();
    let mut result = Ok(());
    for (i, &key) in keys.iter().enumerate() {
        bar.suspend(|| eprintln!("bench-fit [{}/{}] {} (load {})", i + 1, keys.len(), key.label(), load_average()));
        match measure_row(key, inputs, binaries, python, &bar) {
            Ok(outcome) => rows.push(Row { label: key.label(), budget: key.budget(), outcome }),
            Err(e) => {
                bar.suspend(|| eprintln!("  failed: {e:#}"));
                result = Err(e.context(key.label()));
                break;
            }
        }
    }
    bar.finish_and_clear();
    (rows, result)
}

/// Runs the selected rows and prints the table; fails after printing it if a command failed.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let keys = selected(&args.only);
    let (calib, calib_text) = calib_binary(args)?;
    if let Some(base) = &args.calib_base {
        anyhow::ensure!(base.is_file(), "--calib-base {}: no such file", base.display());
    }
    let python = python(args);
    let work = std::env::temp_dir().join(format!("calib-bench-fit-{}", std::process::id()));
    std::fs::create_dir_all(&work).with_context(|| work.display().to_string())?;
    let read = |file: &str| {
        let path = crate::workspace_root().join("fixtures/robots").join(file);
        RobotDescription::read(&path).with_context(|| path.display().to_string())
    };
    let (ur10, irb) = (read("ur10.ron")?, read("irb4400.ron")?);
    let mut inputs = Inputs { args, calib: calib.clone(), work: work.clone(), ur10, irb, c: None, b: None };
    let mut binaries: Vec<(&str, &Path)> = vec![("calib", &calib)];
    if let Some(base) = &args.calib_base {
        binaries.push(("base", base));
    }
    let load_start = load_average();
    let (rows, result) = measure_rows(&keys, &mut inputs, &binaries, &python);
    let _ = std::fs::remove_dir_all(&work);
    let run = Run {
        machine: format!(
            "{}, {} cores visible",
            super::bench_gp::cpu_model(),
            std::thread::available_parallelism().map_or(1, |n| n.get())
        ),
        load_start,
        load_end: load_average(),
        calib: calib_text,
        base: args.calib_base.as_ref().map(|b| b.display().to_string()),
        python: match &python {
            Ok(p) => super::bench_fit_sklearn::versions(p),
            Err(why) => format!("not run ({why})"),
        },
        quick: args.quick,
        command: format!("cargo xtask {}", std::env::args().skip(1).collect::<Vec<_>>().join(" ")),
    };
    let md = table(&run, &rows);
    println!("{md}");
    if let Some(path) = &args.out {
        std::fs::write(path, &md).with_context(|| path.display().to_string())?;
    }
    result?;
    let failed = rows.iter().filter(|r| match &r.outcome {
        Outcome::Measured(m) => m.calib.is_err() || m.base.as_ref().is_some_and(Result::is_err),
        Outcome::Skipped(_) => false,
    });
    let failed: Vec<&str> = failed.map(|r| r.label).collect();
    anyhow::ensure!(failed.is_empty(), "a `calib` command failed on: {}", failed.join("; "));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn parse(line: &[&str]) -> Result<Args, clap::Error> {
        Cli::try_parse_from(std::iter::once("bench-fit").chain(line.iter().copied())).map(|c| c.args)
    }

    #[test]
    fn only_takes_the_row_names_and_selects_them_in_table_order() {
        let args = parse(&["--only", "paper,c-poe-auto,sim-100k,c-poe-auto"]).unwrap();
        assert_eq!(selected(&args.only), [RowKey::CPoeAuto, RowKey::Sim100k, RowKey::Paper]);
        assert_eq!(selected(&[]), RowKey::all());
        let error = parse(&["--only", "c-poe-auto,c-gp"]).unwrap_err().to_string();
        assert!(error.contains("c-gp") && error.contains("c-poe-gp-position"), "{error}");
    }

    #[test]
    fn defaults_are_the_budgets_setting() {
        let args = parse(&[]).unwrap();
        assert_eq!(args.data, PathBuf::from("../shared/data/ipa-ur10"));
        assert_eq!((args.runs, args.paper_seed, args.skip_sklearn, args.quick), (3, 1, false, false));
        assert_eq!((args.repeat_limit_s, args.sklearn_timeout_s), (300.0, 3600.0));
        assert!(args.only.is_empty() && args.out.is_none() && args.calib.is_none() && args.calib_base.is_none());
    }

    #[test]
    fn every_time_budget_is_on_its_row() {
        let budgets: Vec<(RowKey, Budget)> = RowKey::all().iter().filter_map(|k| Some((*k, k.budget()?))).collect();
        assert_eq!(
            budgets,
            [
                (RowKey::CPoeGp, Budget::SpeedupAtLeast(40.0)),
                (RowKey::CPoeGpPosition, Budget::SpeedupAtLeast(40.0)),
                (RowKey::CPoeAuto, Budget::WallAtMost(8.0)),
                (RowKey::CPoeGpAuto, Budget::WallAtMost(25.0)),
                (RowKey::CDiagnose, Budget::WallAtMost(2.0)),
                (RowKey::CAllPoeGpAuto, Budget::WallAtMost(120.0)),
                (RowKey::Sim100k, Budget::WallAtMost(20.0)),
                (RowKey::Paper, Budget::GpStageSpeedupAtLeast(80.0)),
            ]
        );
        // A speed-up budget needs scikit-learn beside it.
        assert!(budgets.iter().all(|(k, b)| matches!(b, Budget::WallAtMost(_)) || k.sklearn().is_some()));
    }

    #[test]
    fn each_row_runs_the_command_a_user_would() {
        let files = Files { train: "t.csv".into(), test: "h.csv".into(), rows: (2, 2), full_pose: true };
        let line = |k: RowKey| command_args(k, Path::new("r.ron"), &files, Path::new("m.ron")).join(" ");
        assert_eq!(line(RowKey::CPoeGp), "fit --robot r.ron --data t.csv --method poe-gp --out m.ron --json");
        assert_eq!(
            line(RowKey::CPoeGpAuto),
            "fit --robot r.ron --data t.csv --method poe-gp --effects auto --out m.ron --json"
        );
        assert_eq!(
            line(RowKey::Sim100k),
            "fit --robot r.ron --data t.csv --method poe-gp --gp sparse --out m.ron --json"
        );
        assert_eq!(line(RowKey::Paper), "fit --robot r.ron --data t.csv --method poe-gp-load --out m.ron --json");
        assert_eq!(line(RowKey::CDiagnose), "diagnose --robot r.ron --data t.csv --json");
    }
}
