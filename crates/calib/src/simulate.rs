//! `calib simulate`: a simulated tracker campaign written as SPEC measurement CSV, to try the other
//! subcommands without a robot, or to test a calibration on data whose truth is known.

use calib::flow::{CampaignShape, ShapeFault};
use campaign::ErrorKind;
use campaign::GeneratorConfig;
use errors::Error;
use std::path::PathBuf;

/// Simulate tracker measurements of a robot whose kinematics are off its nominal.
///
/// The true robot is the nominal one with every local frame (each joint and the tool) moved by up
/// to 1 mm and 1 mrad per component, a 0.2 m tool, seen by a tracker placed 3–5 m away; all of it
/// drawn from the seed.
///
/// Campaign shapes: `--moving-joints 1,2 --fixed-jitter-mrad 2` moves only joints 1 and 2 (the
/// others at 0 within 2 mrad); `--runs` measures the payloads in consecutive runs, in the order
/// given; `--tool-per-payload` also remounts the probe for each run (a different tool transform,
/// up to 2 mm and 2 mrad per component off the first; a `tool` column); `--torques` writes the
/// measured joint torques `tau1_nm … tauN_nm` (the drive torques holding gravity, payload and
/// balancer, with sensor noise).
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    robot: crate::robot_args::RobotArgs,
    /// Where to write the measurements (SPEC CSV).
    #[arg(long)]
    out: PathBuf,
    /// Number of poses (at most 1,000,000, ~280 MB; rows are written as they are drawn).
    #[arg(long, default_value_t = 300)]
    rows: usize,
    /// Seed of the true robot, the tracker placement, the poses, payloads and noise.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Measure the orientation too (a 6-DOF probe): writes qw, qx, qy, qz.
    #[arg(long)]
    full_pose: bool,
    /// Effects (RON, loadsim's `Effects`: joint_compliance, backlash, gear_periodic, thermal,
    /// time_drift, link_deflection, screw_periodic, tracker_noise, coupling, the `--effects` names of
    /// `calib fit`; a field left out is off) [default: joint compliance and tracker noise].
    #[arg(long)]
    effects: Option<PathBuf>,
    /// Payloads, kg, one drawn per pose [default: the paper's 1,2.5,3.5,5,7.5].
    #[arg(long, value_delimiter = ',')]
    payloads: Option<Vec<f64>>,
    /// Only these joints move (1-based, comma separated); the others sit at 0.
    #[arg(long, value_delimiter = ',')]
    moving_joints: Option<Vec<usize>>,
    /// Joints that do not move are drawn within ± this of 0, mrad (with --moving-joints) [default: 0].
    #[arg(long)]
    fixed_jitter_mrad: Option<f64>,
    /// Payload runs: the poses split into consecutive runs, one per payload in the order given.
    #[arg(long)]
    runs: bool,
    /// One run per payload with the probe remounted for each: a tool per run (implies --runs).
    #[arg(long)]
    tool_per_payload: bool,
    /// Write measured joint torques (needs the robot's dynamics block).
    #[arg(long)]
    torques: bool,
    /// Standard deviation of the measured torques, N·m (with --torques) [default: 0.5, loadsim's
    /// TorqueSensorNoise].
    #[arg(long)]
    torque_sigma_nm: Option<f64>,
    /// A later day of the same campaign: the same true robot, the tracker re-sighted (up to 5 mm
    /// and 5 mrad per component off the first day's placement), the clock this many days on, the
    /// poses and noise of a seed of the day's own [default: 0, the first day].
    #[arg(long, default_value_t = 0)]
    day: u64,
    /// The cell's temperature at the campaign's start, °C (it then warms by 3 °C with a 2 h time
    /// constant, loadsim's `TemperatureProfile`; on a later day it has warmed) [default: 20].
    #[arg(long)]
    temp_c: Option<f64>,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    // Refused before any work: the measurements must not replace the robot or the effects file.
    measurements::InputFiles::new()
        .with("--robot", &args.robot.robot)
        .with_optional("--effects", args.effects.as_deref())
        .check_output("--out", &args.out)?;
    if args.rows > campaign::MAX_ROWS {
        return Err(format!(
            "--rows: {}",
            Error::new(ErrorKind::TooManySimulatedRows { rows: args.rows, max: campaign::MAX_ROWS })
        )
        .into());
    }
    let robot = args.robot.read()?;
    let effects = match &args.effects {
        Some(path) => campaign::read_effects(path, &robot)?,
        None => campaign::paper_effects(),
    };
    if args.rows == 0 {
        return Err("--rows: at least one pose is needed".into());
    }
    let mut config = generator_config(args)?;
    if let Some(temp_c) = args.temp_c {
        if !(temp_c.is_finite() && temp_c.abs() <= campaign::MAX_TEMPERATURE_C) {
            return Err(format!(
                "--temp-c: {temp_c} is not a temperature (°C, within ±{})",
                campaign::MAX_TEMPERATURE_C
            )
            .into());
        }
        config.temperature.start_c = temp_c;
    }
    let day = campaign::Day { index: args.day, ..campaign::Day::default() };
    // Each row is written as it is drawn (memory of one row, whatever --rows), into the atomic
    // output: a failure or a kill leaves the old file, never a part.
    let mut out = measurements::OutputFile::create(&args.out)?;
    let robot_file = args.robot.robot.display().to_string();
    let out_name = args.out.display().to_string();
    let rows =
        calib::flow::simulate_day(&robot, &robot_file, &effects, &config, &day, args.full_pose, &mut out, &out_name)?;
    out.finish()?;

    let on: Vec<&str> = effect_names(&effects);
    println!(
        "simulated {} poses of {} ({}), effects: {}, seed {}",
        rows,
        robot.name,
        if args.full_pose { "full pose" } else { "position only" },
        if on.is_empty() { "none".to_owned() } else { on.join(", ") },
        args.seed
    );
    if args.day > 0 {
        println!("  day {} of the campaign: the tracker re-sighted, the clock {} days on", args.day, args.day);
    }
    if let Some(temp_c) = args.temp_c {
        println!("  the cell at {temp_c} °C at the campaign's start");
    }
    for line in shape_lines(&config) {
        println!("  {line}");
    }
    println!("  wrote {}", args.out.display());
    Ok(())
}

