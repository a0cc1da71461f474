//! `cargo xtask ur10`: every method and the diagnosis on the real UR10 tracker data of Landgraf et
//! al. (CASE 2021): train on the first half of a series (in measurement order), test on the second.
//! Writes `ur10.md` and the diagnosis report into `--out`.

use crate::convert_ur10::{Dataset, read_series};
use indicatif::{ProgressBar, ProgressStyle};
use pipeline::diagnose::{DiagnoseOptions, diagnose};
use pipeline::{CompensationOptions, FitOptions, MeasurementSet, Method, ResidualFrame, RobotDescription};
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

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

fn halves(set: &MeasurementSet) -> (MeasurementSet, MeasurementSet) {
    let half = set.rows.len() / 2;
    (set.subset(&(0..half).collect::<Vec<_>>()), set.subset(&(half..set.rows.len()).collect::<Vec<_>>()))
}

pub fn run(args: &Args) -> Result<(), String> {
    let robot = RobotDescription::read(&args.robot).map_err(|e| e.to_string())?;
    let paper = CompensationOptions {
        gp: gp::GpConfig { kernel: gp::KernelChoice::Quadratic, ..gp::GpConfig::default() },
        residual_frame: ResidualFrame::Tracker,
        ..CompensationOptions::default()
    };
    let variants: Vec<(String, Method, FitOptions)> = vec![
        ("base-tool".into(), Method::BaseTool, FitOptions::default()),
        ("poe".into(), Method::Poe, FitOptions::default()),
        ("poe-gp".into(), Method::PoeGp, FitOptions::default()),
        ("poe-gp-load".into(), Method::PoeGpLoad, FitOptions::default()),
        (
            "poe-gp, paper's kernel (Eq. 5) and frame (Eq. 8)".into(),
            Method::PoeGp,
            FitOptions { compensation: paper, ..FitOptions::default() },
        ),
    ];
    let bar = ProgressBar::new(2 * variants.len() as u64 + 1);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut rows = Vec::new();
    let mut sizes = (0, 0);
    for (label, full_pose) in [("position", false), ("full pose", true)] {
        let set = read_series(&args.dataset.input, &args.dataset.series, full_pose)?;
        let (train, test) = halves(&set);
        sizes = (train.rows.len(), test.rows.len());
        for (name, method, options) in &variants {
            bar.set_message(format!("{label}: {name}"));
            let start = Instant::now();
            let (model, _) = pipeline::fit(&robot, &train, *method, options).map_err(|e| e.to_string())?;
            let fit_s = start.elapsed().as_secs_f64();
            let s = pipeline::evaluate(&model, &test).map_err(|e| e.to_string())?.summary;
            rows.push(Row {
                data: label,
                method: name.clone(),
                mean_mm: s.mean_position_error_mm,
                rms_mm: s.rms_position_error_mm,
                max_mm: s.max_position_error_mm,
                rotation_mrad: s.mean_rotation_error_mrad,
                fit_s,
            });
            bar.inc(1);
        }
    }
    bar.set_message("diagnose");
    let set = read_series(&args.dataset.input, &args.dataset.series, false)?;
    let (train, _) = halves(&set);
    let start = Instant::now();
    let diagnosis = diagnose(&robot, &train, &DiagnoseOptions::default()).map_err(|e| e.to_string())?;
    let diagnose_s = start.elapsed().as_secs_f64();
    bar.finish_and_clear();

    diagnosis.write_report(&args.out.join("ur10-diagnosis")).map_err(|e| e.to_string())?;

    let mut md = String::new();
    let _ = writeln!(md, "# The real UR10: every method and the diagnosis\n");
    let _ = writeln!(
        md,
        "Data: series {} of the IPA UR10 data set (Landgraf, Ernst, Schleth, Fabritius, Huber, *A hybrid neural \
         network approach for increasing the absolute accuracy of industrial robots*, CASE 2021; MIT licence; not part of \
         this repository): a UR10 measured with a Leica laser tracker and a T-Mac at random poses, no payload variation. \
         Train on the first half of the rows in measurement order ({} poses), test on the second ({} poses). \
         Orientation from the tracker's rx, ry, rz as R = Rx Ry Rz. Produced by `cargo xtask ur10`.\n",
        args.dataset.series, sizes.0, sizes.1
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
        "\n`poe-gp-load` equals `poe-gp` here: the data set has one payload, so the payload input is constant.\n"
    );
    let _ = writeln!(md, "## Diagnosis of the training half (position only, {diagnose_s:.1} s)\n");
    let _ = writeln!(md, "```\n{}```\n", diagnosis.summary());
    let _ = writeln!(md, "The full report with plots: [ur10-diagnosis/diagnosis.md](ur10-diagnosis/diagnosis.md).");
    let path = args.out.join("ur10.md");
    std::fs::write(&path, &md).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{md}");
    Ok(())
}
