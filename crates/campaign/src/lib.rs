//! Simulated tracker campaigns, shared by `calib simulate`, the experiments of `cargo xtask` and
//! tests: a "true" robot made by perturbing the nominal one, a tracker placed in the cell, and the
//! samples of [`loadsim::generate`] as a [`MeasurementSet`].
//!
//! Campaign shapes beyond random poses (all set in [`GeneratorConfig`]): only some joints moving
//! (`moving_joints`, the others at `fixed_at_rad` within `fixed_jitter_rad`), payload runs
//! (`payload_runs`: one consecutive run per payload), one tool per run (`tool_per_run`: the probe
//! remounted between runs, see [`Remount`] and [`campaign_cell`]; the rows carry a `tool`), and
//! measured joint torques (`torque_sensor`; the rows carry `torques_nm`, the drive torques
//! `−τ_static` plus noise, see [`TorqueSensorNoise`]). [`payload_run_campaign`] is the shape of
//! a real 7-axis campaign; [`simulate_campaign`] draws cell and data in one call:
//!
//! ```
//! # let fixture = |name: &str| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name);
//! use robot::RobotDescription;
//! use campaign::{Perturbation, Remount, paper_effects, payload_run_campaign, simulate_campaign};
//!
//! let robot = RobotDescription::read(&fixture("iiwa7.ron")).unwrap();
//! let config = payload_run_campaign(300, 1);
//! let (cell, data) =
//!     simulate_campaign(&robot, &paper_effects(), &Perturbation::default(), &Remount::default(), &config, true)
//!         .unwrap();
//! assert_eq!(data.tools.len(), 4); // one tool per payload run
//! assert!(data.rows.iter().all(|r| r.torques_nm.is_some() && r.q[2].abs() <= 2e-3));
//! assert_eq!(cell.robot.tool_count(), 4);
//! ```
//!
//! The loadsim types a caller needs to configure a campaign are re-exported here, so that the
//! `calib` binary depends on this crate alone.
#![deny(missing_docs)]

mod effects_file;
mod error_kind;

use errors::Error;
use lie::{SE3, SO3, Twist, Vector3};
use measurements::{Measurement, MeasurementSet};
use poe::LocalPoe;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot::RobotDescription;
use serde::{Deserialize, Serialize};

pub use effects_file::{
    MAX_DRIFT_PER_S, MAX_EXPANSION_PER_K, MAX_FIXED_POINT_ITERATIONS, MAX_JOINT_ERROR_RAD, MAX_NOISE, MAX_ORDER,
    MAX_SCREW_ERROR_M, MAX_TEMPERATURE_C, check_effects, parse_effects, read_effects,
};
pub use error_kind::ErrorKind;
pub use loadsim::{
    CouplingFactor, CouplingModel, CouplingTerm, EffectKind, Effects, GeneratorConfig, JointComplianceModel,
    JointRange, Sample, SimulatedCell, TorqueSensorNoise, TrackerNoiseModel,
};

/// How far the true robot is from its nominal model: every constant transform of the local POE
/// model (one per joint, and the tool) is moved by `exp(ξ̂)` with each component of `ξ = (v, ω)`
/// uniform in ±`translation_m`, ±`rotation_rad`; the tool sits `tool_m` out along the flange's z.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Perturbation {
    /// Largest offset of each translation component, m.
    pub translation_m: f64,
    /// Largest offset of each rotation-vector component, rad.
    pub rotation_rad: f64,
    /// Nominal tool length along the flange's z axis, m.
    pub tool_m: f64,
}

impl Default for Perturbation {
    /// 1 mm and 1 mrad per component, a 0.2 m tool. Machining and assembly tolerances of a
    /// 1-tonne arm's castings leave link lengths and axis alignments off by tenths of a millimetre
    /// to a millimetre and by tenths of a milliradian to a milliradian; an uncalibrated arm of this
    /// size then misses by one to a few millimetres, the range tracker studies report before
    /// calibration (e.g. Nubiola & Bonev 2013, ABB IRB 1600: 0.97 mm mean, 2.2 mm max).
    fn default() -> Self {
        Self { translation_m: 1e-3, rotation_rad: 1e-3, tool_m: 0.2 }
    }
}

