//! `diagnose` on simulated data whose hidden effect it is not told.

use loadsim::{Harmonic, PeriodicError};
use pipeline::diagnose::{DiagnoseOptions, Effect, diagnose};
use pipeline::simulated::{
    Effects, GeneratorConfig, Perturbation, TrackerNoise, joint_ranges, simulate, simulated_cell,
};
use pipeline::{MeasurementSet, RobotDescription};
use std::path::PathBuf;

fn irb4400() -> RobotDescription {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots/irb4400.ron");
    RobotDescription::read(&path).unwrap()
}

fn simulated(robot: &RobotDescription, effects: &Effects, full_pose: bool, seed: u64) -> MeasurementSet {
    let cell = simulated_cell(robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: 250, seed, ..GeneratorConfig::default() };
    let effects = Effects { tracker_noise: Some(TrackerNoise::default()), ..effects.clone() };
    simulate(&cell, &effects, &joint_ranges(robot), &config, full_pose).unwrap()
}

/// The robot as the diagnosis gets it: no masses, no stiffness.
fn blind(robot: &RobotDescription) -> RobotDescription {
    RobotDescription { dynamics: None, ..robot.clone() }
}

#[test]
fn a_second_harmonic_on_joint_three_is_named_and_removed_position_only_and_full_pose() {
    let robot = irb4400();
    let effects = Effects {
        periodic: Some(PeriodicError {
            harmonics: vec![Harmonic { joint_index: 2, order: 2.0, amplitude_rad: 2e-4, phase_rad: 0.4 }],
        }),
        ..Effects::default()
    };
    for (seed, full_pose) in [(21, false), (22, true)] {
        let data = simulated(&robot, &effects, full_pose, seed);
        let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
        assert_eq!(d.verdict.effect, Effect::GearPeriodic, "{}", d.summary());
        assert_eq!(d.verdict.joints, vec![3], "{}", d.summary());
        assert_eq!(d.selected[0].harmonic, Some(2), "{}", d.summary());
        assert!(d.heldout_after_mm < 0.5 * d.heldout_before_mm, "{}", d.summary());
        // What is left is the noise: within 25 % of the floor the diagnosis estimated.
        assert!(d.heldout_after_mm < 1.25 * d.noise.floor_mm, "{}", d.summary());
        let json = d.to_json();
        assert_eq!(json["verdict"]["effect"], "gear_periodic");
        assert_eq!(json["verdict"]["joints"], serde_json::json!([3]));
        assert!(json["candidates"].as_array().unwrap().len() > 20);
    }
}

#[test]
fn compliance_is_found_without_the_masses() {
    let robot = irb4400();
    let effects = Effects { compliance: Some(loadsim::JointCompliance::default()), ..Effects::default() };
    let data = simulated(&robot, &effects, false, 23);
    let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
    assert_eq!(d.verdict.effect, Effect::JointCompliance, "{}", d.summary());
    assert!(d.heldout_after_mm < 0.5 * d.heldout_before_mm, "{}", d.summary());
}

#[test]
fn noise_alone_gives_none() {
    let robot = irb4400();
    for (seed, full_pose) in [(24, false), (25, true)] {
        let data = simulated(&robot, &Effects::default(), full_pose, seed);
        let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
        assert_eq!(d.verdict.effect, Effect::None, "{}", d.summary());
        assert!(d.selected.is_empty());
        assert!((d.heldout_after_mm - d.heldout_before_mm).abs() < 1e-12);
    }
}

#[test]
fn a_report_has_a_plot_per_joint_and_the_tables() {
    let robot = irb4400();
    let data = simulated(&robot, &Effects::default(), false, 26);
    let options = DiagnoseOptions { check_structure: false, noise_mm: Some(0.01), ..DiagnoseOptions::default() };
    let d = diagnose(&blind(&robot), &data, &options).unwrap();
    let plots = d.plots();
    let names: Vec<String> = plots.iter().map(|(n, _)| n.clone()).collect();
    for j in 1..=6 {
        assert!(names.contains(&format!("joint{j}.svg")), "{names:?}");
    }
    assert!(names.contains(&"payload.svg".to_owned()) && names.contains(&"temperature.svg".to_owned()));
    let md = d.markdown(&names);
    assert!(md.contains("## Where") && md.contains("| joint 2 |") && md.contains("![joint1.svg](joint1.svg)"));
    assert_eq!(d.noise.source, pipeline::diagnose::NoiseSource::Given);
}

#[test]
fn too_few_rows_are_refused() {
    let robot = irb4400();
    let data = simulated(&robot, &Effects::default(), false, 27);
    let small = data.subset(&(0..30).collect::<Vec<_>>());
    let error = diagnose(&robot, &small, &DiagnoseOptions::default()).unwrap_err();
    assert!(matches!(error, pipeline::Error::TooFewRows { rows: 30, needed: 50, .. }), "{error}");
}
