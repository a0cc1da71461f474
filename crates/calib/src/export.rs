//! `calib export`: the calibrated geometry as a URDF for controllers, planners and simulators.

use crate::args::{JsonFlag, ModelArg};
use cell::UrdfTemplate;
use robot::{NominalTolerance, UrdfDocument};
use std::path::PathBuf;

/// Write a calibrated model's geometry as a URDF.
///
/// The URDF is in the robot's base frame (joint 1 where the nominal description puts it, as
/// calibrated), with a fixed `tracker` link at the tracker frame and a fixed link per calibrated
/// tool. What a URDF cannot hold (joint compliance, the GP) is reported with the error the model
/// makes without it on the training data (--data). The base frame and the limits come from the
/// nominal description: --like's URDF, else --robot, else the one the model keeps; a model written
/// before it kept its robot and given neither has its base at the calibrated joint 1 frame and its
/// revolute joints written as continuous.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    model: ModelArg,
    /// Where to write the URDF.
    #[arg(long)]
    urdf: PathBuf,
    /// Write into this URDF (of the robot the model was fitted with): its links, inertias, visuals
    /// and limits are kept, the movable joints' origins become the calibrated ones (--base-link
    /// and --tip-link choose its chain).
    #[arg(long, conflicts_with = "robot")]
    like: Option<PathBuf>,
    // The nominal robot description places the base frame and gives the limits: --like's URDF,
    // else --robot, else the one the model keeps (the group compensate and report take); without
    // any (a model written before it kept its robot), the base is the calibrated joint 1 frame and
    // revolute joints are written as continuous (the command's help says so).
    #[command(flatten)]
    robot: crate::robot_args::KeptRobotArgs,
    /// The training data (SPEC CSV): the error with and without what a URDF cannot hold. Required
    /// for a model with joint compliance or a GP.
    #[arg(long)]
    data: Option<PathBuf>,
    #[command(flatten)]
    json: JsonFlag,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    // Refused before any work: the URDF must not replace a file this export reads.
    measurements::InputFiles::new()
        .with("--model", &args.model.model)
        .with_optional("--like", args.like.as_deref())
        .with_optional("--robot", args.robot.robot.as_deref())
        .with_optional("--data", args.data.as_deref())
        .check_output("--urdf", &args.urdf)?;
    let model = args.model.read()?;
    let training = match &args.data {
        Some(path) => Some(measurements::read_measurements(path, &model.read_options(Default::default()))?),
        None => None,
    };
    let export = export(args, &model, training.as_ref())?;
    cell::write_urdf(&args.urdf, &export)?;
    let report = &export.report;
    if args.json.json {
        println!("{}", serde_json::to_string(report)?);
        return Ok(());
    }
    print_summary(args, report);
    Ok(())
}

/// The export, written like --like's URDF, else as a URDF of our own on the nominal description.
fn export(
    args: &Args,
    model: &model::CalibratedModel,
    training: Option<&measurements::MeasurementSet>,
) -> Result<cell::UrdfExport, Box<dyn std::error::Error>> {
    let tolerance = NominalTolerance::default();
    Ok(match &args.like {
        Some(like) => {
            let document = UrdfDocument::read(like)?;
            let chain = document.chain(&args.robot.ends())?;
            cell::export_urdf(model, UrdfTemplate::Like { document: &document, chain: &chain }, training, &tolerance)?
        }
        // --robot, else the robot the model keeps, as compensate and report take it.
        None => {
            let nominal = args.robot.read_or_kept(model, &args.model.model)?;
            let nominal = nominal.as_ref().map(|(description, file)| (description, file.as_str()));
            cell::export_urdf(model, UrdfTemplate::Plain { nominal }, training, &tolerance)?
        }
    })
}

/// What was written, for a reader.
fn print_summary(args: &Args, report: &cell::UrdfExportReport) {
    println!(
        "wrote {} ({}): base link {}, tracker link {}",
        args.urdf.display(),
        report.robot,
        report.base_link,
        report.tracker_link
    );
    println!("  base frame: {}", report.base_frame);
    println!(
        "  tool links: {}{}",
        report.tool_links.join(", "),
        if report.tool_orientation_calibrated {
            ""
        } else {
            " (position-only data: their orientation is not calibrated)"
        }
    );
    for change in &report.axis_changes {
        println!(
            "  {}: axis moved {:.3} mm, turned {:.3} mrad from the nominal",
            change.joint, change.offset_mm, change.angle_mrad
        );
    }
    if !report.not_in_urdf.is_empty() {
        println!("  not in the URDF: {}", report.not_in_urdf.join(", "));
    }
    if let Some(errors) = &report.training_error {
        println!(
            "  training error ({} rows): model mean {:.4} mm, max {:.4} mm; URDF geometry mean {:.4} mm, max {:.4} mm",
            errors.model.n,
            errors.model.mean_position_error_mm,
            errors.model.max_position_error_mm,
            errors.urdf.mean_position_error_mm,
            errors.urdf.max_position_error_mm
        );
        for part in &errors.without_each {
            println!("    without {}: mean {:.4} mm", part.part, part.error.mean_position_error_mm);
        }
    }
    let tip = report.tool_links.first().map_or("tool", String::as_str);
    println!("  read it back with: --robot {} --tip-link {tip}", args.urdf.display());
}
