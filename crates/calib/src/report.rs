//! `calib report`: one self-contained HTML page on a calibrated model and test data.

use crate::args::{DataArgs, ModelArg};
use diagnose::{DiagnoseOptions, diagnose};
use std::path::PathBuf;

/// Write a calibration report: one HTML file with the errors before and after on the test
/// measurements (--data), ISO 9283 AP/RP, the effects, the GP, the error over the workspace, the
/// worst poses and the diagnosis.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    model: ModelArg,
    #[command(flatten)]
    robot: crate::robot_args::KeptRobotArgs,
    #[command(flatten)]
    data: DataArgs,
    /// The training measurements (read as --data, with its --columns): their angles on the effect
    /// curves, and the diagnosis.
    #[arg(long)]
    train: Option<PathBuf>,
    /// The HTML file to write.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let mut inputs = measurements::InputFiles::new().with("--model", &args.model.model).with("--data", &args.data.data);
    if let Some(robot) = &args.robot.robot {
        inputs = inputs.with("--robot", robot);
    }
    if let Some(train) = &args.train {
        inputs = inputs.with("--train", train);
    }
    inputs.check_output("--out", &args.out)?;
    let started = std::time::Instant::now();
    let model = args.model.read()?;
    let Some((robot, robot_file)) = args.robot.read_or_kept(&model, &args.model.model)? else {
        return Err(format!(
            "{}: the model does not keep its robot description (written before it was kept): give --robot",
            args.model.model.display()
        )
        .into());
    };
    let data = args.data.read(model.read_options(Default::default()))?;
    let evaluation = model::evaluate(&model, &model.bind(&data)?)?;
    let finite = |e: &model::PoseError| e.position_mm.is_finite() && e.rotation_mrad.is_none_or(f64::is_finite);
    if let Some((row, _)) = data.rows.iter().zip(&evaluation.errors).find(|(_, e)| !finite(e)) {
        return Err(calib::flow::Refused::non_finite(&args.model.model, &data.source, row.line).into());
    }
    let train = args
        .train
        .as_ref()
        .map(|path| args.data.columns.read(path, model.read_options(Default::default())))
        .transpose()?;
    let diagnosis = train.as_ref().map(|t| diagnose(&robot, t, &DiagnoseOptions::default())).transpose()?;
    let model_file = args.model.model.display().to_string();
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
