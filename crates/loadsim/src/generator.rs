//! The simulated dataset: random joint configurations inside the limits and away from
//! singularities, a payload, a temperature and a time for each, and the measured pose after every
//! active effect.
//!
//! Beyond the paper's study, the shapes of real campaigns: only some joints moving (the others
//! held at one value within a small jitter), payload runs (the poses split into consecutive runs,
//! one per payload, each optionally measured with its own tool, the probe remounted between
//! runs), and measured joint torques.
//!
//! Determinism: one seed, four independent ChaCha streams (configurations, payloads, tracker
//! noise, torque noise; stream 3 is left to callers that draw a cell from the same seed), so that
//! switching the noise or changing the payload set leaves the configurations as they were.

use crate::singularity::{smallest_singular_value, smallest_singular_value_of_joints};
use crate::{Effects, Error, Payload, PoseContext, SimulatedCell, TorqueSensorNoise};
use lie::SE3;
use poe::LocalPoe;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// A joint's travel, rad (m for a prismatic joint).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointRange {
    /// Lower limit.
    pub lower_rad: f64,
    /// Upper limit.
    pub upper_rad: f64,
}

/// The cell's temperature over a campaign: a warm-up towards a plateau,
/// `T(t) = T₀ + ΔT (1 − e^{−t/τ})` (first-order thermal response of a robot warming up in
/// operation; the default, +3 °C with τ = 2 h from 20 °C, is an engineering estimate of a cell).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TemperatureProfile {
    /// Temperature at `t = 0`, °C.
    pub start_c: f64,
    /// Rise towards the plateau, °C (negative for a cooling cell).
    pub rise_c: f64,
    /// Time constant, s.
    pub time_constant_s: f64,
}

impl Default for TemperatureProfile {
    fn default() -> Self {
        Self { start_c: 20.0, rise_c: 3.0, time_constant_s: 7200.0 }
    }
}

impl TemperatureProfile {
    /// The temperature at time `t_s`, °C.
    pub fn at(&self, t_s: f64) -> f64 {
        self.start_c + self.rise_c * (1.0 - (-t_s / self.time_constant_s).exp())
    }
}

/// How to draw the dataset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GeneratorConfig {
    /// Number of poses. Default 300, the paper's training set.
    pub sample_count: usize,
    /// Seed of every random draw.
    pub seed: u64,
    /// Distance kept from each joint limit, rad. Default 5°.
    pub limit_margin_rad: f64,
    /// Reject a pose whose tool-point Jacobian has a singular value below this. Default 0.05,
    /// which keeps `|q5|` above about 3° on a 6R wrist.
    pub min_singular_value: f64,
    /// Payloads, kg, one drawn uniformly per pose. Default: the paper's 1, 2.5, 3.5, 5, 7.5 kg.
    pub payloads_kg: Vec<f64>,
    /// Payload centre of mass relative to the tool point, tool frame, m. Default: at the tool point.
    pub payload_com_offset_m: [f64; 3],
    /// Time between two poses, s. Default 30 (move, settle, measure).
    pub seconds_per_pose: f64,
    /// Time of the first pose, s.
    pub start_time_s: f64,
    /// Temperature over time.
    pub temperature: TemperatureProfile,
    /// Candidates drawn per accepted pose before giving up. Default 1000.
    pub max_attempts_per_sample: usize,
    /// The joints that move, 0-based; empty (default): every joint. The others sit at
    /// `fixed_at_rad` within `fixed_jitter_rad`, and only the moving joints' columns of the
    /// tool-point Jacobian are checked for a singularity.
    pub moving_joints: Vec<usize>,
    /// Where each joint that does not move sits, rad: empty (default) or one entry per joint
    /// (those of moving joints unused). Empty: 0, moved inside the joint's range less the margin
    /// where 0 is not.
    pub fixed_at_rad: Vec<f64>,
    /// Each fixed joint is drawn uniformly within ± this of its value, rad (a joint held by its
    /// controller reads back within a few encoder counts to milliradians). Default 0.
    pub fixed_jitter_rad: f64,
    /// Payload runs: the poses split into consecutive runs of sizes differing by at most one, one
    /// per entry of `payloads_kg` in order, instead of a payload drawn per pose. Default false.
    pub payload_runs: bool,
    /// Measure run `r` with tool `r` of the cell's robot (the probe remounted between runs, so
    /// each run has its own tool transform); implies `payload_runs`. The cell needs one tool per
    /// payload. Default false: every pose with the cell's tool.
    pub tool_per_run: bool,
    /// Measured joint torques with each sample, with this noise; needs the robot's dynamics.
    /// Default: none.
    pub torque_sensor: Option<TorqueSensorNoise>,
}