/// A random twist with translation and rotation components uniform in ±`translation`, ±`rotation`.
pub fn random_twist<R: Rng + ?Sized>(rng: &mut R, translation: f64, rotation: f64) -> Twist {
    let mut v = || Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    let (a, b) = (v(), v());
    Twist::new(a * translation, b * rotation)
}

/// The nominal arm of `robot` perturbed as `perturbation` says: joints in order, then the tool.
pub fn perturbed_robot<R: Rng + ?Sized>(
    robot: &RobotDescription,
    perturbation: &Perturbation,
    rng: &mut R,
) -> Result<LocalPoe, Error> {
    let Perturbation { translation_m, rotation_rad, tool_m } = *perturbation;
    let mut model = robot.nominal_model()?;
    for joint in model.joints_mut() {
        joint.previous_from_joint_zero =
            random_twist(rng, translation_m, rotation_rad).exp() * joint.previous_from_joint_zero;
    }
    let tool = model.tools()[0] * SE3::from_translation(Vector3::new(0.0, 0.0, tool_m));
    model.set_tools(vec![random_twist(rng, translation_m, rotation_rad).exp() * tool]);
    Ok(model)
}

/// `tracker_from_base` for a tracker 3–5 m from the base on a random bearing, within ±0.5 m of
/// the base's height, turned about the vertical and levelled (as a tracker stands on its tripod).
pub fn tracker_placement<R: Rng + ?Sized>(rng: &mut R) -> SE3 {
    let distance = rng.random_range(3.0..5.0);
    let bearing: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let turn = SO3::exp(&Vector3::new(0.0, 0.0, rng.random_range(-3.1..3.1)));
    let tracker_in_base = Vector3::new(distance * bearing.cos(), distance * bearing.sin(), rng.random_range(-0.5..0.5));
    SE3::new(turn, tracker_in_base).inverse()
}

/// The ChaCha8 stream of a seed that [`simulated_cell`] draws from: loadsim's generator uses
/// streams 0–2, so one seed can give both the cell and its dataset without shared draws.
const CELL_STREAM: u64 = 3;

/// A cell for `robot` drawn from `seed`: the perturbed arm (with the robot file's masses and
/// stiffness), then the tracker placement, from one ChaCha8 stream ([`CELL_STREAM`]).
pub fn simulated_cell(
    robot: &RobotDescription,
    perturbation: &Perturbation,
    seed: u64,
) -> Result<SimulatedCell, Error> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(CELL_STREAM);
    let geometry = perturbed_robot(robot, perturbation, &mut rng)?;
    let mut cell = SimulatedCell::new(geometry, robot.dynamics.clone());
    cell.tracker_from_base = tracker_placement(&mut rng);
    Ok(cell)
}

/// How far the probe moves when it is taken off the flange and mounted again between payload
/// runs: each remounted tool is the first one moved by `exp(ξ̂)`, each component of `ξ = (v, ω)`
/// uniform in ±`translation_m`, ±`rotation_rad`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Remount {
    /// Largest offset of each translation component, m.
    pub translation_m: f64,
    /// Largest offset of each rotation-vector component, rad.
    pub rotation_rad: f64,
}

impl Default for Remount {
    /// 2 mm and 2 mrad per component: a probe re-clamped on the flange rather than dropped into a
    /// kinematic nest (which repeats to micrometres). ENGINEERING ESTIMATE; what matters is that
    /// each run's tool differs by more than the tracker noise, as it does on a real campaign.
    fn default() -> Self {
        Self { translation_m: 2e-3, rotation_rad: 2e-3 }
    }
}

/// The ChaCha8 stream of a seed that [`campaign_cell`] draws the remounted tools from (loadsim's
/// generator uses 0–2 and 4, [`simulated_cell`] 3).
const REMOUNT_STREAM: u64 = 5;

