//! `calib diagnose`: where the geometric model misses, which effect explains it, how far it shrinks.

use pipeline::RobotDescription;
use pipeline::diagnose::{DiagnoseOptions, diagnose};
use std::path::PathBuf;

/// Diagnose what a geometric calibration leaves: where, which effect, how far it shrinks.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Robot description (RON).
    #[arg(long)]
    robot: PathBuf,
    /// Measurements (SPEC CSV).
    #[arg(long)]
    data: PathBuf,
    /// Print one JSON object on stdout instead of the summary.
    #[arg(long)]
    json: bool,
    /// The tracker's noise per axis, mm, if known (otherwise estimated from the data).
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
    if let Some(noise) = args.noise_mm {
        if !(noise.is_finite() && noise > 0.0) {
            return Err(format!("--noise-mm must be a positive number of millimetres, got {noise}").into());
        }
    }
    let robot = RobotDescription::read(&args.robot)?;
    let data = pipeline::read_measurements(&args.data, Some(robot.joint_count()))?;
    let options =
        DiagnoseOptions { folds: args.folds, seed: args.seed, noise_mm: args.noise_mm, ..DiagnoseOptions::default() };
    let diagnosis = diagnose(&robot, &data, &options)?;
    if let Some(folder) = &args.report {
        std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
        let plots = diagnosis.plots();
        for (name, svg) in &plots {
            let path = folder.join(name);
            std::fs::write(&path, svg).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        let names: Vec<String> = plots.into_iter().map(|(name, _)| name).collect();
        let path = folder.join("diagnosis.md");
        std::fs::write(&path, diagnosis.markdown(&names)).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if args.json {
        println!("{}", diagnosis.to_json());
    } else {
        print!("{}", diagnosis.summary());
        if let Some(folder) = &args.report {
            println!("  report:         {}", folder.join("diagnosis.md").display());
        }
    }
    Ok(())
}
