//! The GP methods on simulated data with a load effect: the paper's ordering on held-out rows.

use lie::{SE3, SO3, Twist, Vector3};
use loadsim::{Effects, GeneratorConfig, JointCompliance, JointRange, SimulatedCell, TrackerNoise};
use pipeline::{FitOptions, Measurement, MeasurementSet, Method, RobotDescription};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;

fn irb4400() -> RobotDescription {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots/irb4400.ron");
    RobotDescription::read(&path).unwrap()
}

/// Simulated tracker data of a perturbed IRB 4400 whose joints give under gravity and payload.
/// The payloads span the robot's rating (0 to 60 kg), where the load effect is of the same order
/// as the self-weight one.
fn loaded_data(robot: &RobotDescription, rows: usize, full_pose: bool, seed: u64) -> MeasurementSet {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut truth = robot.nominal_model().unwrap();
    let mut twist = |t: f64, r: f64| {
        let mut v =
            || Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let (a, b) = (v(), v());
        Twist::new(a * t, b * r).exp()
    };
    for joint in truth.joints_mut() {
        joint.previous_from_joint_zero = twist(0.001, 0.001) * joint.previous_from_joint_zero;
    }
    let tool = truth.tools()[0] * SE3::from_translation(Vector3::new(0.0, 0.0, 0.2));
    truth.set_tools(vec![tool]);
    let mut cell = SimulatedCell::new(truth, robot.dynamics.clone());
    cell.tracker_from_base = SE3::new(SO3::exp(&Vector3::new(0.0, 0.0, 2.0)), Vector3::new(3.5, 1.0, -0.3));
    let effects = Effects {
        compliance: Some(JointCompliance::default()),
        tracker_noise: Some(TrackerNoise::default()),
        ..Effects::default()
    };
    let ranges: Vec<JointRange> =
        robot.limits().into_iter().map(|(lower_rad, upper_rad)| JointRange { lower_rad, upper_rad }).collect();
    let config = GeneratorConfig {
        sample_count: rows,
        seed,
        payloads_kg: vec![0.0, 15.0, 30.0, 45.0, 60.0],
        ..GeneratorConfig::default()
    };
    let samples = loadsim::generate(&cell, &effects, &ranges, &config).unwrap();
    let rows = samples
        .into_iter()
        .map(|s| Measurement {
            line: 0,
            q: s.q,
            position: s.tracker_from_tool.translation(),
            orientation: full_pose.then(|| s.tracker_from_tool.rotation()),
            payload_kg: s.payload_kg,
            tool: 0,
            temp_c: None,
            t_s: None,
            torques_nm: None,
        })
        .collect();
    MeasurementSet::from_rows("simulated", rows, vec![])
}

#[test]
fn with_a_load_effect_poe_gp_load_beats_poe_gp_which_beats_poe() {
    let robot = irb4400();
    for (seed, full_pose) in [(11, true), (12, false)] {
        let all = loaded_data(&robot, 400, full_pose, seed);
        let train = all.subset(&(0..250).collect::<Vec<_>>());
        let test = all.subset(&(250..400).collect::<Vec<_>>());
        let error = |method| {
            let (model, _) = pipeline::fit(&robot, &train, method, &FitOptions::default()).unwrap();
            pipeline::evaluate(&model, &test).unwrap().summary.mean_position_error_mm
        };
        let (poe, gp, load) = (error(Method::Poe), error(Method::PoeGp), error(Method::PoeGpLoad));
        eprintln!("seed {seed} full pose {full_pose}: poe {poe:.4} poe-gp {gp:.4} poe-gp-load {load:.4} mm");
        assert!(gp < 0.9 * poe, "poe-gp {gp} mm should beat poe {poe} mm by 10 %");
        assert!(load < 0.9 * gp, "poe-gp-load {load} mm should beat poe-gp {gp} mm by 10 %");
    }
}

#[test]
fn identified_joint_compliance_leaves_little_more_than_the_noise() {
    let robot = irb4400();
    for (seed, full_pose) in [(13, true), (14, false)] {
        let all = loaded_data(&robot, 400, full_pose, seed);
        let train = all.subset(&(0..250).collect::<Vec<_>>());
        let test = all.subset(&(250..400).collect::<Vec<_>>());
        let error = |method, joint_compliance| {
            let options = FitOptions { joint_compliance, ..FitOptions::default() };
            let (model, _) = pipeline::fit(&robot, &train, method, &options).unwrap();
            pipeline::evaluate(&model, &test).unwrap().summary.mean_position_error_mm
        };
        let load = error(Method::PoeGpLoad, false);
        let compliance = error(Method::Poe, true);
        eprintln!(
            "seed {seed} full pose {full_pose}: poe-gp-load {load:.4} mm, poe + joint compliance {compliance:.4} mm"
        );
        // The Leica-like noise alone leaves about 0.03 mm.
        assert!(compliance < 0.06, "poe with joint compliance left {compliance} mm");
        assert!(compliance < 0.5 * load, "joint compliance {compliance} mm against poe-gp-load {load} mm");
    }
}
