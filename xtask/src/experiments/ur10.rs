//! `cargo xtask ur10`: every method and the diagnosis on the real UR10 tracker data of Landgraf et
//! al. (CASE 2021). Train on the even rows of a series and test on the odd ones (or on the first
//! and second half, `--split halves`).
//!
//! The diagnosis part, for each series of `--diagnose-series`: `calib diagnose` on the training
//! rows, timed; then the verdict's effect fitted with the geometry on the same rows (`calib fit
//! --effects …`, the list `pipeline::effects_of` makes of the verdict's selected effects)
//! and evaluated on the test rows, against the diagnosis's cross-validated prediction. Writes
//! `ur10.md` into `--out` (with `--diagnosis-only`, only its section from `## Diagnosis` on is
//! replaced, the methods table kept) and the report folder `ur10-diagnosis/` (the first series).

use super::convert_ur10::{Dataset, read_series};
use anyhow::{Context, Result};
use diagnose::{DiagnoseOptions, Diagnosis, diagnose};
use effects::EffectSelection;
use indicatif::{ProgressBar, ProgressStyle};
use measurements::MeasurementSet;
use model::{Method, ResidualFrame, ResidualGpOptions};
use pipeline::FitOptions;
use pipeline::effects_of;
use robot::RobotDescription;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

/// The heading of the diagnosis section of `ur10.md`; `--diagnosis-only` replaces the file from it on.
const DIAGNOSIS_HEADING: &str = "## Diagnosis";

/// CPU time this process has used so far (all threads, user and system), s: fields 14 and 15 of
/// `/proc/self/stat`, in clock ticks of 1/100 s (Linux's USER_HZ on every architecture it
/// exports to user space); NaN where that file cannot be read.
pub(crate) fn process_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return f64::NAN };
    // The command name (field 2) is in parentheses and may hold spaces: count from after it.
    let Some(after) = stat.rfind(')').map(|at| &stat[at + 1..]) else { return f64::NAN };
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(f64::NAN);
    // After the name, field 3 is at index 0: utime (14) at 11, stime (15) at 12.
    (ticks(11) + ticks(12)) / 100.0
}

/// How the rows of a series are split into training and test rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Split {
    /// Even rows train, odd rows test (the `ur10_X_even.csv` / `_odd.csv` files).
    EvenOdd,
    /// The first half in measurement order trains, the second tests.
    Halves,
}

/// Fit and evaluate every method, and diagnose, on the IPA UR10 data set.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    dataset: Dataset,
    /// Robot description.
    #[arg(long, default_value = "fixtures/robots/ur10.ron")]
    robot: PathBuf,
    /// Where `ur10.md` and `ur10-diagnosis/` go.
    #[arg(long, default_value = "docs/results")]
    out: PathBuf,
    /// How training and test rows are split.
    #[arg(long, value_enum, default_value = "even-odd")]
    split: Split,
    /// Only the diagnosis part: replaces the `## Diagnosis` section of `ur10.md`, keeping its
    /// methods table (which takes minutes of GP fits).
    #[arg(long)]
    diagnosis_only: bool,
    /// The series the diagnosis part runs on (comma separated).
    #[arg(long, default_value = "C,B,D", value_delimiter = ',')]
    diagnose_series: Vec<String>,
    /// Timed diagnosis runs per series; the median is reported.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
}

struct Row {
    data: &'static str,
    method: String,
    mean_mm: f64,
    rms_mm: f64,
    max_mm: f64,
    rotation_mrad: Option<f64>,
    fit_s: f64,
}

fn split(set: &MeasurementSet, how: Split) -> (MeasurementSet, MeasurementSet) {
    let n = set.rows.len();
    let (train, test): (Vec<usize>, Vec<usize>) = match how {
        Split::EvenOdd => ((0..n).step_by(2).collect(), (1..n).step_by(2).collect()),
        Split::Halves => ((0..n / 2).collect(), (n / 2..n).collect()),
    };
    (set.subset(&train), set.subset(&test))
}

fn split_name(how: Split) -> &'static str {
    match how {
        Split::EvenOdd => "train on the even rows, test on the odd rows",
        Split::Halves => "train on the first half of the rows in measurement order, test on the second",
    }
}

