//! Shared by the experiments: a perturbed "true" robot in a cell, simulated datasets as
//! measurement sets. The building blocks live in `campaign` (the `calib simulate`
//! command needs them too; `random_twist` moved there); these wrappers keep the experiments'
//! signatures.

use campaign::Perturbation;
use lie::SE3;
use loadsim::{Effects, GeneratorConfig, JointRange, SimulatedCell};
use measurements::MeasurementSet;
use poe::LocalPoe;
use rand::Rng;
use robot::RobotDescription;

/// The nominal arm with every constant transform (joints and tool) off by up to `translation_m`
/// and `rotation_rad` per axis, and a tool `tool_m` out along the flange's z axis.
pub fn perturbed_robot<R: Rng>(
    robot: &RobotDescription,
    rng: &mut R,
    translation_m: f64,
    rotation_rad: f64,
    tool_m: f64,
) -> anyhow::Result<LocalPoe> {
    let perturbation = Perturbation { translation_m, rotation_rad, tool_m };
    campaign::perturbed_robot(robot, &perturbation, rng).map_err(anyhow::Error::from)
}

/// A tracker 3–5 m from the base, turned about the vertical, levelled.
pub fn tracker_placement<R: Rng>(rng: &mut R) -> SE3 {
    campaign::tracker_placement(rng)
}

/// The robot's joint ranges as the generator takes them.
pub fn ranges(robot: &RobotDescription) -> Vec<JointRange> {
    campaign::joint_ranges(robot)
}

/// A simulated dataset as a measurement set (position only unless `full_pose`).
pub fn simulate(
    cell: &SimulatedCell,
    effects: &Effects,
    ranges: &[JointRange],
    config: &GeneratorConfig,
    full_pose: bool,
) -> anyhow::Result<MeasurementSet> {
    campaign::simulate(cell, effects, ranges, config, full_pose).map_err(anyhow::Error::from)
}

/// Mean distance between the measured points of two sets of the same poses, mm.
pub fn mean_distance_mm(a: &MeasurementSet, b: &MeasurementSet) -> f64 {
    a.rows.iter().zip(&b.rows).map(|(x, y)| (x.position - y.position).norm()).sum::<f64>() * 1e3
        / a.rows.len().max(1) as f64
}
