//! `calib fit`: fit a calibration method to measurements and write the model.

use pipeline::effects::{EffectSelection, EffectSpec};
use pipeline::{ErrorSummary, FitOptions, Method, ReadOptions};
use std::path::PathBuf;

/// Fit a calibrated model to measurements.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    robot: crate::robot_args::RobotArgs,
    /// Measurements (SPEC CSV; `;` and decimal commas are detected).
    #[arg(long)]
    data: PathBuf,
    /// Other headers mapped onto the SPEC's column names: NAME=HEADER,… (e.g. x_mm="X [mm]",qw=Q0).
    #[arg(long)]
    columns: Option<pipeline::ColumnMap>,
    /// Calibration method: base-tool, poe, poe-gp or poe-gp-load.
    #[arg(long)]
    method: Method,
    /// Where to write the calibrated model (RON).
    #[arg(long)]
    out: PathBuf,
    /// Non-geometric effects identified with the geometry, applied before any GP (beyond the
    /// paper): a comma-separated list of joint_compliance, gear_periodic:JOINT:HARMONICS,
    /// backlash:JOINT, thermal, time_drift; or auto, what `calib diagnose` selects on the data.
    #[arg(long, value_name = "LIST|auto")]
    effects: Option<EffectSelection>,
    /// The same as --effects joint_compliance: joint compliance through measured torques
    /// (tauN_nm) where the data has them, gravity-torque regressors otherwise (no masses needed).
    #[arg(long, conflicts_with = "effects")]
    joint_compliance: bool,
    /// Fit options (RON): any field of pipeline's FitOptions, e.g. (identification: (max_iterations:
    /// 100), effects: (prior_sigma: 1e-3)); --effects given here too is overridden by the flag.
    #[arg(long, value_name = "FIT.ron")]
    options: Option<PathBuf>,
    /// The GP of the -gp methods: exact, sparse (variational, inducing inputs: for large data
    /// sets) or auto (sparse above 4000 training rows) [default: auto, or what --options says].
    #[arg(long)]
    gp: Option<pipeline::GpChoice>,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let robot = args.robot.read()?;
    let options = ReadOptions::for_joints(robot.joint_kinds()).with_columns(args.columns.clone().unwrap_or_default());
    let data = pipeline::read_measurements(&args.data, &options)?;
    println!("{}", data.read_summary());
    let mut options = match &args.options {
        Some(path) => FitOptions::read(path)?,
        None => FitOptions::default(),
    };
    match (&args.effects, args.joint_compliance) {
        (Some(selection), _) => options.effects.selection = selection.clone(),
        (None, true) => options.effects.selection = EffectSelection::List(vec![EffectSpec::JointCompliance]),
        (None, false) => {}
    }
    if let Some(choice) = args.gp {
        options.compensation.method = choice;
    }
    let (model, report) = pipeline::fit(&robot, &data, args.method, &options)?;
    pipeline::write_model(&args.out, &model)?;

    let kind = if data.full_pose { "full pose" } else { "position only" };
    let tools = data.tools.iter().filter(|t| !t.is_empty()).count().max(1);
    println!(
        "{} on {} ({} rows, {kind}, {tools} tool{}) for {}",
        args.method,
        args.data.display(),
        data.rows.len(),
        if tools == 1 { "" } else { "s" },
        robot.name
    );
    print_errors("training error before (nominal, registered)", &report.before);
    print_errors("training error after", &report.after);
    let id = &report.identification;
    println!(
        "  identifiable: {} of {} free parameters, condition number {:.3e}",
        id.rank, id.free_parameters, id.condition_number
    );
    if let Some(auto) = &report.auto {
        let chosen: Vec<String> = auto.chosen.iter().map(ToString::to_string).collect();
        println!(
            "  effects auto: the diagnosis of the training data (held-out {:.4} mm with the geometry alone) selected {}",
            auto.heldout_before_mm,
            if auto.selected.is_empty() { "nothing".to_owned() } else { chosen.join(", ") }
        );
        for s in &auto.selected {
            let joints: Vec<String> = s.joints.iter().map(ToString::to_string).collect();
            let harmonic = s.harmonic.map_or(String::new(), |h| format!(" harmonic {h}"));
            println!(
                "    {} on joint(s) {}{harmonic}: held-out {:.4} mm (paired t = {:.1})",
                s.effect.name(),
                joints.join(","),
                s.heldout_after_mm,
                s.t
            );
        }
    }
    for effect in &model.effects {
        println!("  effect {}: {} parameters identified with the geometry", effect.label(), effect.parameter_count());
    }
    if let Some(compensation) = &model.compensation {
        println!("  GP: {}", compensation.gp.choice());
    }
    for direction in &id.unidentifiable {
        println!("    unidentifiable: {direction}");
    }
    println!("  iterations: {} ({})", id.iteration_count(), id.termination);
    println!("  wrote {}", args.out.display());
    Ok(())
}

fn print_errors(label: &str, summary: &ErrorSummary) {
    print!(
        "  {label}: mean {:.4} mm, rms {:.4} mm, max {:.4} mm",
        summary.mean_position_error_mm, summary.rms_position_error_mm, summary.max_position_error_mm
    );
    match summary.mean_rotation_error_mrad {
        Some(rotation) => println!(", rotation mean {rotation:.4} mrad"),
        None => println!(),
    }
}
