//! `calib predict`: the compensated pose of every row of a joint file, with the GP's standard
//! deviation where the model has a GP.

use std::io::Write;
use std::path::PathBuf;

/// Predict the tool pose (tracker frame) for joint configurations, as CSV on stdout.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Calibrated model (RON, from `calib fit`).
    #[arg(long)]
    model: PathBuf,
    /// Joint configurations: the measurement CSV; the position columns may be left out.
    #[arg(long)]
    data: PathBuf,
    /// Other headers mapped onto the SPEC's column names: NAME=HEADER,… (e.g. x_mm="X [mm]",qw=Q0).
    #[arg(long)]
    columns: Option<pipeline::ColumnMap>,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let model = pipeline::read_model(&args.model)?;
    let options =
        pipeline::ReadOptions::for_joints(model.joint_kinds()).with_columns(args.columns.clone().unwrap_or_default());
    let data = pipeline::read_configurations(&args.data, &options)?;
    let tools = pipeline::tool_indices(&model, &data)?;
    let predictions = model.predict(&data.rows, &tools)?;
    let finite = |p: &pipeline::PredictedPose| {
        let pose = p.pose;
        pose.translation().iter().chain(pose.rotation().matrix().iter()).all(|v| v.is_finite())
    };
    if let Some(row) = data.rows.iter().zip(&predictions).find_map(|(row, p)| (!finite(p)).then_some(row)) {
        return Err(non_finite(&args.model, &data.source, row.line).into());
    }
    for warning in model.extrapolation(&data.rows) {
        eprintln!("warning: {warning}");
    }
    for warning in model.outside_training_range(&data.rows) {
        eprintln!("warning: {warning}");
    }
    for warning in model.beyond_joint_limits(&data.rows) {
        eprintln!("warning: {warning}");
    }
    let stdout = std::io::stdout();
    let mut out = csv::Writer::from_writer(stdout.lock());
    // The GP's standard deviation, and that of what the effects leave where they fade out.
    let gp = model.predicts_std();
    let mut header: Vec<&str> = vec!["line", "x_mm", "y_mm", "z_mm"];
    if model.full_pose {
        header.extend(["qw", "qx", "qy", "qz"]);
    }
    if gp {
        header.extend(["std_x_mm", "std_y_mm", "std_z_mm"]);
        if model.full_pose {
            header.extend(["std_rx_mrad", "std_ry_mrad", "std_rz_mrad"]);
        }
    }
    if data.positions_measured {
        header.push("error_mm");
    }
    out.write_record(&header)?;
    for (row, prediction) in data.rows.iter().zip(&predictions) {
        let p = prediction.pose.translation() * 1e3;
        let mut record =
            vec![row.line.to_string(), format!("{:.6}", p.x), format!("{:.6}", p.y), format!("{:.6}", p.z)];
        if model.full_pose {
            record.extend(prediction.pose.rotation().to_quaternion().iter().map(|v| format!("{v:.9}")));
        }
        if let Some(std) = prediction.std {
            record.extend(std[..3].iter().map(|s| format!("{:.6}", s * 1e3)));
            if model.full_pose {
                record.extend(std[3..].iter().map(|s| format!("{:.6}", s * 1e3)));
            }
        }
        if data.positions_measured {
            record.push(format!("{:.6}", (row.position - prediction.pose.translation()).norm() * 1e3));
        }
        out.write_record(&record)?;
    }
    out.flush()?;
    std::io::stdout().flush()?;
    eprintln!("{}", data.read_summary());
    Ok(())
}

/// The refusal of a model that predicts a non-finite pose: a value in its file beyond any real
/// range (the file's check accepts every finite number), never a NaN printed as an answer.
pub(crate) fn non_finite(model: &std::path::Path, data: &str, line: u64) -> String {
    format!(
        "{}: the model predicts a non-finite pose for line {line} of {data}: a value in the model file is beyond any real range",
        model.display()
    )
}