impl Default for GeneratorConfig {
    fn default() -> Self {
        Self {
            sample_count: 300,
            seed: 0,
            limit_margin_rad: 5f64.to_radians(),
            min_singular_value: 0.05,
            payloads_kg: vec![1.0, 2.5, 3.5, 5.0, 7.5],
            payload_com_offset_m: [0.0; 3],
            seconds_per_pose: 30.0,
            start_time_s: 0.0,
            temperature: TemperatureProfile::default(),
            max_attempts_per_sample: 1000,
            moving_joints: Vec::new(),
            fixed_at_rad: Vec::new(),
            fixed_jitter_rad: 0.0,
            payload_runs: false,
            tool_per_run: false,
            torque_sensor: None,
        }
    }
}

impl GeneratorConfig {
    /// Whether the poses come in payload runs (`payload_runs`, or implied by `tool_per_run`).
    pub fn runs(&self) -> bool {
        self.payload_runs || self.tool_per_run
    }

    /// The payload run of pose `index` (0 without runs).
    pub fn run_of(&self, index: usize) -> usize {
        if self.runs() && self.sample_count > 0 { index * self.payloads_kg.len() / self.sample_count } else { 0 }
    }

    /// Whether joint `j` moves.
    fn moves(&self, j: usize) -> bool {
        self.moving_joints.is_empty() || self.moving_joints.contains(&j)
    }
}

/// One simulated measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Commanded joint values, rad.
    pub q: Vec<f64>,
    /// Measured tool pose in the tracker frame, after every active effect and the noise.
    pub tracker_from_tool: SE3,
    /// Payload at the tool, kg.
    pub payload_kg: f64,
    /// Temperature, °C.
    pub temp_c: f64,
    /// Time, s.
    pub t_s: f64,
    /// Index of the tool measured, in the cell's robot.
    pub tool: usize,
    /// Measured joint torques, the drive torques of the robot controller's convention
    /// ([`TorqueSensorNoise`]), N·m; `None` unless the configuration asks for them.
    pub torques_nm: Option<Vec<f64>>,
}

const CONFIGURATION_STREAM: u64 = 0;
const PAYLOAD_STREAM: u64 = 1;
const NOISE_STREAM: u64 = 2;
const TORQUE_STREAM: u64 = 4;

fn stream(seed: u64, id: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(id);
    rng
}

/// Joint configurations drawn uniformly inside `ranges` less the margin (the moving joints; the
/// others at their fixed value within the jitter), rejecting those whose tool-point Jacobian
/// (its moving joints' columns) has a smallest singular value below the threshold.
pub fn sample_configurations(
    model: &LocalPoe,
    tool: usize,
    ranges: &[JointRange],
    config: &GeneratorConfig,
) -> Result<Vec<Vec<f64>>, Error> {
    let mut sampler = ConfigurationSampler::new(model, tool, ranges, config)?;
    let mut accepted = Vec::with_capacity(config.sample_count);
    while accepted.len() < config.sample_count {
        accepted.push(sampler.next_configuration(accepted.len())?);
    }
    Ok(accepted)
}

/// [`sample_configurations`] one configuration at a time, so that a data set can be written as it
/// is drawn (the draws, and so the configurations, are the same).
struct ConfigurationSampler<'a> {
    model: &'a LocalPoe,
    tool: usize,
    config: &'a GeneratorConfig,
    bounds: Vec<(f64, f64)>,
    fixed: Vec<Option<f64>>,
    rng: ChaCha8Rng,
    budget: usize,
    attempts: usize,
}

