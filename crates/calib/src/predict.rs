//! `calib predict`: the compensated pose of every row of a joint file, with the GP's standard
//! deviation where the model has a GP.

use crate::args::ModelDataArgs;
use std::io::Write;

/// Predict the tool pose (tracker frame) for the joint configurations of --data (its position
/// columns may be left out), as CSV on stdout.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    data: ModelDataArgs,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let (model, read) = args.data.read_configurations()?;
    // Angles a turn away from the fitted range are taken into it, as `calib register` does; the
    // CSV's columns are the same, the note on stderr says which rows.
    let (data, wrapped) = calib::flow::wrapped(&model, read);
    // The one binding of `predict`: joints checked, tools mapped.
    let bound = model.bind(&data)?;
    let predicted = calib::flow::predict(&model, args.data.model_file(), &bound, &wrapped)?;
    for joint in &predicted.notes {
        eprintln!("note: {joint}");
    }
    for warning in &predicted.warnings {
        eprintln!("warning: {warning}");
    }
    let predictions = predicted.poses;
    model::write_predictions(std::io::stdout().lock(), "stdout", &model, &data, &predictions)?;
    std::io::stdout().flush()?;
    eprintln!("{}", data.read_summary());
    Ok(())
}