/// The generator's configuration from the command line.
fn generator_config(args: &Args) -> Result<GeneratorConfig, String> {
    let shape = CampaignShape {
        payloads: args.payloads.clone(),
        moving_joints: args.moving_joints.clone(),
        fixed_jitter_mrad: args.fixed_jitter_mrad,
        runs: args.runs,
        tool_per_payload: args.tool_per_payload,
        torques: args.torques,
        torque_sigma_nm: args.torque_sigma_nm,
    };
    shape.config(args.rows, args.seed).map_err(|fault| match fault {
        ShapeFault::JointZero => "--moving-joints: joints are numbered from 1".to_owned(),
        ShapeFault::JitterWithoutMovingJoints => {
            "--fixed-jitter-mrad needs --moving-joints (only joints that do not move are held)".to_owned()
        }
        ShapeFault::Jitter(jitter) => format!("--fixed-jitter-mrad: {jitter} is not a non-negative number"),
        ShapeFault::SigmaWithoutTorques => "--torque-sigma-nm needs --torques".to_owned(),
        ShapeFault::Sigma(sigma) => format!("--torque-sigma-nm: {sigma} is not a non-negative number"),
    })
}

/// What the campaign's shape is, in words, where it is not the default.
fn shape_lines(config: &GeneratorConfig) -> Vec<String> {
    let mut lines = Vec::new();
    if !config.moving_joints.is_empty() {
        let joints: Vec<String> = config.moving_joints.iter().map(|j| (j + 1).to_string()).collect();
        lines.push(format!(
            "moving joints {}, the others at 0 within {} mrad",
            joints.join(","),
            config.fixed_jitter_rad * 1e3
        ));
    }
    if config.runs() {
        let kg: Vec<String> = config.payloads_kg.iter().map(|m| format!("{m} kg")).collect();
        let tools = if config.tool_per_run { ", the probe remounted for each (one tool per run)" } else { "" };
        lines.push(format!("payload runs: {}{tools}", kg.join(", ")));
    }
    if let Some(sensor) = &config.torque_sensor {
        lines.push(format!("measured torques, sensor noise {} N·m", sensor.sigma_nm));
    }
    lines
}

/// The names of the effects that are on, as the RON file spells them.
fn effect_names(effects: &campaign::Effects) -> Vec<&'static str> {
    campaign::EffectKind::ALL
        .iter()
        .filter(|&&kind| effects.is_on(kind))
        .filter_map(|kind| kind.simulated_field())
        .collect()
}
