//! The dataset generator: deterministic for a seed, inside the limits, away from singularities.

use crate::robot::{irb4400, with_tool};
use lie::{SE3, SO3, Vector3};
use loadsim::{
    Effects, Error, GeneratorConfig, JointRange, SimulatedCell, generate, sample_configurations,
    smallest_singular_value,
};

fn cell() -> (SimulatedCell, Vec<JointRange>) {
    let robot = irb4400();
    let mut cell = SimulatedCell::new(with_tool(&robot.model, 0.2), Some(robot.dynamics));
    cell.tracker_from_base = SE3::new(SO3::from_rpy(0.0, 0.0, 3.0), Vector3::new(3.5, 0.5, -0.3));
    (cell, robot.ranges)
}

fn small() -> GeneratorConfig {
    GeneratorConfig { sample_count: 60, seed: 7, ..GeneratorConfig::default() }
}

#[test]
fn generator_is_deterministic_for_a_seed_and_differs_between_seeds() {
    let (cell, ranges) = cell();
    let effects = Effects::typical(6);
    let first = generate(&cell, &effects, &ranges, &small()).unwrap();
    let again = generate(&cell, &effects, &ranges, &small()).unwrap();
    assert_eq!(first, again);
    let other = generate(&cell, &effects, &ranges, &GeneratorConfig { seed: 8, ..small() }).unwrap();
    assert_ne!(first[0].q, other[0].q);
}

#[test]
fn generated_joints_stay_inside_the_limits_less_the_margin() {
    let (cell, ranges) = cell();
    let config = small();
    for sample in generate(&cell, &Effects::typical(6), &ranges, &config).unwrap() {
        for (q, r) in sample.q.iter().zip(&ranges) {
            assert!(*q >= r.lower_rad + config.limit_margin_rad && *q <= r.upper_rad - config.limit_margin_rad);
        }
    }
}

#[test]
fn generated_poses_are_away_from_singularities() {
    let (cell, ranges) = cell();
    let config = GeneratorConfig { sample_count: 300, ..small() };
    let configurations = sample_configurations(&cell.robot, 0, &ranges, &config).unwrap();
    let mut smallest_q5 = f64::INFINITY;
    for q in &configurations {
        assert!(smallest_singular_value(&cell.robot, q, 0).unwrap() >= config.min_singular_value);
        smallest_q5 = smallest_q5.min(q[4].sin().abs());
    }
    // The wrist singularity q5 = 0 is the one a 6R arm meets most: the threshold keeps it away.
    assert!(smallest_q5 > 1f64.to_radians().sin(), "|sin q5| down to {smallest_q5}");
}

#[test]
fn generator_rejects_candidates_at_the_wrist_singularity() {
    let (cell, mut ranges) = cell();
    ranges[4] = JointRange { lower_rad: -0.5f64.to_radians(), upper_rad: 0.5f64.to_radians() };
    let config = GeneratorConfig { sample_count: 5, limit_margin_rad: 0.0, max_attempts_per_sample: 20, ..small() };
    let refused = sample_configurations(&cell.robot, 0, &ranges, &config).unwrap_err();
    assert!(matches!(refused, Error::SamplingExhausted { accepted: 0, attempts: 100 }), "{refused:?}");
}

#[test]
fn switching_the_noise_leaves_configurations_payloads_and_times_unchanged() {
    let (cell, ranges) = cell();
    let noisy = generate(&cell, &Effects::typical(6), &ranges, &small()).unwrap();
    let quiet_effects = Effects { tracker_noise: None, ..Effects::typical(6) };
    let quiet = generate(&cell, &quiet_effects, &ranges, &small()).unwrap();
    for (a, b) in noisy.iter().zip(&quiet) {
        assert_eq!((&a.q, a.payload_kg, a.temp_c, a.t_s), (&b.q, b.payload_kg, b.temp_c, b.t_s));
        let gap = (a.tracker_from_tool.translation() - b.tracker_from_tool.translation()).norm();
        assert!(gap > 0.0 && gap < 1e-4, "noise of tens of micrometres, got {gap}");
    }
}

#[test]
fn payload_temperature_and_time_columns_follow_the_configuration() {
    let (cell, ranges) = cell();
    let config = GeneratorConfig { sample_count: 300, ..small() };
    let samples = generate(&cell, &Effects::typical(6), &ranges, &config).unwrap();
    for kg in &config.payloads_kg {
        assert!(samples.iter().any(|s| s.payload_kg == *kg), "{kg} kg used");
    }
    assert!(samples.iter().all(|s| config.payloads_kg.contains(&s.payload_kg)));
    for (i, pair) in samples.windows(2).enumerate() {
        assert_eq!(pair[1].t_s - pair[0].t_s, config.seconds_per_pose, "pose {i}");
        assert!(pair[1].temp_c > pair[0].temp_c, "the cell warms up");
    }
    let last = samples.last().unwrap();
    // 300 poses at 30 s: 2.5 h, so 3 °C · (1 − e^{−1.25}) ≈ 2.14 °C above the start.
    assert!((last.temp_c - 20.0 - 3.0 * (1.0 - (-last.t_s / 7200.0f64).exp())).abs() < 1e-12);
    assert!((2.0..2.3).contains(&(last.temp_c - 20.0)));
}
