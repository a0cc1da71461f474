//! `calib simulate`: a simulated tracker campaign written as SPEC measurement CSV, to try the other
//! subcommands without a robot, or to test a calibration on data whose truth is known.

use pipeline::Error;
use pipeline::simulated::{self, GeneratorConfig, Perturbation};
use std::path::PathBuf;

/// Simulate tracker measurements of a robot whose kinematics are off its nominal.
///
/// The true robot is the nominal one with every local frame (each joint and the tool) moved by up
/// to 1 mm and 1 mrad per component, a 0.2 m tool, seen by a tracker placed 3–5 m away; all of it
/// drawn from the seed.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    robot: crate::robot_args::RobotArgs,
    /// Where to write the measurements (SPEC CSV).
    #[arg(long)]
    out: PathBuf,
    /// Number of poses.
    #[arg(long, default_value_t = 300)]
    rows: usize,
    /// Seed of the true robot, the tracker placement, the poses, payloads and noise.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Measure the orientation too (a 6-DOF probe): writes qw, qx, qy, qz.
    #[arg(long)]
    full_pose: bool,
    /// Effects (RON, loadsim's `Effects`: compliance, backlash, periodic, thermal, drift,
    /// tracker_noise; a field left out is off) [default: joint compliance and tracker noise].
    #[arg(long)]
    effects: Option<PathBuf>,
    /// Payloads, kg, one drawn per pose [default: the paper's 1,2.5,3.5,5,7.5].
    #[arg(long, value_delimiter = ',')]
    payloads: Option<Vec<f64>>,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let robot = args.robot.read()?;
    let effects = match &args.effects {
        Some(path) => simulated::read_effects(path)?,
        None => simulated::paper_effects(),
    };
    if args.rows == 0 {
        return Err("--rows: at least one pose is needed".into());
    }
    let defaults = GeneratorConfig::default();
    let payloads_kg = args.payloads.clone().unwrap_or_else(|| defaults.payloads_kg.clone());
    let config = GeneratorConfig { sample_count: args.rows, seed: args.seed, payloads_kg, ..defaults };
    let cell = simulated::simulated_cell(&robot, &Perturbation::default(), args.seed)?;
    let data = simulated::simulate(&cell, &effects, &simulated::joint_ranges(&robot), &config, args.full_pose)?;

    let path = args.out.display().to_string();
    let io = |source: std::io::Error| Error::Io { path: path.clone(), source };
    let file = std::fs::File::create(&args.out).map_err(io)?;
    data.write_csv(std::io::BufWriter::new(file)).map_err(io)?;

    let on: Vec<&str> = effect_names(&effects);
    println!(
        "simulated {} poses of {} ({}), effects: {}, seed {}",
        data.rows.len(),
        robot.name,
        if args.full_pose { "full pose" } else { "position only" },
        if on.is_empty() { "none".to_owned() } else { on.join(", ") },
        args.seed
    );
    println!("  wrote {}", args.out.display());
    Ok(())
}

/// The names of the effects that are on, as the RON file spells them.
fn effect_names(effects: &simulated::Effects) -> Vec<&'static str> {
    [
        ("compliance", effects.compliance.is_some()),
        ("backlash", effects.backlash.is_some()),
        ("periodic", effects.periodic.is_some()),
        ("thermal", effects.thermal.is_some()),
        ("drift", effects.drift.is_some()),
        ("tracker_noise", effects.tracker_noise.is_some()),
    ]
    .into_iter()
    .filter_map(|(name, on)| on.then_some(name))
    .collect()
}
