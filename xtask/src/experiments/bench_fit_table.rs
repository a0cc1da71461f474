//! The table `cargo xtask bench-fit` prints: one line per row (the `calib` binary's median time,
//! CPU, peak memory and held-out errors, the base binary's beside it, scikit-learn's pipeline and
//! the ratio), each of the time budgets with its verdict, and what the run was measured on.

use std::fmt::Write;

use super::bench_fit_sklearn::SklearnSide;

/// The time budget of a row: how long a person may wait for it on the 2-core machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Budget {
    /// The fit's wall time at most this, s.
    WallAtMost(f64),
    /// The scikit-learn pipeline's time over the fit's wall time at least this, at no worse
    /// held-out error.
    SpeedupAtLeast(f64),
    /// scikit-learn's GP fit over the fit's GP search (`fit / GP / search` of its timings) at
    /// least this, at no worse held-out error: the GP stage against the GP stage.
    GpStageSpeedupAtLeast(f64),
}

impl Budget {
    /// The budget in words.
    pub fn text(self) -> String {
        match self {
            Budget::WallAtMost(s) => format!("≤ {s} s"),
            Budget::SpeedupAtLeast(x) => format!("≥ {x}×"),
            Budget::GpStageSpeedupAtLeast(x) => format!("GP stage ≥ {x}×"),
        }
    }
}

/// One run of one binary on one row.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// Wall, CPU and peak memory of the command.
    pub cost: super::bench_fit_run::Cost,
    /// Mean held-out position error (mm) and rotation error (mrad, full pose); `None` for the
    /// diagnosis, which predicts nothing.
    pub heldout: Option<(f64, Option<f64>)>,
    /// The phases its `--json` report gave.
    pub phases: Vec<timings::PhaseTime>,
}

/// The phase whose wall time is the GP stage: the exact or sparse GP's hyperparameter search,
/// what `bench-gp --paper` times as the GP's fit.
pub const GP_SEARCH: &str = "fit / GP / search";

/// One binary's runs of a row, summarised.
#[derive(Debug, Clone, PartialEq)]
pub struct Side {
    /// How many runs.
    pub runs: usize,
    /// Median wall time, s.
    pub wall_s: f64,
    /// Median CPU time, s, where every run has one.
    pub cpu_s: Option<f64>,
    /// The highest peak over the runs, MiB.
    pub peak_mib: Option<f64>,
    /// The first run's held-out errors.
    pub heldout: Option<(f64, Option<f64>)>,
    /// Whether another run's held-out errors differ from the first's (a fit that is not
    /// repeatable).
    pub heldout_varies: bool,
    /// The phases of the run whose wall time is nearest the median.
    pub phases: Vec<timings::PhaseTime>,
    /// Median wall time of [`GP_SEARCH`], where every run reported it.
    pub gp_search_s: Option<f64>,
}

/// The median of `values` (the mean of the middle two for an even count); `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(v[n / 2]),
        _ => Some(0.5 * (v[n / 2 - 1] + v[n / 2])),
    }
}

/// Every value, or `None` where one is missing.
fn all<T: Copy>(values: impl Iterator<Item = Option<T>>) -> Option<Vec<T>> {
    values.collect()
}

impl Side {
    /// The summary of `runs` (at least one).
    pub fn from_runs(runs: &[RunResult]) -> Option<Side> {
        let first = runs.first()?;
        let walls: Vec<f64> = runs.iter().map(|r| r.cost.wall_s).collect();
        let wall_s = median(&walls)?;
        let nearest =
            runs.iter().min_by(|a, b| (a.cost.wall_s - wall_s).abs().total_cmp(&(b.cost.wall_s - wall_s).abs()))?;
        let gp = |r: &RunResult| r.phases.iter().find(|p| p.phase == GP_SEARCH).map(|p| p.wall_s);
        Some(Side {
            runs: runs.len(),
            wall_s,
            cpu_s: all(runs.iter().map(|r| r.cost.cpu_s)).and_then(|c| median(&c)),
            peak_mib: all(runs.iter().map(|r| r.cost.peak_mib)).and_then(|p| p.into_iter().reduce(f64::max)),
            heldout: first.heldout,
            heldout_varies: runs.iter().any(|r| r.heldout != first.heldout),
            phases: nearest.phases.clone(),
            gp_search_s: all(runs.iter().map(gp)).and_then(|g| median(&g)),
        })
    }
}