impl<'a> ConfigurationSampler<'a> {
    fn new(
        model: &'a LocalPoe,
        tool: usize,
        ranges: &[JointRange],
        config: &'a GeneratorConfig,
    ) -> Result<Self, Error> {
        let n = model.joint_count();
        if ranges.len() != n {
            return Err(Error::from(dynamics::Error::LengthMismatch {
                field: "joint ranges",
                given: ranges.len(),
                expected: n,
            }));
        }
        let margin = config.limit_margin_rad;
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(Error::from(dynamics::Error::InvalidParameter { field: "limit_margin_rad", value: margin }));
        }
        let bounds: Vec<(f64, f64)> = ranges.iter().map(|r| (r.lower_rad + margin, r.upper_rad - margin)).collect();
        for (joint_index, (r, (lo, hi))) in ranges.iter().zip(&bounds).enumerate() {
            if lo.partial_cmp(hi) != Some(std::cmp::Ordering::Less) {
                return Err(Error::EmptyJointRange {
                    joint_index,
                    lower_rad: r.lower_rad,
                    upper_rad: r.upper_rad,
                    margin_rad: margin,
                });
            }
        }
        let fixed = fixed_values(config, &bounds)?;
        Ok(Self {
            model,
            tool,
            config,
            bounds,
            fixed,
            rng: stream(config.seed, CONFIGURATION_STREAM),
            budget: config.sample_count.max(1).saturating_mul(config.max_attempts_per_sample),
            attempts: 0,
        })
    }

    /// The next accepted configuration; `accepted` of them were drawn before (for the error).
    fn next_configuration(&mut self, accepted: usize) -> Result<Vec<f64>, Error> {
        let (config, jitter) = (self.config, self.config.fixed_jitter_rad);
        loop {
            if self.attempts >= self.budget {
                return Err(Error::SamplingExhausted { accepted, attempts: self.attempts });
            }
            self.attempts += 1;
            let rng = &mut self.rng;
            let q: Vec<f64> = self
                .bounds
                .iter()
                .enumerate()
                .map(|(j, &(lo, hi))| match self.fixed[j] {
                    None => rng.random_range(lo..hi),
                    Some(at) if jitter > 0.0 => (at + rng.random_range(-jitter..jitter)).clamp(lo, hi),
                    Some(at) => at,
                })
                .collect();
            let smallest = if config.moving_joints.is_empty() {
                smallest_singular_value(self.model, &q, self.tool)?
            } else {
                smallest_singular_value_of_joints(self.model, &q, self.tool, &config.moving_joints)?
            };
            if smallest >= config.min_singular_value {
                return Ok(q);
            }
        }
    }
}

/// Each joint's fixed value (`None` for a moving joint), checked against the configuration.
fn fixed_values(config: &GeneratorConfig, bounds: &[(f64, f64)]) -> Result<Vec<Option<f64>>, Error> {
    let n = bounds.len();
    if let Some(&joint_index) = config.moving_joints.iter().find(|&&j| j >= n) {
        return Err(Error::from(dynamics::Error::UnknownJoint { field: "moving_joints", joint_index, joint_count: n }));
    }
    if !config.fixed_at_rad.is_empty() && config.fixed_at_rad.len() != n {
        return Err(Error::from(dynamics::Error::LengthMismatch {
            field: "fixed_at_rad",
            given: config.fixed_at_rad.len(),
            expected: n,
        }));
    }
    let jitter = config.fixed_jitter_rad;
    if !(jitter.is_finite() && jitter >= 0.0) {
        return Err(Error::from(dynamics::Error::InvalidParameter { field: "fixed_jitter_rad", value: jitter }));
    }
    (0..n)
        .map(|j| {
            if config.moves(j) {
                return Ok(None);
            }
            let (lo, hi) = bounds[j];
            match config.fixed_at_rad.get(j) {
                Some(&at) if at.is_finite() && (lo..=hi).contains(&at) => Ok(Some(at)),
                Some(&value) => Err(Error::from(dynamics::Error::InvalidParameter { field: "fixed_at_rad", value })),
                None => Ok(Some(0f64.clamp(lo, hi))),
            }
        })
        .collect()
}

