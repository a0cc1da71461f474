//! `calib diagnose`: where the geometric model misses, which effect explains it, how far it shrinks.

use pipeline::ReadOptions;
use pipeline::diagnose::{DiagnoseOptions, diagnose};
use std::path::PathBuf;

/// Diagnose what a geometric calibration leaves: where, which effect, how far it shrinks.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    robot: crate::robot_args::RobotArgs,
    /// Measurements (SPEC CSV; `;` and decimal commas are detected).
    #[arg(long)]
    data: PathBuf,
    /// Other headers mapped onto the SPEC's column names: NAME=HEADER,… (e.g. x_mm="X [mm]",qw=Q0).
    #[arg(long)]
    columns: Option<pipeline::ColumnMap>,
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
    if let Some(noise) = args.noise_mm
        && !(noise.is_finite() && noise > 0.0)
    {
        return Err(format!("--noise-mm must be a positive number of millimetres, got {noise}").into());
    }
    let robot = args.robot.read()?;
    let read = ReadOptions::for_joints(robot.joint_kinds()).with_columns(args.columns.clone().unwrap_or_default());
    let data = pipeline::read_measurements(&args.data, &read)?;
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
        println!("{}", json_text(diagnosis.to_json())?);
        eprintln!("{}", data.read_summary());
    } else {
        println!("{}", data.read_summary());
        print!("{}", diagnosis.summary());
        if let Some(folder) = &args.report {
            println!("  report:         {}", folder.join("diagnosis.md").display());
        }
    }
    Ok(())
}

/// The diagnosis's JSON text. `Diagnosis::to_json` gives `null` when serialisation failed: that is
/// an error with a non-zero exit, never a `null` printed as if it were the answer.
fn json_text(value: serde_json::Value) -> Result<String, String> {
    match value {
        serde_json::Value::Null => Err("the diagnosis could not be written as JSON".into()),
        value => Ok(value.to_string()),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_diagnosis_that_did_not_serialise_is_an_error_not_null() {
        assert!(super::json_text(serde_json::Value::Null).is_err());
        assert_eq!(super::json_text(serde_json::json!({"n": 1})).unwrap(), r#"{"n":1}"#);
    }
}