/// A row's measurements.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Training / test rows and whether they are full pose.
    pub data: String,
    /// The `calib` binary, or why it failed.
    pub calib: Result<Side, String>,
    /// The base binary (`--calib-base`), or why it failed.
    pub base: Option<Result<Side, String>>,
    /// scikit-learn's kernel and pipeline, where the row has one.
    pub sklearn: Option<(String, SklearnSide)>,
}

/// A row's result.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// Measured (possibly failed: [`Measured::calib`] says).
    Measured(Box<Measured>),
    /// Its data are absent, and which.
    Skipped(String),
}

/// A row of the table: its name, its budget and what happened.
#[derive(Debug, Clone)]
pub struct Row {
    /// The name.
    pub label: &'static str,
    /// The row's time budget, if it has one.
    pub budget: Option<Budget>,
    /// What happened.
    pub outcome: Outcome,
}

/// What the run was measured on.
#[derive(Debug, Clone)]
pub struct Run {
    /// CPU, cores.
    pub machine: String,
    /// `/proc/loadavg` before the first row.
    pub load_start: String,
    /// And after the last.
    pub load_end: String,
    /// The binaries: `calib` and the base, with how each was found.
    pub calib: String,
    /// The base binary, if any.
    pub base: Option<String>,
    /// The Python side's interpreter and versions.
    pub python: String,
    /// `--quick`: smaller sets, one run, no verdicts.
    pub quick: bool,
    /// The command line.
    pub command: String,
}

