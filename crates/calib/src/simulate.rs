//! `calib simulate`: a simulated tracker campaign written as SPEC measurement CSV, to try the other
//! subcommands without a robot, or to test a calibration on data whose truth is known.

use campaign::ErrorKind;
use campaign::{GeneratorConfig, Perturbation, Remount, TorqueSensorNoise};
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
    /// Effects (RON, loadsim's `Effects`: compliance, backlash, periodic, thermal, drift,
    /// deflection, screw, tracker_noise, coupling; a field left out is off) [default: joint compliance and tracker noise].
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
    let config = generator_config(args)?;
    // The generator draws poses where the tool point moves in all three directions: a planar
    // chain has none, and would be refused after a million draws as "too strict a threshold".
    if config.moving_joints.is_empty()
        && let Some(direction) = robot.planar_direction()
    {
        let file = args.robot.robot.display().to_string();
        return Err(Error::in_file(file, ErrorKind::PlanarChain { direction, joints: robot.joint_count() }).into());
    }
    let cell = campaign::campaign_cell(&robot, &Perturbation::default(), &Remount::default(), &config)?;
    // Each row is written as it is drawn (memory of one row, whatever --rows), into the atomic
    // output: a failure or a kill leaves the old file, never a part.
    let mut out = measurements::OutputFile::create(&args.out)?;
    let rows = campaign::simulate_to_csv(
        &cell,
        &effects,
        &campaign::joint_ranges(&robot),
        &config,
        args.full_pose,
        &mut out,
        &args.out.display().to_string(),
    )?;
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
    for line in shape_lines(&config) {
        println!("  {line}");
    }
    println!("  wrote {}", args.out.display());
    Ok(())
}

/// The generator's configuration from the command line.
fn generator_config(args: &Args) -> Result<GeneratorConfig, Box<dyn std::error::Error>> {
    let defaults = GeneratorConfig::default();
    let payloads_kg = args.payloads.clone().unwrap_or_else(|| defaults.payloads_kg.clone());
    let mut moving_joints = Vec::new();
    for &joint in args.moving_joints.iter().flatten() {
        if joint == 0 {
            return Err("--moving-joints: joints are numbered from 1".into());
        }
        moving_joints.push(joint - 1);
    }
    moving_joints.sort_unstable();
    moving_joints.dedup();
    if args.fixed_jitter_mrad.is_some() && moving_joints.is_empty() {
        return Err("--fixed-jitter-mrad needs --moving-joints (only joints that do not move are held)".into());
    }
    let jitter = args.fixed_jitter_mrad.unwrap_or(0.0);
    if !(jitter.is_finite() && jitter >= 0.0) {
        return Err(format!("--fixed-jitter-mrad: {jitter} is not a non-negative number").into());
    }
    if args.torque_sigma_nm.is_some() && !args.torques {
        return Err("--torque-sigma-nm needs --torques".into());
    }
    if let Some(sigma) = args.torque_sigma_nm.filter(|s| !(s.is_finite() && *s >= 0.0)) {
        return Err(format!("--torque-sigma-nm: {sigma} is not a non-negative number").into());
    }
    let torque_sensor = args.torques.then(|| match args.torque_sigma_nm {
        Some(sigma_nm) => TorqueSensorNoise { sigma_nm, ..TorqueSensorNoise::default() },
        None => TorqueSensorNoise::default(),
    });
    Ok(GeneratorConfig {
        sample_count: args.rows,
        seed: args.seed,
        payloads_kg,
        moving_joints,
        fixed_jitter_rad: jitter * 1e-3,
        payload_runs: args.runs || args.tool_per_payload,
        tool_per_run: args.tool_per_payload,
        torque_sensor,
        ..defaults
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
