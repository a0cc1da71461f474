//! `calib export`: the calibrated geometry as a URDF for controllers, planners and simulators.

use cell::UrdfTemplate;
use robot::{ChainEnds, NominalTolerance, RobotDescription, UrdfDocument};
use std::path::PathBuf;

/// Write a calibrated model's geometry as a URDF.
///
/// The URDF is in the robot's base frame (joint 1 where the nominal description puts it, as
/// calibrated), with a fixed `tracker` link at the tracker frame and a fixed link per calibrated
/// tool. What a URDF cannot hold (joint compliance, the GP) is reported with the error the model
/// makes without it on the training data (--data).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Calibrated model (RON, from `calib fit`).
    #[arg(long)]
    model: PathBuf,
    /// Where to write the URDF.
    #[arg(long)]
    urdf: PathBuf,
    /// Write into this URDF (of the robot the model was fitted with): its links, inertias, visuals
    /// and limits are kept, the movable joints' origins become the calibrated ones.
    #[arg(long, conflicts_with = "robot")]
    like: Option<PathBuf>,
    /// The nominal robot description the model was fitted with (RON or URDF): places the base
    /// frame and gives the limits [default: the --like URDF, else the description the model keeps;
    /// without any, the base is the calibrated joint 1 frame and revolute joints are written as
    /// continuous].
    #[arg(long)]
    robot: Option<PathBuf>,
    /// URDF only: the chain's base link in --like or --robot.
    #[arg(long)]
    base_link: Option<String>,
    /// URDF only: the chain's tip link in --like or --robot.
    #[arg(long)]
    tip_link: Option<String>,
    /// The training data (SPEC CSV): the error with and without what a URDF cannot hold. Required
    /// for a model with joint compliance or a GP.
    #[arg(long)]
    data: Option<PathBuf>,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    // Refused before any work: the URDF must not replace a file this export reads.
    measurements::InputFiles::new()
        .with("--model", &args.model)
        .with_optional("--like", args.like.as_deref())
        .with_optional("--robot", args.robot.as_deref())
        .with_optional("--data", args.data.as_deref())
        .check_output("--urdf", &args.urdf)?;
    let model = model::read_model(&args.model)?;
    let ends = ChainEnds { base_link: args.base_link.clone(), tip_link: args.tip_link.clone() };
    let training = match &args.data {
        Some(path) => Some(measurements::read_measurements(path, &model.read_options(Default::default()))?),
        None => None,
    };
    let tolerance = NominalTolerance::default();
    let export = match (&args.like, &args.robot) {
        (Some(like), _) => {
            let document = UrdfDocument::read(like)?;
            let chain = document.chain(&ends)?;
            cell::export_urdf(
                &model,
                UrdfTemplate::Like { document: &document, chain: &chain },
                training.as_ref(),
                &tolerance,
            )?
        }
        (None, Some(robot)) => {
            let description = RobotDescription::read_with(robot, &ends)?;
            let file = robot.display().to_string();
            let template = UrdfTemplate::Plain { nominal: Some((&description, &file)) };
            cell::export_urdf(&model, template, training.as_ref(), &tolerance)?
        }
        (None, None) => {
            if ends != ChainEnds::default() {
                return Err(
                    "--base-link and --tip-link choose the chain of --like or --robot, and neither is given".into()
                );
            }
            let kept = model.robot_description.clone();
            let file = format!("{} (as the model keeps it)", args.model.display());
            let nominal = kept.as_ref().map(|description| (description, file.as_str()));
            cell::export_urdf(&model, UrdfTemplate::Plain { nominal }, training.as_ref(), &tolerance)?
        }
    };
    cell::write_urdf(&args.urdf, &export)?;
    let report = &export.report;
    if args.json {
        println!("{}", serde_json::to_string(report)?);
        return Ok(());
    }
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
    Ok(())
}