/// Seconds with three significant figures or so.
fn seconds(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

fn dash() -> String {
    "–".to_owned()
}

/// The held-out cells: position mm and rotation mrad.
fn heldout_cells(heldout: Option<(f64, Option<f64>)>) -> (String, String) {
    match heldout {
        Some((mm, mrad)) => (format!("{mm:.4}"), mrad.map_or_else(dash, |r| format!("{r:.3}"))),
        None => (dash(), dash()),
    }
}

/// Whether `ours` is no worse than scikit-learn's, position and (where both have it) rotation.
fn no_worse(ours: Option<(f64, Option<f64>)>, theirs_mm: f64, theirs_mrad: Option<f64>) -> bool {
    ours.is_some_and(|(mm, mrad)| mm <= theirs_mm && mrad.zip(theirs_mrad).is_none_or(|(o, t)| o <= t))
}

/// scikit-learn's time over the side's for a speed-up budget, or `None` where it is not known;
/// with whether scikit-learn finished.
fn speedup(budget: Budget, side: &Side, sklearn: &SklearnSide) -> Option<(f64, bool)> {
    let done = matches!(sklearn, SklearnSide::Done { .. });
    match (budget, sklearn) {
        (Budget::WallAtMost(_), _) | (_, SklearnSide::Skipped(_)) => None,
        (Budget::SpeedupAtLeast(_), _) => Some((sklearn.seconds() / side.wall_s, done)),
        (Budget::GpStageSpeedupAtLeast(_), SklearnSide::Done { gp_s, .. }) => Some((gp_s / side.gp_search_s?, done)),
        (Budget::GpStageSpeedupAtLeast(_), SklearnSide::TimedOut { limit_s, .. }) => {
            Some((limit_s / side.gp_search_s?, done))
        }
    }
}

/// Whether `side` meets `budget`: `met`, `missed`, or why it is not known. A speed-up counts only
/// at no worse held-out error (position, and rotation where both have it): a faster answer that is
/// less accurate is not the same answer.
pub fn verdict(budget: Budget, side: &Side, sklearn: Option<&SklearnSide>) -> String {
    let target = match budget {
        Budget::WallAtMost(limit) => return (if side.wall_s <= limit { "met" } else { "missed" }).to_owned(),
        Budget::SpeedupAtLeast(x) | Budget::GpStageSpeedupAtLeast(x) => x,
    };
    let Some(sklearn) = sklearn else { return "not compared".to_owned() };
    let Some((ratio, done)) = speedup(budget, side, sklearn) else {
        return match sklearn {
            SklearnSide::Skipped(_) => "not compared".to_owned(),
            _ => format!("unknown (no `{GP_SEARCH}` timing)"),
        };
    };
    match sklearn {
        SklearnSide::Done { heldout_mm, heldout_mrad, .. } => {
            match (ratio >= target, no_worse(side.heldout, *heldout_mm, *heldout_mrad)) {
                (true, true) => "met".to_owned(),
                (true, false) => "missed (faster, less accurate)".to_owned(),
                (false, _) => "missed".to_owned(),
            }
        }
        _ if !done && ratio >= target => "met on time (scikit-learn stopped; accuracy not compared)".to_owned(),
        _ => "unknown (scikit-learn stopped too soon)".to_owned(),
    }
}

/// The ratio cell: scikit-learn's time over calib's (whole pipeline over whole fit, and for a
/// GP-stage budget the GP fit over the GP search too).
fn ratio_cell(budget: Option<Budget>, side: &Side, sklearn: &SklearnSide) -> String {
    let at_least = |done: bool| if done { "" } else { "≥ " };
    let mut cell = match speedup(Budget::SpeedupAtLeast(0.0), side, sklearn) {
        Some((r, done)) => format!("{}{r:.1}×", at_least(done)),
        None => dash(),
    };
    if let Some(b @ Budget::GpStageSpeedupAtLeast(_)) = budget {
        let gp = speedup(b, side, sklearn).map_or_else(dash, |(r, done)| format!("{}{r:.1}×", at_least(done)));
        let _ = write!(cell, "; GP stage {gp}");
    }
    cell
}

/// The columns of one binary: runs, wall, CPU, peak, held-out position and rotation.
fn side_cells(side: &Result<Side, String>) -> Vec<String> {
    match side {
        Err(_) => vec!["failed".to_owned(), dash(), dash(), dash(), dash(), dash()],
        Ok(s) => {
            let (mm, mrad) = heldout_cells(s.heldout);
            let star = if s.heldout_varies { " (varies)" } else { "" };
            vec![
                s.runs.to_string(),
                seconds(s.wall_s),
                s.cpu_s.map_or_else(dash, seconds),
                s.peak_mib.map_or_else(dash, |p| format!("{p:.0}")),
                format!("{mm}{star}"),
                mrad,
            ]
        }
    }
}

fn phases_text(list: &[timings::PhaseTime]) -> String {
    let each = list.iter().filter(|p| p.wall_s >= 1.0 && p.phase != "fit").map(|p| {
        let calls = if p.calls > 1 { format!(" ×{}", p.calls) } else { String::new() };
        let name = p.phase.strip_prefix("fit / ").unwrap_or(&p.phase);
        format!("{name}{calls} {} ({})", seconds(p.wall_s), seconds(p.cpu_s))
    });
    let each: Vec<String> = each.collect();
    if each.is_empty() { "none reported".to_owned() } else { each.join("; ") }
}

/// The budget cell: the budget, the calib binary's verdict and the base's.
fn budget_cell(row: &Row, m: &Measured, quick: bool) -> String {
    let Some(budget) = row.budget else { return dash() };
    if quick {
        return format!("{}: not judged (--quick)", budget.text());
    }
    let sklearn = m.sklearn.as_ref().map(|(_, s)| s);
    let judge = |side: &Result<Side, String>| {
        side.as_ref().map_or_else(|_| "failed".to_owned(), |s| verdict(budget, s, sklearn))
    };
    let mut cell = format!("{}: {}", budget.text(), judge(&m.calib));
    if let Some(base) = &m.base {
        let _ = write!(cell, " (base: {})", judge(base));
    }
    cell
}

/// The markdown: what the run was measured on, the table, then the phases, the scikit-learn
/// side, the rows skipped or failed, and what the columns mean.
pub fn table(run: &Run, rows: &[Row]) -> String {
    let mut md = String::new();
    preamble(&mut md, run);
    let head = columns(run.base.is_some());
    let _ = writeln!(md, "\n| {} |", head.join(" | "));
    let align: Vec<&str> =
        head.iter().enumerate().map(|(i, _)| if i < 2 || i + 1 == head.len() { "---" } else { "---:" }).collect();
    let _ = writeln!(md, "|{}|", align.join("|"));
    let mut phases = Vec::new();
    let mut notes = Vec::new();
    for row in rows {
        let cells = match &row.outcome {
            Outcome::Skipped(why) => {
                let mut cells = vec![row.label.to_owned(), format!("data absent: {why}")];
                cells.resize(head.len(), dash());
                cells
            }
            Outcome::Measured(m) => measured_cells(run, row, m, &mut phases, &mut notes),
        };
        let _ = writeln!(md, "| {} |", cells.join(" | "));
    }
    if !phases.is_empty() {
        let _ = writeln!(
            md,
            "\nPhases of 1 s or more (`calib fit --json`'s timings, run nearest the median), wall (CPU) s:\n\n{}",
            phases.join("\n")
        );
    }
    if !notes.is_empty() {
        let _ = writeln!(md, "\nThe scikit-learn side and failures:\n\n{}", notes.join("\n"));
    }
    md.push_str(LEGEND);
    md
}

/// The command, the machine and its load, the binaries, and what `--quick` means.
fn preamble(md: &mut String, run: &Run) {
    let _ = writeln!(md, "`{}`\n", run.command);
    let _ = writeln!(
        md,
        "Machine: {}. Load average (1, 5, 15 min) {} at the start, {} at the end: times move with the load of a \
         shared machine. `calib`: {}.{} Python side: {}.",
        run.machine,
        run.load_start,
        run.load_end,
        run.calib,
        run.base.as_ref().map_or(String::new(), |b| format!(" Base: {b}.")),
        run.python
    );
    if run.quick {
        let _ = writeln!(
            md,
            "\n**--quick**: every set cut to a few hundred rows (10⁵ poses to a few thousand), one run, scikit-learn \
             without restarts: a smoke run, not the budgets' measurement; the budgets are not judged."
        );
    }
}

/// The table's columns (the base binary's with `with_base`).
fn columns(with_base: bool) -> Vec<&'static str> {
    let mut head =
        vec!["row", "train / test", "runs", "wall (s)", "CPU (s)", "peak (MiB)", "held-out (mm)", "held-out (mrad)"];
    if with_base {
        head.extend([
            "base runs",
            "base wall (s)",
            "base CPU (s)",
            "base peak (MiB)",
            "base (mm)",
            "base (mrad)",
            "wall / base",
        ]);
    }
    head.extend(["scikit-learn (s)", "its (mm)", "its (mrad)", "scikit-learn / calib", "budget: verdict"]);
    head
}