fn bar(len: usize) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// The methods table (position only and full pose).
fn methods(args: &Args, robot: &RobotDescription) -> Result<String> {
    let (rows, sizes) = method_rows(args, robot)?;
    let mut md = String::new();
    let _ = writeln!(md, "# The real UR10: every method\n");
    let _ = writeln!(
        md,
        "Data: series {} of the IPA UR10 data set (Landgraf, Ernst, Schleth, Fabritius, Huber, *A hybrid neural \
         network approach for increasing the absolute accuracy of industrial robots*, CASE 2021; MIT licence; not part of \
         this repository): a UR10 measured with a Leica laser tracker and a T-Mac at random poses, no payload variation. \
         {} ({} training poses, {} test poses). Orientation from the tracker's rx, ry, rz as R = Rx Ry Rz. Produced by \
         `cargo xtask ur10`; the diagnosis: below.\n",
        args.dataset.series,
        split_name(args.split),
        sizes.0,
        sizes.1
    );
    let _ = writeln!(md, "| data | method | mean (mm) | RMS (mm) | max (mm) | rotation mean (mrad) | fit time (s) |");
    let _ = writeln!(md, "| --- | --- | ---: | ---: | ---: | ---: | ---: |");
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {:.3} | {} | {:.1} |",
            r.data,
            r.method,
            r.mean_mm,
            r.rms_mm,
            r.max_mm,
            r.rotation_mrad.map_or("–".into(), |v| format!("{v:.3}")),
            r.fit_s
        );
    }
    let _ = writeln!(
        md,
        "\n`poe-gp-load` equals `poe-gp` here: the data set has one payload, so the payload input is constant."
    );
    Ok(md)
}

/// Every method fitted on the training rows and evaluated on the test rows, position only and full
/// pose; and the numbers of training and test rows.
fn method_rows(args: &Args, robot: &RobotDescription) -> Result<(Vec<Row>, (usize, usize))> {
    let paper = ResidualGpOptions {
        gp: gp::GpConfig { kernel: gp::KernelChoice::Quadratic, ..gp::GpConfig::default() },
        residual_frame: ResidualFrame::Tracker,
        ..ResidualGpOptions::default()
    };
    let variants: Vec<(String, Method, FitOptions)> = vec![
        ("base-tool".into(), Method::BaseTool, FitOptions::default()),
        ("poe".into(), Method::Poe, FitOptions::default()),
        ("poe-gp".into(), Method::PoeGp, FitOptions::default()),
        ("poe-gp-load".into(), Method::PoeGpLoad, FitOptions::default()),
        (
            "poe-gp, paper's kernel (Eq. 5) and frame (Eq. 8)".into(),
            Method::PoeGp,
            FitOptions { residual_gp: paper, ..FitOptions::default() },
        ),
    ];
    let progress = bar(2 * variants.len());
    let mut rows = Vec::new();
    let mut sizes = (0, 0);
    for (label, full_pose) in [("position", false), ("full pose", true)] {
        let set = read_series(&args.dataset.input, &args.dataset.series, full_pose)?;
        let (train, test) = split(&set, args.split);
        sizes = (train.rows.len(), test.rows.len());
        for (name, method, options) in &variants {
            progress.set_message(format!("{label}: {name}"));
            let start = Instant::now();
            let (model, _) = pipeline::fit(robot, &train, *method, options)?;
            let fit_s = start.elapsed().as_secs_f64();
            let s = model::evaluate(&model, &model.bind(&test)?)?.summary;
            rows.push(Row {
                data: label,
                method: name.clone(),
                mean_mm: s.mean_position_error_mm,
                rms_mm: s.rms_position_error_mm,
                max_mm: s.max_position_error_mm,
                rotation_mrad: s.mean_rotation_error_mrad,
                fit_s,
            });
            progress.inc(1);
        }
    }
    progress.finish_and_clear();
    Ok((rows, sizes))
}

/// One series' diagnosis, timed, and the verdict's effect fitted and tested.
struct Checked {
    series: String,
    train: usize,
    test: usize,
    diagnosis: Diagnosis,
    seconds: Vec<f64>,
    /// CPU seconds (every thread, user and system) of each timed run, sorted.
    cpu_seconds: Vec<f64>,
    effects: String,
    poe_test_mm: f64,
    effect_test_mm: Option<Fitted>,
}

/// The verdict's effect fitted on the training rows, evaluated on the test rows: all of them, and
/// those whose every joint angle lies within (and outside) the range of the training rows' angles
/// (a periodic series of high order is determined only where the training rows are).
struct Fitted {
    all_mm: f64,
    inside: (usize, Option<f64>),
    outside: (usize, Option<f64>),
}

