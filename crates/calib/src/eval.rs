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
    let calib::flow::Evaluated { data, evaluation, report, notices } =
        calib::flow::evaluate(&model, args.data.model_file(), true, data)?;
    if args.json.json {
        println!("{}", serde_json::to_string(&report)?);
        eprintln!("{}", data.read_summary());
        for note in &notices.notes {
            eprintln!("note: {note}");
        }
        for warning in &notices.warnings {
            eprintln!("warning: {warning}");
        }
        return Ok(());
    }
    let s = &evaluation.summary;
    println!("{}", data.read_summary());
    println!("{} model of {} on {} ({} rows)", model.method, model.robot, args.data.display(), s.n);
    println!(
        "  position error: mean {:.4} mm, rms {:.4} mm, median {:.4} mm, max {:.4} mm",
        s.mean_position_error_mm, s.rms_position_error_mm, s.median_position_error_mm, s.max_position_error_mm
    );
    if let (Some(mean), Some(max)) = (s.mean_rotation_error_mrad, s.max_rotation_error_mrad) {
        println!("  rotation error: mean {mean:.4} mrad, max {max:.4} mrad");
    }
    for note in &notices.notes {
        println!("  note: {note}");
    }
    let covered = if report.sigma_fallback.is_some() {
        "the effects' coverage (the angles they were fitted on, their σ within the fallback limit)"
    } else {
        "the angles the effects were fitted on"
    };
    print_split(report.coverage.as_ref(), covered);
    print_split(report.range_split.as_ref(), "the range the model was fitted on");
    for warning in &notices.warnings {
        println!("  warning: {warning}");
    }
    Ok(())
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
