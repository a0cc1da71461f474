//! Shared by the experiments: a perturbed "true" robot in a cell, simulated datasets as
//! measurement sets.

use lie::{SE3, SO3, Twist, Vector3};
use loadsim::{Effects, GeneratorConfig, JointRange, SimulatedCell};
use pipeline::{Measurement, MeasurementSet, RobotDescription};
use poe::LocalPoe;
use rand::Rng;

/// A random twist with translation and rotation components uniform in ±`translation`, ±`rotation`.
pub fn random_twist<R: Rng>(rng: &mut R, translation: f64, rotation: f64) -> Twist {
    let mut v = || Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    let (a, b) = (v(), v());
    Twist::new(a * translation, b * rotation)
}

/// The nominal arm with every constant transform (joints and tool) off by up to `translation_m`
/// and `rotation_rad` per axis, and a tool `tool_m` out along the flange's z axis.
pub fn perturbed_robot<R: Rng>(
    robot: &RobotDescription,
    rng: &mut R,
    translation_m: f64,
    rotation_rad: f64,
    tool_m: f64,
) -> Result<LocalPoe, String> {
    let mut model = robot.nominal_model().map_err(|e| e.to_string())?;
    for joint in model.joints_mut() {
        joint.previous_from_joint_zero =
            random_twist(rng, translation_m, rotation_rad).exp() * joint.previous_from_joint_zero;
    }
    let tool = model.tools()[0] * SE3::from_translation(Vector3::new(0.0, 0.0, tool_m));
    model.set_tools(vec![random_twist(rng, translation_m, rotation_rad).exp() * tool]);
    Ok(model)
}

/// A tracker 3–5 m from the base, turned about the vertical, levelled.
pub fn tracker_placement<R: Rng>(rng: &mut R) -> SE3 {
    let distance = rng.random_range(3.0..5.0);
    let bearing: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let turn = SO3::exp(&Vector3::new(0.0, 0.0, rng.random_range(-3.1..3.1)));
    // tracker_from_base: the base seen from a tracker placed at `distance` on `bearing`.
    let tracker_in_base = Vector3::new(distance * bearing.cos(), distance * bearing.sin(), rng.random_range(-0.5..0.5));
    let base_from_tracker = SE3::new(turn, tracker_in_base);
    base_from_tracker.inverse()
}

/// The robot's joint ranges as the generator takes them.
pub fn ranges(robot: &RobotDescription) -> Vec<JointRange> {
    robot.limits().into_iter().map(|(lower_rad, upper_rad)| JointRange { lower_rad, upper_rad }).collect()
}

/// A simulated dataset as a measurement set (position only unless `full_pose`).
pub fn simulate(
    cell: &SimulatedCell,
    effects: &Effects,
    ranges: &[JointRange],
    config: &GeneratorConfig,
    full_pose: bool,
) -> Result<MeasurementSet, String> {
    let samples = loadsim::generate(cell, effects, ranges, config).map_err(|e| e.to_string())?;
    let rows = samples
        .into_iter()
        .enumerate()
        .map(|(i, s)| Measurement {
            line: i as u64 + 2,
            q: s.q,
            position: s.tracker_from_tool.translation(),
            orientation: full_pose.then(|| s.tracker_from_tool.rotation()),
            payload_kg: s.payload_kg,
            tool: 0,
            temp_c: Some(s.temp_c),
            t_s: Some(s.t_s),
            torques_nm: None,
        })
        .collect();
    Ok(MeasurementSet::from_rows("simulated", rows, vec![]))
}

/// Mean distance between the measured points of two sets of the same poses, mm.
pub fn mean_distance_mm(a: &MeasurementSet, b: &MeasurementSet) -> f64 {
    a.rows.iter().zip(&b.rows).map(|(x, y)| (x.position - y.position).norm()).sum::<f64>() * 1e3
        / a.rows.len().max(1) as f64
}
