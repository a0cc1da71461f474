//! `calib eval`: the errors of a calibrated model on measurements.

use crate::args::{JsonFlag, ModelDataArgs};

/// Evaluate a calibrated model on measurements.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    data: ModelDataArgs,
    #[command(flatten)]
    json: JsonFlag,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let (model, data) = args.data.read()?;
    // Angles a turn away from the fitted range taken into it, the one binding, the evaluation.
    let calib::flow::Evaluated { data, evaluation, report } =
        calib::flow::evaluate(&model, args.data.model_file(), data)?;
    if args.json.json {
        println!("{}", serde_json::to_string(&report)?);
        print_json_notes(&data, &report, args);
        return Ok(());
    }
    print_text(&model, &data, &evaluation.summary, &report, args);
    Ok(())
}

/// The notes and warnings of `--json`, on stderr beside the report on stdout.
fn print_json_notes(data: &measurements::MeasurementSet, report: &model::EvalReport, args: &Args) {
    eprintln!("{}", data.read_summary());
    for joint in &report.wrapped {
        eprintln!("note: {joint}");
    }
    if report.orientations_not_evaluated {
        eprintln!("note: {}", model::ORIENTATIONS_NOT_EVALUATED);
    }
    if let Some(placement) = &report.other_placement {
        eprintln!("warning: {}", placement_text(placement, args));
    }
    for warning in &report.warnings {
        eprintln!("warning: {warning}");
    }
    for warning in &report.out_of_range {
        eprintln!("warning: {warning}");
    }
    if let Some(predicted) = &report.geometry_sigma {
        eprintln!("warning: {predicted}");
    }
    for warning in &report.beyond_joint_limits {
        eprintln!("warning: {warning}");
    }
    if let Some(suspects) = &report.suspect_rows {
        eprintln!("warning: {}", suspect_text(suspects));
    }
    if let Some(fallen) = &report.sigma_fallback {
        eprintln!("warning: {fallen}");
    }
    if let Some(faded) = &report.gp_fade {
        eprintln!("warning: {faded}");
    }
}

/// The evaluation for a reader: the errors, then the notes and warnings.
fn print_text(
    model: &model::CalibratedModel,
    data: &measurements::MeasurementSet,
    s: &model::ErrorSummary,
    report: &model::EvalReport,
    args: &Args,
) {
    println!("{}", data.read_summary());
    println!("{} model of {} on {} ({} rows)", model.method, model.robot, args.data.display(), s.n);
    println!(
        "  position error: mean {:.4} mm, rms {:.4} mm, median {:.4} mm, max {:.4} mm",
        s.mean_position_error_mm, s.rms_position_error_mm, s.median_position_error_mm, s.max_position_error_mm
    );
    if let (Some(mean), Some(max)) = (s.mean_rotation_error_mrad, s.max_rotation_error_mrad) {
        println!("  rotation error: mean {mean:.4} mrad, max {max:.4} mrad");
    }
    if report.orientations_not_evaluated {
        println!("  note: {}", model::ORIENTATIONS_NOT_EVALUATED);
    }
    for joint in &report.wrapped {
        println!("  note: {joint}");
    }
    let covered = if report.sigma_fallback.is_some() {
        "the effects' coverage (the angles they were fitted on, their σ within the fallback limit)"
    } else {
        "the angles the effects were fitted on"
    };
    print_split(report.coverage.as_ref(), covered);
    print_split(report.range_split.as_ref(), "the range the model was fitted on");
    if let Some(placement) = &report.other_placement {
        println!("  warning: {}", placement_text(placement, args));
    }
    if let Some(suspects) = &report.suspect_rows {
        println!("  warning: {}", suspect_text(suspects));
    }
    for warning in &report.warnings {
        println!("  warning: {warning}");
    }
    for warning in &report.out_of_range {
        println!("  warning: {warning}");
    }
    if let Some(predicted) = &report.geometry_sigma {
        println!("  warning: {predicted}");
    }
    for warning in &report.beyond_joint_limits {
        println!("  warning: {warning}");
    }
    if let Some(fallen) = &report.sigma_fallback {
        println!("  warning: {fallen}");
    }
    if let Some(faded) = &report.gp_fade {
        println!("  warning: {faded}");
    }
}

/// The warning about another tracker placement, with this model's file in the command it names.
fn placement_text(placement: &model::OtherPlacement, args: &Args) -> String {
    placement.to_string().replace("--model MODEL", &format!("--model {}", args.data.model_file().display()))
}

/// The warning about rows far beyond the others, with what the others give.
fn suspect_text(suspects: &model::SuspectRows) -> String {
    let w = &suspects.without;
    format!(
        "{} row(s) lie beyond {} robust sigmas of the other rows' errors: {}; a measurement error \
         (a tracker glitch, a row measured twice apart) more likely than the model's; without them: \
         mean {:.4} mm, max {:.4} mm (the numbers above keep them)",
        suspects.rows.len(),
        suspects.threshold_sigmas,
        measurements::list_lines(&suspects.rows),
        w.mean_position_error_mm,
        w.max_position_error_mm
    )
}

/// The two lines of a split: `inside WHAT: …` and `outside WHAT: …`, each where it has rows.
fn print_split(split: Option<&model::CoverageSplit>, what: &str) {
    let Some(split) = split else { return };
    for (side, part) in [("inside", &split.inside), ("outside", &split.outside)] {
        if part.n > 0 {
            println!(
                "  {side} {what}: {} rows, mean {:.4} mm, max {:.4} mm",
                part.n, part.mean_position_error_mm, part.max_position_error_mm
            );
        }
    }
}