/// The cell for a campaign drawn with `config`: [`simulated_cell`] from `config.seed`, and with
/// `config.tool_per_run` one tool per payload run, the first as drawn and each further one that
/// tool remounted ([`Remount`], from its own stream of the seed).
pub fn campaign_cell(
    robot: &RobotDescription,
    perturbation: &Perturbation,
    remount: &Remount,
    config: &GeneratorConfig,
) -> Result<SimulatedCell, Error> {
    let mut cell = simulated_cell(robot, perturbation, config.seed)?;
    if config.tool_per_run {
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        rng.set_stream(REMOUNT_STREAM);
        let first = cell.robot.tools()[cell.tool];
        let mut tools = vec![first];
        for _ in 1..config.payloads_kg.len() {
            tools.push(random_twist(&mut rng, remount.translation_m, remount.rotation_rad).exp() * first);
        }
        cell.robot.set_tools(tools);
        cell.tool = 0;
    }
    Ok(cell)
}

/// A later measuring day of a campaign's cell: the same true robot, the tracker set up again (the
/// base placement moved by `exp(ξ̂)`, each component of `ξ = (v, ω)` uniform in
/// ±`resight_translation_m`, ±`resight_rotation_rad`), the clock `index` days on, and the poses,
/// payloads and noise of a seed of the day's own. Day 0 is the campaign as drawn.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Day {
    /// Days after the first.
    pub index: u64,
    /// Largest offset of each translation component of the re-sighted placement, m.
    pub resight_translation_m: f64,
    /// Largest offset of each rotation-vector component of the re-sighted placement, rad.
    pub resight_rotation_rad: f64,
}

impl Default for Day {
    /// The first day; a tracker set up again on its tripod in the same corner of the cell lands
    /// millimetres and milliradians from where it stood: 5 mm and 5 mrad per component.
    /// ENGINEERING ESTIMATE; what matters is that each day's placement differs by far more than
    /// the noise, so that a model carried to it has to be registered there first.
    fn default() -> Self {
        Self { index: 0, resight_translation_m: 5e-3, resight_rotation_rad: 5e-3 }
    }
}

/// Seconds in a day, the clock's step from one [`Day`] to the next.
pub const DAY_S: f64 = 86_400.0;

/// The first ChaCha8 stream of a seed that [`Day::of`] draws from (one stream per day, far above
/// the generator's and the cell's).
const DAY_STREAM: u64 = 1 << 32;

impl Day {
    /// The cell and the generator's configuration of this day of the campaign `config` draws on
    /// `cell` (its seed, which drew the cell, also draws each day's placement and seed).
    pub fn of(&self, cell: &SimulatedCell, config: &GeneratorConfig) -> (SimulatedCell, GeneratorConfig) {
        if self.index == 0 {
            return (cell.clone(), config.clone());
        }
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        rng.set_stream(DAY_STREAM.wrapping_add(self.index));
        let resight = random_twist(&mut rng, self.resight_translation_m, self.resight_rotation_rad).exp();
        let day_cell = SimulatedCell { tracker_from_base: resight * cell.tracker_from_base, ..cell.clone() };
        let day_config = GeneratorConfig {
            seed: rng.random(),
            start_time_s: config.start_time_s + self.index as f64 * DAY_S,
            ..config.clone()
        };
        (day_cell, day_config)
    }
}

/// A campaign in one call: [`campaign_cell`], then [`simulate`] on the robot's joint ranges.
pub fn simulate_campaign(
    robot: &RobotDescription,
    effects: &Effects,
    perturbation: &Perturbation,
    remount: &Remount,
    config: &GeneratorConfig,
    full_pose: bool,
) -> Result<(SimulatedCell, MeasurementSet), Error> {
    let cell = campaign_cell(robot, perturbation, remount, config)?;
    let data = simulate(&cell, effects, &joint_ranges(robot), config, full_pose)?;
    Ok((cell, data))
}

