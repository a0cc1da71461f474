//! The shapes of real campaigns: some joints fixed within a jitter, payload runs with a tool
//! each, measured joint torques.

use crate::robot::{iiwa7, irb4400, with_tool};
use lie::{SE3, Vector3};
use loadsim::{
    Effects, Error, GeneratorConfig, JointComplianceModel, JointRange, Payload, SimulatedCell, TorqueSensorNoise,
    generate, static_torque,
};

/// The iiwa 7 with four tools: the probe remounted 1 mm further out along the flange z each time.
fn iiwa_cell_with_tools(tools: usize) -> (SimulatedCell, Vec<JointRange>) {
    let robot = iiwa7();
    let mut model = with_tool(&robot.model, 0.1);
    let first = model.tools()[0];
    model.set_tools(
        (0..tools).map(|r| first * SE3::from_translation(Vector3::new(0.0, 0.0, 1e-3 * r as f64))).collect(),
    );
    (SimulatedCell::new(model, Some(robot.dynamics)), robot.ranges)
}

fn two_joint_runs() -> GeneratorConfig {
    GeneratorConfig {
        sample_count: 41,
        seed: 3,
        moving_joints: vec![0, 1],
        fixed_jitter_rad: 2e-3,
        payloads_kg: vec![0.0, 1.25, 2.5, 5.0],
        tool_per_run: true,
        ..GeneratorConfig::default()
    }
}

#[test]
fn fixed_joints_stay_within_the_jitter_of_zero_and_moving_joints_spread() {
    let (cell, ranges) = iiwa_cell_with_tools(4);
    let samples = generate(&cell, &Effects::default(), &ranges, &two_joint_runs()).unwrap();
    for s in &samples {
        assert!(s.q[2..].iter().all(|q| q.abs() <= 2e-3), "{:?}", s.q);
    }
    assert!(samples.iter().any(|s| s.q[2..].iter().any(|q| q.abs() > 1e-3)), "the jitter is drawn");
    let spread = |j: usize| {
        let (lo, hi) =
            samples.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| (a.min(s.q[j]), b.max(s.q[j])));
        hi - lo
    };
    assert!(spread(0) > 2.0 && spread(1) > 1.5, "joints 1 and 2 move: {} {}", spread(0), spread(1));
}

#[test]
fn payload_runs_are_consecutive_in_order_each_with_its_own_tool() {
    let (cell, ranges) = iiwa_cell_with_tools(4);
    let config = two_joint_runs();
    let samples = generate(&cell, &Effects::default(), &ranges, &config).unwrap();
    let runs: Vec<(f64, usize)> = samples.iter().map(|s| (s.payload_kg, s.tool)).collect();
    let mut sizes = [0usize; 4];
    for (r, kg) in config.payloads_kg.iter().enumerate() {
        sizes[r] = runs.iter().filter(|(m, tool)| m == kg && *tool == r).count();
    }
    assert_eq!(sizes.iter().sum::<usize>(), 41, "each pose carries its run's payload and tool: {runs:?}");
    assert!(sizes.iter().all(|n| (10..=11).contains(n)), "{sizes:?}");
    assert!(runs.windows(2).all(|w| w[1].1 >= w[0].1), "runs are consecutive");
    // The tool is the run's: without effects the measured pose is the geometric one with it.
    for s in &samples {
        let expected = cell.robot.forward(&s.q, s.tool).unwrap();
        assert!((s.tracker_from_tool.translation() - expected.translation()).norm() < 1e-12);
    }
}

#[test]
fn a_tool_per_run_needs_a_tool_per_payload() {
    let (cell, ranges) = iiwa_cell_with_tools(3);
    let refused = generate(&cell, &Effects::default(), &ranges, &two_joint_runs()).unwrap_err();
    assert_eq!(
        refused,
        Error::Campaign { field: "tool_per_run", needs: "one tool of the cell per payload run", given: 3, expected: 4 }
    );
}

