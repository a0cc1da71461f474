//! `calib report`: one self-contained HTML page on a calibrated model and test data.

use diagnose::{DiagnoseOptions, diagnose};
use measurements::ColumnMap;
use std::path::PathBuf;

/// Write a calibration report: one HTML file with the errors before and after, ISO 9283 AP/RP,
/// the effects, the GP, the error over the workspace, the worst poses and the diagnosis.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Calibrated model (RON, from `calib fit`).
    #[arg(long)]
    model: PathBuf,
    #[command(flatten)]
    robot: crate::robot_args::KeptRobotArgs,
    /// Test measurements (SPEC CSV; `;` and decimal commas are detected).
    #[arg(long)]
    data: PathBuf,
    /// The training measurements: their angles on the effect curves, and the diagnosis.
    #[arg(long)]
    train: Option<PathBuf>,
    /// Other headers mapped onto the SPEC's column names (both files): NAME=HEADER,…
    #[arg(long)]
    columns: Option<ColumnMap>,
    /// The HTML file to write.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let mut inputs = measurements::InputFiles::new().with("--model", &args.model).with("--data", &args.data);
    if let Some(robot) = &args.robot.robot {
        inputs = inputs.with("--robot", robot);
    }
    if let Some(train) = &args.train {
        inputs = inputs.with("--train", train);
    }
    inputs.check_output("--out", &args.out)?;
    let started = std::time::Instant::now();
    let model = model::read_model(&args.model)?;
    let Some((robot, robot_file)) = args.robot.read_or_kept(&model, &args.model)? else {
        return Err(format!(
            "{}: the model does not keep its robot description (written before it was kept): give --robot",
            args.model.display()
        )
        .into());
    };
    let options = model.read_options(args.columns.clone().unwrap_or_default());
    let data = measurements::read_measurements(&args.data, &options)?;
    let evaluation = model::evaluate(&model, &model.bind(&data)?)?;
    let finite = |e: &model::PoseError| e.position_mm.is_finite() && e.rotation_mrad.is_none_or(f64::is_finite);
    if let Some((row, _)) = data.rows.iter().zip(&evaluation.errors).find(|(_, e)| !finite(e)) {
        return Err(crate::predict::non_finite(&args.model, &data.source, row.line).into());
    }
    let train = args.train.as_ref().map(|path| measurements::read_measurements(path, &options)).transpose()?;
    let diagnosis = train.as_ref().map(|t| diagnose(&robot, t, &DiagnoseOptions::default())).transpose()?;
    let model_file = args.model.display().to_string();
    let report_inputs = ::report::ReportInputs {
        model: &model,
        model_file: &model_file,
        robot: &robot,
        robot_file: &robot_file,
        data: &data,
        training: train.as_ref(),
    };
    let built = ::report::Report::build(&report_inputs, diagnosis, &::report::ReportOptions::default())?;
    let written = std::time::Instant::now();
    let html = ::report::render_html(&built)?;
    measurements::write_file(&args.out, html.as_bytes())?;
    eprintln!("{}", data.read_summary());
    println!(
        "report: {} ({} bytes; {:.2} s in all, {:.3} s to draw and write the page)",
        args.out.display(),
        html.len(),
        started.elapsed().as_secs_f64(),
        written.elapsed().as_secs_f64()
    );
    Ok(())
}