/// The shape of a real 7-axis campaign: joints 1 and 2 moving, the others at 0 within
/// 2 mrad, four consecutive runs with 0, 1.25, 2.5 and 5 kg, the probe remounted for each (one
/// tool per run), measured joint torques with the default sensor noise.
pub fn payload_run_campaign(sample_count: usize, seed: u64) -> GeneratorConfig {
    GeneratorConfig {
        sample_count,
        seed,
        moving_joints: vec![0, 1],
        fixed_jitter_rad: 2e-3,
        payloads_kg: vec![0.0, 1.25, 2.5, 5.0],
        payload_runs: true,
        tool_per_run: true,
        torque_sensor: Some(TorqueSensorNoise::default()),
        ..GeneratorConfig::default()
    }
}

/// The robot's joint ranges as the generator takes them. A joint without limits (a URDF's
/// continuous joint) is sampled over one turn, ±π, which reaches every pose it can take.
pub fn joint_ranges(robot: &RobotDescription) -> Vec<JointRange> {
    let bounded = |limit: f64, turn: f64| if limit.is_finite() { limit } else { turn };
    robot
        .limits()
        .into_iter()
        .map(|(lower, upper)| JointRange {
            lower_rad: bounded(lower, -std::f64::consts::PI),
            upper_rad: bounded(upper, std::f64::consts::PI),
        })
        .collect()
}

/// The effects of the paper's simulation (Section IV-A): the load model of its ref. \[15\] (joint
/// compliance under the arm's weight and the payload) and tracker noise (Leica AT901 with T-Mac).
pub fn paper_effects() -> Effects {
    Effects {
        joint_compliance: Some(JointComplianceModel::default()),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    }
}

/// Simulated samples as a measurement set named `source` (lines numbered as in a CSV written
/// from it; position only unless `full_pose`). Samples measured with more than one of the cell's
/// tools get a tool each, named `tool1`, `tool2`, … after the cell's tool index; with one tool
/// the set has the default (unnamed) tool. Measured torques are carried over.
pub fn measurement_set(source: &str, samples: Vec<Sample>, full_pose: bool) -> MeasurementSet {
    let mut used: Vec<usize> = samples.iter().map(|s| s.tool).collect();
    used.sort_unstable();
    used.dedup();
    let named = used.len() > 1;
    let rows = samples.into_iter().enumerate().map(|(i, s)| measurement(i, s, &used, full_pose)).collect();
    let tools = if named { used.iter().map(|t| format!("tool{}", t + 1)).collect() } else { vec![] };
    MeasurementSet::from_rows(source, rows, tools)
}

/// Sample `i` as the row at line `i + 2`, its tool the index in `used` where more than one is.
fn measurement(i: usize, s: Sample, used: &[usize], full_pose: bool) -> Measurement {
    Measurement {
        line: i as u64 + 2,
        q: s.q,
        position: s.tracker_from_tool.translation(),
        orientation: full_pose.then(|| s.tracker_from_tool.rotation()),
        payload_kg: s.payload_kg,
        tool: if used.len() > 1 { used.binary_search(&s.tool).unwrap_or(0) } else { 0 },
        temp_c: Some(s.temp_c),
        t_s: Some(s.t_s),
        torques_nm: s.torques_nm,
        inputs: measurements::Inputs::default(),
        std: None,
    }
}

/// The most rows [`simulate`] makes and [`simulate_to_csv`] writes. The writer streams (a row at a
/// time, ~280 bytes of CSV each with the orientation), so the bound is the time and the disk, not
/// memory (242,000 full-pose rows, 66 MB, peak 6.6 MB resident where the whole set held 114 MB): a
/// million rows is 25 s and 190–280 MB; that is a hundred times the sparse GP's largest
/// benchmark and a thousand times a tracker campaign, and a mistyped count is refused at once.
pub const MAX_ROWS: usize = 1_000_000;

/// A simulated dataset: [`loadsim::generate`] then [`measurement_set`]; more than [`MAX_ROWS`]
/// rows are refused.
pub fn simulate(
    cell: &SimulatedCell,
    effects: &Effects,
    ranges: &[JointRange],
    config: &GeneratorConfig,
    full_pose: bool,
) -> Result<MeasurementSet, Error> {
    if config.sample_count > MAX_ROWS {
        return Err(Error::new(ErrorKind::TooManySimulatedRows { rows: config.sample_count, max: MAX_ROWS }));
    }
    let samples = loadsim::generate(cell, effects, ranges, config).map_err(Error::load)?;
    if let Some(row) = samples.iter().position(|s| !finite(s)) {
        return Err(Error::new(ErrorKind::NonFiniteSimulation { row: row + 1 }));
    }
    Ok(measurement_set("simulated", samples, full_pose))
}

