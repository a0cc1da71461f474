//! `calib compensate`: joint targets rewritten so that the calibrated robot reaches what they mean.

use crate::args::{ColumnsArg, ModelArg};
use cell::TargetFrame;
use std::io::Write;
use std::path::PathBuf;

/// Rewrite a program's joint targets so that the calibrated model reaches the intended poses.
///
/// TARGETS holds either joint columns alone (a program taught on the nominal model: the intended
/// pose is where the nominal model, placed on the calibrated one by base and tool, puts the tool;
/// needs the robot description: --robot, or the one the model keeps), or tool poses (x_mm … and optionally an orientation) with seed joint columns.
/// The whole model counts: geometry, joint compliance and the GP, with each row's payload_kg.
/// Output CSV on stdout: q1_rad … qN_rad (empty where refused), the input columns (joint columns
/// as nominal_…), residual_mm, residual_mrad and status (ok, or why the row was refused).
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    model: ModelArg,
    /// The targets (SPEC CSV): joint columns, and for pose targets x_mm, y_mm, z_mm and optionally
    /// qw, qx, qy, qz or rx_deg, ry_deg, rz_deg.
    #[arg(long)]
    targets: PathBuf,
    /// The robot description the model was fitted with: the nominal model of joint targets, the
    /// base frame of --frame base, and the joint limits.
    #[command(flatten)]
    robot: crate::robot_args::KeptRobotArgs,
    /// Frame of pose targets: tracker or base.
    #[arg(long, default_value = "tracker")]
    frame: TargetFrame,
    #[command(flatten)]
    columns: ColumnsArg,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let model = args.model.read()?;
    let robot = args.robot.read_or_kept(&model, &args.model.model)?;
    let robot_ref = robot.as_ref().map(|(r, f)| (r, f.as_str()));
    let calib::flow::CompensatedTargets { file, solved, summary, warnings } =
        calib::flow::compensate(&model, &args.targets, args.columns.map(), robot_ref, args.frame)?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    cell::write_compensated(&mut out, &file, &solved)?;
    out.flush()?;
    eprintln!("{}", file.set.read_summary());
    for warning in &warnings {
        eprintln!("warning: {warning}");
    }
    let refused = summary.rows - summary.ok;
    let mut line = format!("compensated {} of {} targets", summary.ok, summary.rows);
    if refused > 0 {
        line.push_str(&format!(
            "; refused {refused} (outside limits {}, no convergence {}, singular {}: see status)",
            summary.outside_limits, summary.no_convergence, summary.singular
        ));
    }
    if let Some(rms) = summary.registration_rms_mm {
        line.push_str(&format!(
            "; before compensation the model misses the intended poses by {:.4} mm mean (nominal placed by base and tool, RMS {rms:.4} mm)",
            summary.before_mean_mm
        ));
    }
    if !model.full_pose {
        line.push_str("; position-only model: the tool point is compensated, not the orientation");
    }
    if robot.is_none() {
        line.push_str("; no --robot and the model keeps none: joint limits not checked");
    }
    eprintln!("{line}");
    Ok(())
}