/// A measured row's cells; its phases and notes go to `phases` and `notes`.
fn measured_cells(
    run: &Run,
    row: &Row,
    m: &Measured,
    phases: &mut Vec<String>,
    notes: &mut Vec<String>,
) -> Vec<String> {
    let mut cells = vec![row.label.to_owned(), m.data.clone()];
    cells.extend(side_cells(&m.calib));
    match &m.calib {
        Ok(s) => phases.push(format!("- {}: {}", row.label, phases_text(&s.phases))),
        Err(e) => notes.push(format!("- {}: `calib` failed: {e}", row.label)),
    }
    if let Some(base) = &m.base {
        cells.extend(side_cells(base));
        let ratio = match (&m.calib, base) {
            (Ok(s), Ok(b)) => format!("{:.2}×", s.wall_s / b.wall_s),
            _ => dash(),
        };
        cells.push(ratio);
        match base {
            Ok(b) => phases.push(format!("- {} (base): {}", row.label, phases_text(&b.phases))),
            Err(e) => notes.push(format!("- {}: the base binary failed: {e}", row.label)),
        }
    } else if run.base.is_some() {
        cells.extend(std::iter::repeat_n(dash(), 7));
    }
    match (&m.sklearn, &m.calib) {
        (Some((kernel, side)), calib) => {
            let (mm, mrad) = match side {
                SklearnSide::Done { heldout_mm, heldout_mrad, .. } => heldout_cells(Some((*heldout_mm, *heldout_mrad))),
                _ => (dash(), dash()),
            };
            let ratio = calib.as_ref().map_or_else(|_| dash(), |s| ratio_cell(row.budget, s, side));
            cells.extend([side.seconds_text(), mm, mrad, ratio]);
            notes.push(format!("- {}: scikit-learn `{kernel}`; {}", row.label, side.note()));
        }
        (None, _) => cells.extend([dash(), dash(), dash(), dash()]),
    }
    cells.push(budget_cell(row, m, run.quick));
    cells
}