/// Whether a sample is finite everywhere (an effect or a robot out of any real range can
/// overflow): never a data set with a NaN in it.
fn finite(s: &Sample) -> bool {
    let pose = s.tracker_from_tool;
    pose.translation().iter().chain(pose.rotation().matrix().iter()).all(|v| v.is_finite())
        && s.q.iter().chain(s.torques_nm.iter().flatten()).all(|v| v.is_finite())
}

/// [`simulate`] written to `writer` as SPEC CSV while it is drawn, each row as it comes: memory
/// stays that of one row whatever `config.sample_count` (at most [`MAX_ROWS`]). The same rows,
/// bit for bit, as [`simulate`] followed by [`MeasurementSet::write_csv`]. Returns the row count.
pub fn simulate_to_csv<W: std::io::Write>(
    cell: &SimulatedCell,
    effects: &Effects,
    ranges: &[JointRange],
    config: &GeneratorConfig,
    full_pose: bool,
    writer: W,
    path: &str,
) -> Result<usize, Error> {
    if config.sample_count > MAX_ROWS {
        return Err(Error::new(ErrorKind::TooManySimulatedRows { rows: config.sample_count, max: MAX_ROWS }));
    }
    // The tools the rows will use, known before the first row: with `tool_per_run` the runs
    // that have a row (`run_of(i) = i·runs/n`: all of them once n ≥ runs), else the cell's.
    let (n, runs) = (config.sample_count, config.payloads_kg.len());
    let used: Vec<usize> = match config.tool_per_run {
        true if n >= runs => (0..runs).collect(),
        true => (0..n).map(|i| config.run_of(i)).collect(),
        false => vec![cell.tool],
    };
    let columns = measurements::CsvColumns {
        joint_kinds: cell.robot.joints().iter().map(|j| j.kind).collect(),
        full_pose,
        tools: if used.len() > 1 { used.iter().map(|t| format!("tool{}", t + 1)).collect() } else { vec![] },
        temp_c: true,
        t_s: true,
        torques: if config.torque_sensor.is_some() { cell.robot.joint_count() } else { 0 },
        inputs: Vec::new(),
        stated_std: [false; 2],
    };
    let io = |source: std::io::Error| Error::io(path.to_owned(), source);
    let mut out = measurements::MeasurementWriter::new(writer, columns).map_err(io)?;
    let mut written = 0;
    loadsim::generate_each(cell, effects, ranges, config, |sample| {
        if !finite(&sample) {
            return Err(Written(Error::new(ErrorKind::NonFiniteSimulation { row: written + 1 })));
        }
        out.write_row(&measurement(written, sample, &used, full_pose)).map_err(|e| Written(io(e)))?;
        written += 1;
        Ok(())
    })
    .map_err(|Written(e)| e)?;
    out.finish().map_err(io)?;
    Ok(written)
}

/// The error of a simulated set being written, as `loadsim::generate_each` wants it (one its
/// own errors convert into; `errors` knows no `loadsim`).
struct Written(Error);

