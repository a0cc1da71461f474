//! `calib diagnose`: where the geometric model misses, which effect explains it, how far it shrinks.

use crate::args::{JsonFlag, RobotDataArgs};
use diagnose::DiagnoseOptions;
use std::path::PathBuf;

/// Diagnose what a geometric calibration leaves: where, which effect, how far it shrinks.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    data: RobotDataArgs,
    #[command(flatten)]
    json: JsonFlag,
    /// The instrument's noise per axis, mm, if known (otherwise from repeated poses, or a laser
    /// tracker's default, as the report says).
    #[arg(long)]
    noise_mm: Option<f64>,
    /// Write a markdown report with SVG plots into this folder.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Cross-validation folds.
    #[arg(long, default_value_t = 5)]
    folds: usize,
    /// Seed of the fold assignment.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(noise) = args.noise_mm
        && !(noise.is_finite() && noise > 0.0)
    {
        return Err(format!("--noise-mm must be a positive number of millimetres, got {noise}").into());
    }
    let inputs =
        measurements::InputFiles::new().with("--robot", &args.data.robot.robot).with("--data", &args.data.data.data);
    let (robot, data) = args.data.read(Vec::new())?;
    let options =
        DiagnoseOptions { folds: args.folds, seed: args.seed, noise_mm: args.noise_mm, ..DiagnoseOptions::default() };
    let report = args.report.as_deref().map(|folder| (folder, "--report", &inputs));
    let (diagnosis, report) = calib::flow::diagnose(&robot, &data, &options, report)?;
    if args.json.json {
        println!("{}", diagnosis.to_json()?);
        eprintln!("{}", data.read_summary());
    } else {
        println!("{}", data.read_summary());
        print!("{}", diagnosis.summary());
        if let Some(path) = report {
            println!("  report:         {}", path.display());
        }
    }
    Ok(())
}