#[test]
fn a_moving_joint_the_robot_lacks_and_a_fixed_value_outside_the_range_are_refused() {
    let (cell, ranges) = iiwa_cell_with_tools(4);
    let config = GeneratorConfig { moving_joints: vec![1, 7], ..two_joint_runs() };
    let refused = generate(&cell, &Effects::default(), &ranges, &config).unwrap_err();
    assert_eq!(
        refused,
        Error::from(dynamics::Error::UnknownJoint { field: "moving_joints", joint_index: 7, joint_count: 7 })
    );
    let config = GeneratorConfig { fixed_at_rad: vec![0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 0.0], ..two_joint_runs() };
    let refused = generate(&cell, &Effects::default(), &ranges, &config).unwrap_err();
    assert_eq!(refused, Error::from(dynamics::Error::InvalidParameter { field: "fixed_at_rad", value: 4.0 }));
    let config = GeneratorConfig { fixed_jitter_rad: -1e-3, ..two_joint_runs() };
    let refused = generate(&cell, &Effects::default(), &ranges, &config).unwrap_err();
    assert_eq!(refused, Error::from(dynamics::Error::InvalidParameter { field: "fixed_jitter_rad", value: -1e-3 }));
}

#[test]
fn measured_torques_are_the_drive_torques_holding_the_static_torque_within_the_sensor_noise() {
    let (cell, ranges) = iiwa_cell_with_tools(4);
    let exact = GeneratorConfig {
        torque_sensor: Some(TorqueSensorNoise { sigma_nm: 0.0, ..Default::default() }),
        ..two_joint_runs()
    };
    let effects = Effects { joint_compliance: Some(JointComplianceModel::default()), ..Effects::default() };
    let samples = generate(&cell, &effects, &ranges, &exact).unwrap();
    let dynamics = cell.dynamics.clone().unwrap();
    for s in &samples {
        let held = static_torque(&cell.robot, &dynamics, &s.q, s.tool, &Payload::at_tool(s.payload_kg)).unwrap();
        let measured = s.torques_nm.as_ref().unwrap();
        for (m, t) in measured.iter().zip(&held) {
            assert!((m + t).abs() < 1e-9, "τ_measured = −τ_static: {m} vs {t}");
        }
        // A floor-mounted arm: joint 1 about the vertical carries no gravity torque.
        assert!(measured[0].abs() < 1e-9);
    }
    let noisy = GeneratorConfig { torque_sensor: Some(TorqueSensorNoise::default()), ..two_joint_runs() };
    let with_noise = generate(&cell, &effects, &ranges, &noisy).unwrap();
    let mut squares = 0.0;
    let mut count = 0.0;
    for (a, b) in samples.iter().zip(&with_noise) {
        assert_eq!((&a.q, a.tracker_from_tool), (&b.q, b.tracker_from_tool), "torque noise draws from its own stream");
        for (x, y) in a.torques_nm.as_ref().unwrap().iter().zip(b.torques_nm.as_ref().unwrap()) {
            squares += (x - y) * (x - y);
            count += 1.0;
        }
    }
    let sigma = (squares / count).sqrt();
    assert!((0.4..0.6).contains(&sigma), "sample σ {sigma} for a 0.5 N·m sensor over {count} readings");
}

#[test]
fn torques_need_dynamics_and_a_valid_sensor() {
    let (mut cell, ranges) = iiwa_cell_with_tools(4);
    let bad = GeneratorConfig {
        torque_sensor: Some(TorqueSensorNoise { joint_sigma_nm: vec![0.5; 6], ..Default::default() }),
        ..two_joint_runs()
    };
    let refused = generate(&cell, &Effects::default(), &ranges, &bad).unwrap_err();
    assert_eq!(
        refused,
        Error::from(dynamics::Error::LengthMismatch { field: "torque_sensor.joint_sigma_nm", given: 6, expected: 7 })
    );
    cell.dynamics = None;
    let config = GeneratorConfig { torque_sensor: Some(TorqueSensorNoise::default()), ..two_joint_runs() };
    let refused = generate(&cell, &Effects::default(), &ranges, &config).unwrap_err();
    assert_eq!(refused, Error::MissingDynamics { effect: "measured torques" });
}

#[test]
fn naming_every_joint_as_moving_draws_what_the_default_draws() {
    let robot = irb4400();
    let cell = SimulatedCell::new(with_tool(&robot.model, 0.2), Some(robot.dynamics));
    let config = GeneratorConfig { sample_count: 20, seed: 7, ..GeneratorConfig::default() };
    let samples = generate(&cell, &Effects::default(), &robot.ranges, &config).unwrap();
    let every_joint = GeneratorConfig { moving_joints: (0..6).collect(), ..config.clone() };
    let again = generate(&cell, &Effects::default(), &robot.ranges, &every_joint).unwrap();
    assert_eq!(samples, again);
    assert!(samples.iter().all(|s| s.tool == 0 && s.torques_nm.is_none()));
}