/// The simulated dataset: configurations from [`sample_configurations`] on the cell's true model,
/// a payload per pose drawn from the set (or one per run), the time `start + i · seconds_per_pose`
/// and the temperature profile at that time, the measured pose from [`Effects::measured_pose`]
/// with the cell's tool (or the run's), and the measured torques if asked for.
pub fn generate(
    cell: &SimulatedCell,
    effects: &Effects,
    ranges: &[JointRange],
    config: &GeneratorConfig,
) -> Result<Vec<Sample>, Error> {
    let mut samples = Vec::with_capacity(config.sample_count);
    generate_each(cell, effects, ranges, config, |sample| {
        samples.push(sample);
        Ok::<(), Error>(())
    })?;
    Ok(samples)
}

/// [`generate`], handing each sample to `sink` as it is drawn instead of holding them all (the
/// same samples in the same order): a data set of any size is written in the memory of one row.
/// An error of `sink` ends the generation and is returned.
pub fn generate_each<E: From<Error>>(
    cell: &SimulatedCell,
    effects: &Effects,
    ranges: &[JointRange],
    config: &GeneratorConfig,
    mut sink: impl FnMut(Sample) -> Result<(), E>,
) -> Result<(), E> {
    check_campaign(cell, effects, config)?;
    let runs = config.payloads_kg.len();
    // The cell as each run measures it: its own tool, or the cell's.
    let cells: Vec<SimulatedCell> = (0..runs)
        .map(|r| SimulatedCell { tool: if config.tool_per_run { r } else { cell.tool }, ..cell.clone() })
        .collect();
    let mut sampler = ConfigurationSampler::new(&cell.robot, cell.tool, ranges, config)?;
    let mut payload_rng = stream(config.seed, PAYLOAD_STREAM);
    let mut noise_rng = stream(config.seed, NOISE_STREAM);
    let mut torque_rng = stream(config.seed, TORQUE_STREAM);
    for i in 0..config.sample_count {
        let q = sampler.next_configuration(i)?;
        let run = config.run_of(i);
        let payload_kg =
            if config.runs() { config.payloads_kg[run] } else { config.payloads_kg[payload_rng.random_range(0..runs)] };
        let t_s = config.start_time_s + i as f64 * config.seconds_per_pose;
        let context = PoseContext {
            payload: Payload { mass_kg: payload_kg, com_offset_m: config.payload_com_offset_m },
            temp_c: config.temperature.at(t_s),
            t_s,
        };
        let run_cell = &cells[run];
        let tracker_from_tool = effects.measured_pose(run_cell, &q, &context, &mut noise_rng)?;
        let torques_nm = match &config.torque_sensor {
            Some(sensor) => {
                let held = effects.joint_offsets(run_cell, &q, &context)?.static_torque_nm;
                Some(sensor.measure(&held, &mut torque_rng))
            }
            None => None,
        };
        sink(Sample {
            q,
            tracker_from_tool,
            payload_kg,
            temp_c: context.temp_c,
            t_s,
            tool: run_cell.tool,
            torques_nm,
        })?;
    }
    Ok(())
}

/// Refuses a campaign the cell cannot run: effects that do not fit it, no payload or one that is
/// not a mass, fewer tools than runs where each run has its own, a torque sensor without the
/// dynamics it needs.
fn check_campaign(cell: &SimulatedCell, effects: &Effects, config: &GeneratorConfig) -> Result<(), Error> {
    effects.validate(cell)?;
    if config.payloads_kg.is_empty() {
        return Err(Error::from(dynamics::Error::LengthMismatch { field: "payloads_kg", given: 0, expected: 1 }));
    }
    if let Some(&m) = config.payloads_kg.iter().find(|m| !(m.is_finite() && **m >= 0.0)) {
        return Err(Error::from(dynamics::Error::InvalidParameter { field: "payloads_kg", value: m }));
    }
    let runs = config.payloads_kg.len();
    if config.tool_per_run && cell.robot.tool_count() < runs {
        return Err(Error::Campaign {
            field: "tool_per_run",
            needs: "one tool of the cell per payload run",
            given: cell.robot.tool_count(),
            expected: runs,
        });
    }
    if let Some(sensor) = &config.torque_sensor {
        sensor.validate(cell.robot.joint_count())?;
        cell.dynamics_for("measured torques")?;
    }
    Ok(())
}

impl From<(f64, f64)> for JointRange {
    fn from((lower_rad, upper_rad): (f64, f64)) -> Self {
        Self { lower_rad, upper_rad }
    }
}
