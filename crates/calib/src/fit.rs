//! `calib fit`: fit a calibration method to measurements and write the model.

use pipeline::{ErrorSummary, FitOptions, Method, ReadOptions};
use std::path::PathBuf;

/// Fit a calibrated model to measurements.
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
    /// Calibration method: base-tool, poe, poe-gp or poe-gp-load.
    #[arg(long)]
    method: Method,
    /// Where to write the calibrated model (RON).
    #[arg(long)]
    out: PathBuf,
    /// Also identify joint compliance with the geometry, through gravity-torque regressors (no
    /// masses needed; uses the payload column). Beyond the paper; applied before any GP.
    #[arg(long)]
    joint_compliance: bool,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let robot = args.robot.read()?;
    let options = ReadOptions::for_joints(robot.joint_kinds()).with_columns(args.columns.clone().unwrap_or_default());
    let data = pipeline::read_measurements(&args.data, &options)?;
    println!("{}", data.read_summary());
    let options = FitOptions { joint_compliance: args.joint_compliance, ..FitOptions::default() };
    let (model, report) = pipeline::fit(&robot, &data, args.method, &options)?;
    pipeline::write_model(&args.out, &model)?;

    let kind = if data.full_pose { "full pose" } else { "position only" };
    let tools = data.tools.iter().filter(|t| !t.is_empty()).count().max(1);
    println!(
        "{} on {} ({} rows, {kind}, {tools} tool{}) for {}",
        args.method,
        args.data.display(),
        data.rows.len(),
        if tools == 1 { "" } else { "s" },
        robot.name
    );
    print_errors("training error before (nominal, registered)", &report.before);
    print_errors("training error after", &report.after);
    let id = &report.identification;
    println!(
        "  identifiable: {} of {} free parameters, condition number {:.3e}",
        id.rank, id.free_parameters, id.condition_number
    );
    if let Some(compliance) = &model.joint_compliance {
        println!("  joint compliance: {} torque-regressor terms identified with the geometry", compliance.terms.len());
    }
    for direction in &id.unidentifiable {
        println!("    unidentifiable: {direction}");
    }
    println!("  iterations: {} ({})", id.iteration_count(), id.termination);
    println!("  wrote {}", args.out.display());
    Ok(())
}

fn print_errors(label: &str, summary: &ErrorSummary) {
    print!(
        "  {label}: mean {:.4} mm, rms {:.4} mm, max {:.4} mm",
        summary.mean_position_error_mm, summary.rms_position_error_mm, summary.max_position_error_mm
    );
    match summary.mean_rotation_error_mrad {
        Some(rotation) => println!(", rotation mean {rotation:.4} mrad"),
        None => println!(),
    }
}
