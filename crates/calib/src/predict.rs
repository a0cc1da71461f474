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
    columns: Option<measurements::ColumnMap>,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let model = model::read_model(&args.model)?;
    let options = model.read_options(args.columns.clone().unwrap_or_default());
    let read = measurements::read_configurations(&args.data, &options)?;
    // Angles a turn away from the fitted range are taken into it, as `calib register` does; the
    // CSV's columns are the same, the note on stderr says which rows.
    let (rows, wrapped) = model::wrapped(&model, &read.rows);
    let data = measurements::MeasurementSet { rows, ..read };
    // The one binding of `predict`: joints checked, tools mapped.
    let bound = model.bind(&data)?;
    let predictions = model.predict(&bound)?;
    let finite = |p: &model::PredictedPose| {
        let pose = p.pose;
        pose.translation().iter().chain(pose.rotation().matrix().iter()).all(|v| v.is_finite())
    };
    if let Some(row) = data.rows.iter().zip(&predictions).find_map(|(row, p)| (!finite(p)).then_some(row)) {
        return Err(non_finite(&args.model, &data.source, row.line).into());
    }
    for joint in &wrapped {
        eprintln!("note: {joint}");
    }
    for warning in model.extrapolation(&data.rows) {
        eprintln!("warning: {warning}");
    }
    for warning in model.outside_training_range(&data.rows) {
        eprintln!("warning: {warning}");
    }
    if let Some(predicted) = model.geometry_sigma(&bound)? {
        eprintln!("warning: {predicted}");
    }
    for warning in model.beyond_joint_limits(&data.rows) {
        eprintln!("warning: {warning}");
    }
    if let Some(fallen) = model.sigma_fallback(&bound)? {
        eprintln!("warning: {fallen}");
    }
    if let Some(faded) = model.gp_fade(&data.rows)? {
        eprintln!("warning: {faded}");
    }
    model::write_predictions(std::io::stdout().lock(), "stdout", &model, &data, &predictions)?;
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
