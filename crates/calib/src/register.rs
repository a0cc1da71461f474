//! `calib register`: a calibrated model carried to a moved tracker or new tools from a few poses
//! (crate `cell`).

use crate::args::{JsonFlag, ModelDataArgs};
use std::path::PathBuf;

/// Re-fit the tracker-to-base transform and/or the tools from a few poses (--data, full-pose or
/// position-only), everything else held.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    data: ModelDataArgs,
    /// The registered model (RON); never one of the inputs.
    #[arg(long)]
    out: PathBuf,
    /// What to re-fit: base, tools or base,tools (a tool the model does not know is a new tool).
    #[arg(long, default_value = "base")]
    refit: cell::Refit,
    /// The model's own held-out mean position error, mm (e.g. `calib eval` on rows it was not
    /// fitted on): the residual is judged against it. Default: the fit's estimate kept in the
    /// model file (models written before it was kept have none).
    #[arg(long)]
    heldout_mm: Option<f64>,
    /// The residual-to-held-out ratio above which the robot is said to have changed.
    #[arg(long, default_value_t = cell::RegisterOptions::default().changed_ratio)]
    changed_ratio: f64,
    #[command(flatten)]
    json: JsonFlag,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    measurements::InputFiles::new()
        .with("--model", args.data.model_file())
        .with("--data", &args.data.data.data)
        .check_output("--out", &args.out)?;
    let (model, data) = args.data.read()?;
    let register = cell::RegisterOptions { changed_ratio: args.changed_ratio, ..cell::RegisterOptions::default() };
    let registered = cell::register(&model, &data, args.refit, args.heldout_mm, &register)?;
    let text = cell::checked_model_text(&registered.model, &args.out.display().to_string())?;
    measurements::write_file(&args.out, text.as_bytes())?;
    let report = &registered.report;
    if args.json.json {
        println!("{}", serde_json::to_string(report)?);
        eprintln!("{}", data.read_summary());
        eprintln!("{}", report.verdict_line());
        for note in &report.wrapped {
            eprintln!("note: {note}");
        }
        let warnings = report.out_of_range.iter().map(ToString::to_string);
        let warnings = warnings.chain(report.extrapolation.iter().map(ToString::to_string));
        let warnings = warnings.chain(report.beyond_joint_limits.iter().map(ToString::to_string));
        for warning in warnings.chain(report.warnings.iter().map(ToString::to_string)) {
            eprintln!("warning: {warning}");
        }
    } else {
        println!("{}", data.read_summary());
        for line in report.lines() {
            println!("{line}");
        }
        println!("wrote {}", args.out.display());
    }
    Ok(())
}