/// What the columns mean, printed under the table.
const LEGEND: &str = "
Columns: *wall* is the median over the runs of the `calib` command (`fit`, or `diagnose`) from \
start to exit, *CPU* its median user + system time over every thread, *peak* the highest \
resident high-water mark (`VmHWM`, polled every 10 ms) over the runs; *held-out* are `calib eval \
--json`'s mean errors of the fitted model on the test rows (first run; *varies* where a later run \
differed). *scikit-learn* is what a user would run instead, once per row: scikit-learn's \
`GaussianProcessRegressor` (the kernel in the notes; one GP per output in 2 worker processes, \
standardised inputs, `normalize_y`) on the residuals our own `poe` fit leaves on the same rows, so \
both GPs learn the same residuals; its time is its GP fit's (the geometric identification before \
it is not counted: with `--scipy-identify` SciPy's `least_squares` on the same rows is timed and \
noted), its held-out errors those of our `poe` geometry corrected by its GP's prediction. \
*scikit-learn / calib* is its time over `calib`'s whole wall time (≥ where scikit-learn was \
stopped at its time limit); *GP stage* is its GP fit over the GP search of `calib`'s own timings. \
A speed-up budget counts only at no worse held-out error.
";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::bench_fit_run::Cost;
    use crate::experiments::bench_fit_sklearn::Identification;

    fn run(wall_s: f64, heldout: (f64, Option<f64>), gp_s: Option<f64>) -> RunResult {
        let mut phases = vec![timings::PhaseTime { phase: "fit".into(), calls: 1, wall_s, cpu_s: wall_s }];
        if let Some(gp_s) = gp_s {
            phases.push(timings::PhaseTime { phase: GP_SEARCH.into(), calls: 2, wall_s: gp_s, cpu_s: 1.5 * gp_s });
        }
        RunResult {
            cost: Cost { wall_s, cpu_s: Some(1.5 * wall_s), peak_mib: Some(300.4) },
            heldout: Some(heldout),
            phases,
        }
    }

    fn side(wall_s: f64, heldout: (f64, Option<f64>)) -> Side {
        Side::from_runs(&[run(wall_s, heldout, Some(wall_s / 2.0))]).unwrap()
    }

    fn done(gp_s: f64, heldout_mm: f64, heldout_mrad: Option<f64>) -> SklearnSide {
        let scipy = Some(Identification { seconds: 2.0, rms_mm: 0.31, calib_poe_rms_mm: 0.30 });
        SklearnSide::Done { scipy, gp_s, peak_mib: 500.0, heldout_mm, heldout_mrad }
    }

    fn stopped(limit_s: f64) -> SklearnSide {
        SklearnSide::TimedOut { scipy: None, limit_s }
    }

    #[test]
    fn the_median_of_the_runs_is_the_middle_one_and_the_peak_the_highest() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        let mut runs =
            vec![run(9.0, (0.2, None), Some(4.0)), run(5.0, (0.2, None), Some(3.0)), run(7.0, (0.2, None), Some(8.0))];
        runs[0].cost.peak_mib = Some(900.0);
        let s = Side::from_runs(&runs).unwrap();
        assert_eq!(
            (s.runs, s.wall_s, s.cpu_s, s.peak_mib, s.gp_search_s),
            (3, 7.0, Some(10.5), Some(900.0), Some(4.0))
        );
        assert_eq!(s.phases[0].wall_s, 7.0, "the phases of the median run");
        assert!(!s.heldout_varies);
        runs[2].heldout = Some((0.21, None));
        runs[1].cost.cpu_s = None;
        let s = Side::from_runs(&runs).unwrap();
        assert!(s.heldout_varies && s.cpu_s.is_none());
        runs[1].phases.clear();
        assert_eq!(Side::from_runs(&runs).unwrap().gp_search_s, None, "a run without the GP phase");
        assert!(Side::from_runs(&[]).is_none());
    }

    #[test]
    fn a_speed_up_counts_only_at_no_worse_held_out_error() {
        let budget = Budget::SpeedupAtLeast(40.0);
        // 1000 / 20 = 50×: SciPy's 2 s of identification are not in it.
        let sk = done(1000.0, 0.226, Some(0.35));
        assert_eq!(sk.seconds(), 1000.0);
        assert_eq!(verdict(budget, &side(20.0, (0.137, Some(0.30))), Some(&sk)), "met");
        assert_eq!(verdict(budget, &side(20.0, (0.137, Some(0.40))), Some(&sk)), "missed (faster, less accurate)");
        assert_eq!(verdict(budget, &side(20.0, (0.300, Some(0.30))), Some(&sk)), "missed (faster, less accurate)");
        assert_eq!(verdict(budget, &side(30.0, (0.137, Some(0.30))), Some(&sk)), "missed");
        let fast = side(20.0, (0.137, None));
        assert_eq!(
            verdict(budget, &fast, Some(&stopped(900.0))),
            "met on time (scikit-learn stopped; accuracy not compared)"
        );
        assert_eq!(verdict(budget, &fast, Some(&stopped(300.0))), "unknown (scikit-learn stopped too soon)");
        assert_eq!(verdict(budget, &fast, Some(&SklearnSide::Skipped("--skip-sklearn".into()))), "not compared");
        assert_eq!(verdict(budget, &fast, None), "not compared");
        assert_eq!(verdict(Budget::WallAtMost(25.0), &side(30.0, (0.1, None)), None), "missed");
        assert_eq!(verdict(Budget::WallAtMost(30.0), &side(30.0, (0.1, None)), None), "met");
    }

    #[test]
    fn the_gp_stage_budget_compares_the_gp_fits_and_needs_the_timing() {
        let budget = Budget::GpStageSpeedupAtLeast(80.0);
        // GP search 2 s: 170 / 2 = 85×, but scikit-learn's GP over the whole fit is 170 / 4 = 42.5×.
        let s = side(4.0, (0.14, None));
        assert_eq!(verdict(budget, &s, Some(&done(170.0, 0.42, None))), "met");
        assert_eq!(verdict(budget, &s, Some(&done(150.0, 0.42, None))), "missed");
        assert_eq!(ratio_cell(Some(budget), &s, &done(170.0, 0.42, None)), "42.5×; GP stage 85.0×");
        let old = Side { gp_search_s: None, ..s.clone() };
        assert_eq!(verdict(budget, &old, Some(&done(170.0, 0.42, None))), "unknown (no `fit / GP / search` timing)");
        assert_eq!(ratio_cell(Some(budget), &old, &stopped(300.0)), "≥ 75.0×; GP stage –");
    }

    fn row(label: &'static str, budget: Option<Budget>, outcome: Outcome) -> Row {
        Row { label, budget, outcome }
    }

    fn measured(
        calib: Result<Side, String>,
        base: Option<Result<Side, String>>,
        sklearn: Option<SklearnSide>,
    ) -> Outcome {
        Outcome::Measured(Box::new(Measured {
            data: "1387 / 1386, full pose".into(),
            calib,
            base,
            sklearn: sklearn.map(|s| ("C·RBF(ARD) + C + White, 1 restart".to_owned(), s)),
        }))
    }

    fn info(base: bool, quick: bool) -> Run {
        Run {
            machine: "test CPU (2 cores)".into(),
            load_start: "7.1 7.7 8.2".into(),
            load_end: "8.0 7.9 8.1".into(),
            calib: "target/release/calib".into(),
            base: base.then(|| "/tmp/old/calib".into()),
            python: "python3".into(),
            quick,
            command: "cargo xtask bench-fit".into(),
        }
    }

    fn table_lines(md: &str) -> Vec<&str> {
        md.lines().filter(|l| l.starts_with('|')).collect()
    }

    #[test]
    fn every_table_row_has_the_headers_columns_and_absent_data_or_failures_say_so() {
        for with_base in [false, true] {
            let base = |wall| with_base.then(|| Ok(side(wall, (0.138, Some(0.31)))));
            let rows = vec![
                row(
                    "C poe-gp",
                    Some(Budget::SpeedupAtLeast(40.0)),
                    measured(Ok(side(20.0, (0.137, Some(0.30)))), base(40.0), Some(done(1000.0, 0.226, Some(0.35)))),
                ),
                row(
                    "C poe auto",
                    Some(Budget::WallAtMost(8.0)),
                    measured(Ok(side(9.0, (0.3, None))), base(18.0), None),
                ),
                row(
                    "C diagnose",
                    Some(Budget::WallAtMost(2.0)),
                    measured(Err("exit status 1: no".into()), with_base.then(|| Err("old".into())), None),
                ),
                row("B poe-gp", None, Outcome::Skipped("no UR10 series B in /nowhere".into())),
            ];
            let md = table(&info(with_base, false), &rows);
            let lines = table_lines(&md);
            assert_eq!(lines.len(), 2 + rows.len(), "{md}");
            let cells = |l: &str| l.matches('|').count();
            assert!(lines.iter().all(|l| cells(l) == cells(lines[0])), "{md}");
            assert_eq!(cells(lines[0]), if with_base { 21 } else { 14 }, "{}", lines[0]);
            assert!(lines[2].contains("| 1 | 20.0 | 30.0 | 300 | 0.1370 | 0.300 |"), "{}", lines[2]);
            assert!(lines[2].contains("| 1000.0 | 0.2260 | 0.350 | 50.0× | ≥ 40×: met"), "{}", lines[2]);
            if !with_base {
                assert!(lines[3].ends_with("| – | – | – | – | ≤ 8 s: missed |"), "{}", lines[3]);
            }
            assert!(lines[4].contains("| failed |") && lines[4].contains("≤ 2 s: failed"), "{}", lines[4]);
            assert!(lines[5].contains("data absent: no UR10 series B"), "{}", lines[5]);
            assert!(md.contains("7.1 7.7 8.2 at the start, 8.0 7.9 8.1 at the end"));
            assert!(md.contains("C diagnose: `calib` failed: exit status 1: no"), "{md}");
            assert!(md.contains("scikit-learn `C·RBF(ARD) + C + White, 1 restart`; GP fit 1000.0 s (peak 500 MiB); SciPy `least_squares` on the same rows 2.00 s, not in the ratio"), "{md}");
            assert!(md.contains("- C poe-gp: GP / search ×2 10.0 (15.0)"), "{md}");
            if with_base {
                assert!(
                    lines[2].contains("| 0.50× |") && lines[2].ends_with("≥ 40×: met (base: missed) |"),
                    "{}",
                    lines[2]
                );
                assert!(lines[3].ends_with("≤ 8 s: missed (base: missed) |"), "{}", lines[3]);
                assert!(md.contains("Base: /tmp/old/calib."));
                assert!(md.contains("C diagnose: the base binary failed: old"));
            }
        }
    }

    #[test]
    fn a_quick_run_judges_no_budget() {
        let rows =
            vec![row("C poe auto", Some(Budget::WallAtMost(8.0)), measured(Ok(side(1.0, (0.3, None))), None, None))];
        let md = table(&info(false, true), &rows);
        assert!(table_lines(&md)[2].ends_with("| ≤ 8 s: not judged (--quick) |"), "{md}");
        assert!(md.contains("**--quick**"));
    }
}