impl From<loadsim::Error> for Written {
    fn from(e: loadsim::Error) -> Self {
        Written(Error::load(e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_seeded_cell_is_reproducible_and_off_nominal_by_the_perturbation() {
        let robot = testkit::robot("irb4400.ron");
        let perturbation = Perturbation::default();
        let a = simulated_cell(&robot, &perturbation, 7).unwrap();
        assert_eq!(a, simulated_cell(&robot, &perturbation, 7).unwrap());
        assert_ne!(a, simulated_cell(&robot, &perturbation, 8).unwrap());
        let nominal = robot.nominal_model().unwrap();
        for (true_joint, nominal_joint) in a.robot.joints().iter().zip(nominal.joints()) {
            let offset = (true_joint.previous_from_joint_zero * nominal_joint.previous_from_joint_zero.inverse()).log();
            let v = offset.to_vector();
            assert!(v.iter().all(|c| c.abs() <= 1.8e-3), "{v:?}");
        }
        let distance = a.tracker_from_base.inverse().translation().norm();
        assert!((3.0..5.1).contains(&distance), "{distance}");
    }

    #[test]
    fn a_later_day_is_the_same_robot_re_sighted_a_day_on_with_draws_of_its_own() {
        let robot = testkit::robot("irb4400.ron");
        let config = GeneratorConfig { sample_count: 5, seed: 9, ..GeneratorConfig::default() };
        let cell = simulated_cell(&robot, &Perturbation::default(), config.seed).unwrap();
        assert_eq!(Day::default().of(&cell, &config), (cell.clone(), config.clone()));
        let day = |index| Day { index, ..Day::default() }.of(&cell, &config);
        let (one, one_config) = day(1);
        assert_eq!((one.robot.clone(), one.tool), (cell.robot.clone(), cell.tool));
        assert_eq!(one_config.start_time_s, DAY_S);
        assert_ne!(one_config.seed, config.seed);
        assert_eq!((&one, &one_config), (&day(1).0, &day(1).1), "a day is drawn from the seed alone");
        assert_ne!(one.tracker_from_base, day(2).0.tracker_from_base);
        let moved = (one.tracker_from_base * cell.tracker_from_base.inverse()).log();
        let (v, w) = (moved.v, moved.w);
        let limit = Day::default().resight_translation_m;
        assert!(v.norm() > 1e-4 && v.amax() <= limit * 1.01, "{v:?}");
        assert!(w.norm() > 1e-4 && w.amax() <= Day::default().resight_rotation_rad * 1.01, "{w:?}");
        let rows = simulate(&one, &paper_effects(), &joint_ranges(&robot), &one_config, false).unwrap();
        assert!(rows.rows.iter().all(|r| r.t_s.is_some_and(|t| t >= DAY_S)));
    }

    #[test]
    fn simulated_rows_carry_payload_and_orientation_only_for_full_pose() {
        let robot = testkit::robot("irb4400.ron");
        let cell = simulated_cell(&robot, &Perturbation::default(), 1).unwrap();
        let config = GeneratorConfig { sample_count: 5, ..GeneratorConfig::default() };
        for full_pose in [false, true] {
            let set = simulate(&cell, &paper_effects(), &joint_ranges(&robot), &config, full_pose).unwrap();
            assert_eq!(set.rows.len(), 5);
            assert_eq!(set.full_pose, full_pose);
            assert!(set.rows.iter().all(|r| config.payloads_kg.contains(&r.payload_kg)));
        }
    }

    #[test]
    fn a_simulation_that_overflows_is_refused_not_written() {
        let robot = testkit::robot("irb4400.ron");
        let cell = simulated_cell(&robot, &Perturbation::default(), 1).unwrap();
        let config = GeneratorConfig { sample_count: 3, ..GeneratorConfig::default() };
        let noise = TrackerNoiseModel { transverse_sigma_per_m: 1e308, ..TrackerNoiseModel::default() };
        let effects = Effects { tracker_noise: Some(noise), ..Effects::default() };
        let result = simulate(&cell, &effects, &joint_ranges(&robot), &config, true);
        assert!(
            matches!(
                result.as_ref().map_err(Error::kind::<ErrorKind>),
                Err(Some(ErrorKind::NonFiniteSimulation { row: 1 }))
            ),
            "{result:?}"
        );
    }

    #[test]
    fn a_payload_run_campaign_has_a_remounted_tool_per_run_fixed_joints_and_torques() {
        let robot = testkit::robot("iiwa7.ron");
        let config = payload_run_campaign(40, 2);
        let (cell, data) =
            simulate_campaign(&robot, &paper_effects(), &Perturbation::default(), &Remount::default(), &config, true)
                .unwrap();
        assert_eq!(data.tools, ["tool1", "tool2", "tool3", "tool4"]);
        for (run, kg) in config.payloads_kg.iter().enumerate() {
            let rows: Vec<&Measurement> = data.rows.iter().filter(|r| r.tool == run).collect();
            assert_eq!(rows.len(), 10);
            assert!(rows.iter().all(|r| r.payload_kg == *kg));
        }
        assert!(data.rows.iter().all(|r| r.q[2..].iter().all(|q| q.abs() <= 2e-3)));
        assert!(data.rows.iter().all(|r| r.torques_nm.as_ref().is_some_and(|t| t.len() == 7)));
        // Each remount moves the probe by millimetres, within the remount's bounds.
        let first = cell.robot.tools()[0];
        for tool in &cell.robot.tools()[1..] {
            let offset = (*tool * first.inverse()).log().to_vector();
            assert!(offset.iter().take(3).any(|c| c.abs() > 1e-4), "{offset:?}");
            assert!(offset.iter().all(|c| c.abs() <= 2.5e-3), "{offset:?}");
        }
        // The same campaign without a tool per run keeps the cell of `simulated_cell`.
        let one_tool = GeneratorConfig { tool_per_run: false, ..config.clone() };
        let plain = campaign_cell(&robot, &Perturbation::default(), &Remount::default(), &one_tool).unwrap();
        assert_eq!(plain, simulated_cell(&robot, &Perturbation::default(), 2).unwrap());
        assert_eq!(cell.robot.tools()[0], plain.robot.tools()[0]);
    }

    #[test]
    fn streamed_rows_are_the_bytes_of_the_set_written_whole() {
        let iiwa = testkit::robot("iiwa7.ron");
        // Plain, a tool per run with torques, and fewer rows than runs (some runs without a row).
        let cases = [
            (testkit::robot("irb4400.ron"), GeneratorConfig { sample_count: 7, ..GeneratorConfig::default() }, true),
            (testkit::robot("irb4400.ron"), GeneratorConfig { sample_count: 7, ..GeneratorConfig::default() }, false),
            (iiwa.clone(), payload_run_campaign(9, 3), true),
            (iiwa, payload_run_campaign(3, 3), false),
        ];
        for (robot, config, full_pose) in cases {
            let (cell, whole) = simulate_campaign(
                &robot,
                &paper_effects(),
                &Perturbation::default(),
                &Remount::default(),
                &config,
                full_pose,
            )
            .unwrap();
            let mut expected = Vec::new();
            whole.write_csv(&mut expected).unwrap();
            let mut streamed = Vec::new();
            let rows = simulate_to_csv(
                &cell,
                &paper_effects(),
                &joint_ranges(&robot),
                &config,
                full_pose,
                &mut streamed,
                "mem",
            )
            .unwrap();
            assert_eq!(rows, config.sample_count);
            assert_eq!(String::from_utf8(streamed).unwrap(), String::from_utf8(expected).unwrap(), "{config:?}");
        }
    }

    #[test]
    fn a_streamed_simulation_that_overflows_is_refused_at_its_row() {
        let robot = testkit::robot("irb4400.ron");
        let cell = simulated_cell(&robot, &Perturbation::default(), 1).unwrap();
        let config = GeneratorConfig { sample_count: 3, ..GeneratorConfig::default() };
        let noise = TrackerNoiseModel { transverse_sigma_per_m: 1e308, ..TrackerNoiseModel::default() };
        let effects = Effects { tracker_noise: Some(noise), ..Effects::default() };
        let result = simulate_to_csv(&cell, &effects, &joint_ranges(&robot), &config, true, Vec::new(), "mem");
        assert!(
            matches!(
                result.as_ref().map_err(Error::kind::<ErrorKind>),
                Err(Some(ErrorKind::NonFiniteSimulation { row: 1 }))
            ),
            "{result:?}"
        );
        let many = GeneratorConfig { sample_count: MAX_ROWS + 1, ..GeneratorConfig::default() };
        let result = simulate_to_csv(&cell, &effects, &joint_ranges(&robot), &many, true, Vec::new(), "mem");
        assert!(
            matches!(
                result.as_ref().map_err(Error::kind::<ErrorKind>),
                Err(Some(ErrorKind::TooManySimulatedRows { .. }))
            ),
            "{result:?}"
        );
    }
}
