//! The simulated dataset: random joint configurations inside the limits and away from
//! singularities, a payload, a temperature and a time for each, and the measured pose after every
//! active effect.
//!
//! Determinism: one seed, three independent ChaCha streams (configurations, payloads, tracker
//! noise), so that switching the noise or changing the payload set leaves the configurations as
//! they were.

use crate::{Effects, Error, Payload, PoseContext, SimulatedCell, singularity::smallest_singular_value};
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
        }
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
}

const CONFIGURATION_STREAM: u64 = 0;
const PAYLOAD_STREAM: u64 = 1;
const NOISE_STREAM: u64 = 2;

fn stream(seed: u64, id: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(id);
    rng
}

/// `count` joint configurations drawn uniformly inside `ranges` less the margin, rejecting those
/// whose tool-point Jacobian's smallest singular value is below the threshold.
pub fn sample_configurations(
    model: &LocalPoe,
    tool: usize,
    ranges: &[JointRange],
    config: &GeneratorConfig,
) -> Result<Vec<Vec<f64>>, Error> {
    let n = model.joint_count();
    if ranges.len() != n {
        return Err(Error::LengthMismatch { field: "joint ranges", given: ranges.len(), expected: n });
    }
    let margin = config.limit_margin_rad;
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(Error::InvalidParameter { field: "limit_margin_rad", value: margin });
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
    let mut rng = stream(config.seed, CONFIGURATION_STREAM);
    let mut accepted = Vec::with_capacity(config.sample_count);
    let budget = config.sample_count.max(1).saturating_mul(config.max_attempts_per_sample);
    let mut attempts = 0;
    while accepted.len() < config.sample_count {
        if attempts >= budget {
            return Err(Error::SamplingExhausted { accepted: accepted.len(), attempts });
        }
        attempts += 1;
        let q: Vec<f64> = bounds.iter().map(|&(lo, hi)| rng.random_range(lo..hi)).collect();
        if smallest_singular_value(model, &q, tool)? >= config.min_singular_value {
            accepted.push(q);
        }
    }
    Ok(accepted)
}

/// The simulated dataset: configurations from [`sample_configurations`] on the cell's true model,
/// a payload per pose drawn from the set, the time `start + i · seconds_per_pose` and the
/// temperature profile at that time, and the measured pose from [`Effects::measured_pose`].
pub fn generate(
    cell: &SimulatedCell,
    effects: &Effects,
    ranges: &[JointRange],
    config: &GeneratorConfig,
) -> Result<Vec<Sample>, Error> {
    effects.validate(cell)?;
    if config.payloads_kg.is_empty() {
        return Err(Error::LengthMismatch { field: "payloads_kg", given: 0, expected: 1 });
    }
    if let Some(&m) = config.payloads_kg.iter().find(|m| !(m.is_finite() && **m >= 0.0)) {
        return Err(Error::InvalidParameter { field: "payloads_kg", value: m });
    }
    let configurations = sample_configurations(&cell.robot, cell.tool, ranges, config)?;
    let mut payload_rng = stream(config.seed, PAYLOAD_STREAM);
    let mut noise_rng = stream(config.seed, NOISE_STREAM);
    configurations
        .into_iter()
        .enumerate()
        .map(|(i, q)| {
            let payload_kg = config.payloads_kg[payload_rng.random_range(0..config.payloads_kg.len())];
            let t_s = config.start_time_s + i as f64 * config.seconds_per_pose;
            let context = PoseContext {
                payload: Payload { mass_kg: payload_kg, com_offset_m: config.payload_com_offset_m },
                temp_c: config.temperature.at(t_s),
                t_s,
            };
            let tracker_from_tool = effects.measured_pose(cell, &q, &context, &mut noise_rng)?;
            Ok(Sample { q, tracker_from_tool, payload_kg, temp_c: context.temp_c, t_s })
        })
        .collect()
}

impl From<(f64, f64)> for JointRange {
    fn from((lower_rad, upper_rad): (f64, f64)) -> Self {
        Self { lower_rad, upper_rad }
    }
}