/// The test rows whose joint angles all lie within the training rows' range on every joint, and
/// the others.
fn by_training_range(train: &MeasurementSet, test: &MeasurementSet) -> (Vec<usize>, Vec<usize>) {
    let joints = train.rows.first().map_or(0, |r| r.q.len());
    let range: Vec<(f64, f64)> = (0..joints)
        .map(|j| {
            train.rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| (lo.min(r.q[j]), hi.max(r.q[j])))
        })
        .collect();
    (0..test.rows.len()).partition(|&i| test.rows[i].q.iter().zip(&range).all(|(q, (lo, hi))| (lo..=hi).contains(&q)))
}

fn check_series(args: &Args, robot: &RobotDescription, series: &str) -> Result<Checked> {
    let set = read_series(&args.dataset.input, series, false)?;
    let (train, test) = split(&set, args.split);
    let mut seconds = Vec::new();
    let mut cpu_seconds = Vec::new();
    let mut diagnosis = None;
    for _ in 0..args.repeats.max(1) {
        let cpu = process_cpu_seconds();
        let start = Instant::now();
        diagnosis = Some(diagnose(robot, &train, &DiagnoseOptions::default())?);
        seconds.push(start.elapsed().as_secs_f64());
        cpu_seconds.push(process_cpu_seconds() - cpu);
    }
    let diagnosis = diagnosis.context("no diagnosis ran")?;
    seconds.sort_by(f64::total_cmp);
    cpu_seconds.sort_by(f64::total_cmp);
    let (poe, _) = pipeline::fit(robot, &train, Method::Poe, &FitOptions::default())?;
    let poe_test_mm = model::evaluate(&poe, &poe.bind(&test)?)?.summary.mean_position_error_mm;
    let verdict: Vec<_> = diagnosis.selected.iter().filter(|s| s.effect == diagnosis.verdict.effect).cloned().collect();
    let specs = effects_of(&verdict);
    let effects = specs.iter().map(ToString::to_string).collect::<Vec<_>>().join(",");
    let effect_test_mm = if specs.is_empty() {
        None
    } else {
        let mut options = FitOptions::default();
        options.effects.selection = EffectSelection::List(specs);
        let (model, _) = pipeline::fit(robot, &train, Method::Poe, &options)?;
        let (inside, outside) = by_training_range(&train, &test);
        let mean = |rows: &[usize]| -> Result<Option<f64>> {
            if rows.is_empty() {
                return Ok(None);
            }
            Ok(Some(model::evaluate(&model, &model.bind(test.subset(rows))?)?.summary.mean_position_error_mm))
        };
        Some(Fitted {
            all_mm: model::evaluate(&model, &model.bind(&test)?)?.summary.mean_position_error_mm,
            inside: (inside.len(), mean(&inside)?),
            outside: (outside.len(), mean(&outside)?),
        })
    };
    Ok(Checked {
        series: series.to_owned(),
        train: train.rows.len(),
        test: test.rows.len(),
        diagnosis,
        seconds,
        cpu_seconds,
        effects,
        poe_test_mm,
        effect_test_mm,
    })
}

fn diagnosis_section(args: &Args, checked: &[Checked]) -> String {
    let mut md = String::new();
    diagnosis_intro(&mut md, args);
    verdict_table(&mut md, checked);
    range_table(&mut md, checked);
    series_summaries(&mut md, checked);
    md
}

/// The heading, the data, how it was produced and how to do the same by hand.
fn diagnosis_intro(md: &mut String, args: &Args) {
    let _ = writeln!(md, "{DIAGNOSIS_HEADING}: the verdict, and its prediction tested\n");
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let _ = writeln!(
        md,
        "Series {} of the IPA UR10 data set (see [ur10.md](ur10.md)), position only, {}. Produced by `cargo xtask ur10 \
         --diagnosis-only` (release build, {} threads; load average when it ran: {}). \"predicted\" is the diagnosis's \
         cross-validated held-out error with the verdict's effect, on the training rows alone; \"fitted, test rows\" is \
         that effect identified with the geometry on the training rows and evaluated on the test rows. Diagnose time: \
         median of {} runs (wall clock, `diagnose::diagnose` alone, data already read); CPU: the CPU time it used on \
         all threads (about the wall clock on one idle core; rayon's idle threads spin briefly, which adds a little). The same by hand, for series C \
         (`/work/data` holds the converted CSVs, see `cargo xtask convert-ur10`):\n\n```sh\n\
         calib diagnose --robot fixtures/robots/ur10.ron --data ur10_C_even.csv\n\
         calib fit --robot fixtures/robots/ur10.ron --data ur10_C_even.csv --method poe --effects LIST --out m.ron\n\
         calib eval --model m.ron --data ur10_C_odd.csv\n```\n\nwith LIST the verdict's effects as listed below \
         for each series.\n",
        args.diagnose_series.join(", "),
        split_name(args.split),
        rayon::current_num_threads(),
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" "),
        args.repeats.max(1)
    );
}

