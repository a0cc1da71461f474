//! `calib eval`: the errors of a calibrated model on measurements.

use std::path::PathBuf;

/// Evaluate a calibrated model on measurements.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Calibrated model (RON, from `calib fit`).
    #[arg(long)]
    model: PathBuf,
    /// Measurements (SPEC CSV).
    #[arg(long)]
    data: PathBuf,
    /// Print one JSON object on stdout instead of a table.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let model = pipeline::read_model(&args.model)?;
    let data = pipeline::read_measurements(&args.data, &pipeline::ReadOptions::for_joints(model.joint_kinds()))?;
    let evaluation = pipeline::evaluate(&model, &data)?;
    let s = &evaluation.summary;
    if args.json {
        let mut value = serde_json::to_value(s)?;
        if let Some(object) = value.as_object_mut() {
            object.insert("method".into(), model.method.name().into());
            object.insert("full_pose".into(), data.full_pose.into());
        }
        println!("{value}");
        return Ok(());
    }
    println!("{} model of {} on {} ({} rows)", model.method, model.robot, args.data.display(), s.n);
    println!(
        "  position error: mean {:.4} mm, rms {:.4} mm, median {:.4} mm, max {:.4} mm",
        s.mean_position_error_mm, s.rms_position_error_mm, s.median_position_error_mm, s.max_position_error_mm
    );
    if let (Some(mean), Some(max)) = (s.mean_rotation_error_mrad, s.max_rotation_error_mrad) {
        println!("  rotation error: mean {mean:.4} mrad, max {max:.4} mrad");
    }
    Ok(())
}