/// Each series' verdict, predicted and fitted errors, and the diagnosis's time.
fn verdict_table(md: &mut String, checked: &[Checked]) {
    let _ = writeln!(
        md,
        "| series | train / test poses | verdict | joints | held out before (mm) | predicted (mm) | `poe`, test rows (mm) | fitted, test rows (mm) | fitted / predicted | diagnose (s) | CPU (s) |"
    );
    let _ = writeln!(md, "| --- | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for c in checked {
        let d = &c.diagnosis;
        let joints = d.verdict.joints.iter().map(usize::to_string).collect::<Vec<_>>().join(", ");
        let _ = writeln!(
            md,
            "| {} | {} / {} | {} | {joints} | {:.4} | {:.4} | {:.4} | {} | {} | {:.2} | {:.2} |",
            c.series,
            c.train,
            c.test,
            d.verdict.effect.name(),
            d.heldout_before_mm,
            d.heldout_after_mm,
            c.poe_test_mm,
            c.effect_test_mm.as_ref().map_or("–".into(), |v| format!("{:.4}", v.all_mm)),
            c.effect_test_mm.as_ref().map_or("–".into(), |v| format!("{:.3}", v.all_mm / d.heldout_after_mm)),
            c.seconds[c.seconds.len() / 2],
            c.cpu_seconds[c.cpu_seconds.len() / 2]
        );
    }
}

/// The fitted effect inside and outside the training rows' joint ranges.
fn range_table(md: &mut String, checked: &[Checked]) {
    let _ = writeln!(
        md,
        "\nThe fitted effect on the test rows whose every joint angle lies within the training rows' range, and on \
         the others (where a series is held at its last fitted angle and faded out, and the model blends to the geometry fitted alone):\n"
    );
    let _ =
        writeln!(md, "| series | test rows inside | fitted, inside (mm) | test rows outside | fitted, outside (mm) |");
    let _ = writeln!(md, "| --- | ---: | ---: | ---: | ---: |");
    let value = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.4}"));
    for c in checked {
        if let Some(f) = &c.effect_test_mm {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} |",
                c.series,
                f.inside.0,
                value(f.inside.1),
                f.outside.0,
                value(f.outside.1)
            );
        }
    }
}

/// Each series' fitted effects and diagnosis summary, and where the full report is.
fn series_summaries(md: &mut String, checked: &[Checked]) {
    for c in checked {
        let _ = writeln!(md, "\n### Series {}\n", c.series);
        if !c.effects.is_empty() {
            let _ = writeln!(md, "Fitted: `--effects {}`.\n", c.effects);
        }
        let _ = writeln!(md, "```\n{}```", c.diagnosis.summary());
    }
    let _ = writeln!(
        md,
        "\nThe full report of series {} with plots: [ur10-diagnosis/diagnosis.md](ur10-diagnosis/diagnosis.md).",
        checked.first().map_or("C", |c| c.series.as_str())
    );
}

pub fn run(args: &Args) -> Result<()> {
    let robot = RobotDescription::read(&args.robot).with_context(|| args.robot.display().to_string())?;
    std::fs::create_dir_all(&args.out).with_context(|| args.out.display().to_string())?;
    let methods_md = if args.diagnosis_only { String::new() } else { methods(args, &robot)? };
    println!("{methods_md}");
    let progress = bar(args.diagnose_series.len());
    let mut checked = Vec::new();
    for series in &args.diagnose_series {
        progress.set_message(format!("diagnose series {series}"));
        checked.push(check_series(args, &robot, series)?);
        progress.inc(1);
    }
    progress.finish_and_clear();
    if let Some(first) = checked.first() {
        let folder = args.out.join("ur10-diagnosis");
        report::write_diagnosis_report(&first.diagnosis, &folder, "--out", &measurements::InputFiles::new())?;
    }
    let section = diagnosis_section(args, &checked);
    let path = args.out.join("ur10.md");
    let methods_md = if args.diagnosis_only {
        let old = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
        old.find(DIAGNOSIS_HEADING).map_or(old.clone(), |at| old[..at].to_owned())
    } else {
        methods_md
    };
    let md = format!("{}\n\n{section}", methods_md.trim_end());
    std::fs::write(&path, &md).with_context(|| path.display().to_string())?;
    println!("{section}");
    Ok(())
}
