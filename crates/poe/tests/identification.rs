//! End-to-end identification on synthetic measurements made here (no committed data).

mod common;

use common::{gaussian, iiwa7, irb4400, mean_position_error, measured_robot, observe, rng};
use lie::{SE3, SO3, Vector3};
use poe::identify::{
    IdentificationOptions, Loss, Observation, ParameterMask, Redundancy, RobustOptions, Scope, Solver, Target,
    calibrate, identify,
};
use poe::{Block, LocalPoe};

/// A nominal robot and its joint limits.
type RobotFixture = fn() -> (LocalPoe, Vec<(f64, f64)>);

struct Case {
    name: &'static str,
    robot: RobotFixture,
    full_pose: bool,
    identifiable: usize,
}

const CASES: [Case; 4] = [
    Case { name: "6R full pose", robot: irb4400, full_pose: true, identifiable: 30 },
    Case { name: "6R position", robot: irb4400, full_pose: false, identifiable: 27 },
    Case { name: "7R full pose", robot: iiwa7, full_pose: true, identifiable: 34 },
    Case { name: "7R position", robot: iiwa7, full_pose: false, identifiable: 31 },
];

#[test]
fn noise_free_calibration_reproduces_held_out_poses_to_a_nanometre() {
    for (seed, case) in CASES.iter().enumerate() {
        let (nominal, limits) = (case.robot)();
        let mut rng = rng(100 + seed as u64);
        let truth = measured_robot(&nominal, &mut rng);
        let train = observe(&truth, &limits, 120, case.full_pose, 0.0, 0.0, &mut rng);
        let test = observe(&truth, &limits, 100, case.full_pose, 0.0, 0.0, &mut rng);
        let fit = calibrate(&nominal, &train, Scope::Full, &IdentificationOptions::default()).unwrap();
        let error_mm = mean_position_error(&fit.model, &test) * 1e3;
        assert!(error_mm < 1e-6, "{}: held-out error {error_mm:e} mm", case.name);
        assert!(fit.report.converged, "{}", case.name);
    }
}

#[test]
fn noisy_calibration_reaches_within_fifteen_percent_of_the_noise_floor() {
    let sigma = 2e-5; // 0.02 mm per axis, and 0.02 mrad per axis for orientation
    let options = IdentificationOptions { position_sigma_m: sigma, rotation_sigma_rad: sigma, ..Default::default() };
    for seed in [7_u64, 8] {
        for case in &CASES {
            let (nominal, limits) = (case.robot)();
            let mut rng = rng(seed * 31 + case.identifiable as u64);
            let truth = measured_robot(&nominal, &mut rng);
            let train = observe(&truth, &limits, 300, case.full_pose, sigma, sigma, &mut rng);
            let test = observe(&truth, &limits, 300, case.full_pose, sigma, sigma, &mut rng);
            let fit = calibrate(&nominal, &train, Scope::Full, &options).unwrap();
            let floor = mean_position_error(&truth, &test);
            let error = mean_position_error(&fit.model, &test);
            assert!(
                error <= 1.15 * floor,
                "{} seed {seed}: held-out {:.4} mm, noise floor {:.4} mm",
                case.name,
                error * 1e3,
                floor * 1e3
            );
        }
    }
}

#[test]
fn identifiable_parameter_counts_follow_chen_6_plus_4r() {
    for case in &CASES {
        let (nominal, limits) = (case.robot)();
        let mut rng = rng(200);
        let truth = measured_robot(&nominal, &mut rng);
        let train = observe(&truth, &limits, 80, case.full_pose, 0.0, 0.0, &mut rng);
        let fit = calibrate(&nominal, &train, Scope::Full, &IdentificationOptions::default()).unwrap();
        let report = &fit.report;
        assert_eq!(report.free_parameters, 6 * (limits.len() + 1), "{}", case.name);
        assert_eq!(report.rank, case.identifiable, "{}", case.name);
        assert_eq!(report.unidentifiable.len(), report.free_parameters - report.rank, "{}", case.name);
        assert!(!report.unidentifiable.iter().any(|r| matches!(r, Redundancy::Unexplained { .. })));
        assert!(report.condition_number.is_finite() && report.condition_number > 1.0);
    }
}

#[test]
fn base_tool_baseline_has_twelve_or_nine_identifiable_parameters() {
    for case in &CASES[..2] {
        let (nominal, limits) = (case.robot)();
        let mut rng = rng(300);
        let truth = measured_robot(&nominal, &mut rng);
        let train = observe(&truth, &limits, 60, case.full_pose, 0.0, 0.0, &mut rng);
        let fit = calibrate(&nominal, &train, Scope::BaseTool, &IdentificationOptions::default()).unwrap();
        let expected = if case.full_pose { 12 } else { 9 };
        assert_eq!(fit.report.free_parameters, 12);
        assert_eq!(fit.report.rank, expected, "{}", case.name);
        // Kinematic errors remain: the baseline cannot reach the noise-free truth.
        assert!(mean_position_error(&fit.model, &train) > 1e-5);
    }
}

#[test]
fn levenberg_marquardt_reaches_the_same_solution_as_the_pseudo_inverse() {
    let (nominal, limits) = irb4400();
    let mut rng = rng(400);
    let truth = measured_robot(&nominal, &mut rng);
    let train = observe(&truth, &limits, 100, true, 0.0, 0.0, &mut rng);
    let test = observe(&truth, &limits, 50, true, 0.0, 0.0, &mut rng);
    let options = IdentificationOptions { solver: Solver::LevenbergMarquardt, ..Default::default() };
    let fit = calibrate(&nominal, &train, Scope::Full, &options).unwrap();
    assert!(mean_position_error(&fit.model, &test) < 1e-9);
}

#[test]
fn each_tool_gets_its_own_transform_and_the_arm_is_shared() {
    let (nominal, limits) = irb4400();
    let mut rng = rng(500);
    let truth = measured_robot(&nominal, &mut rng);
    let second = SE3::new(SO3::exp(&Vector3::new(0.2, -0.1, 0.4)), Vector3::new(0.05, -0.1, 0.25));
    let mut truth2 = truth.clone();
    truth2.set_tools(vec![truth.tools()[0], truth.tools()[0] * second]);
    let mut observations = Vec::new();
    for i in 0..160 {
        let q = common::random_q(&mut rng, &limits);
        let tool = i % 2;
        let p = truth2.forward(&q, tool).unwrap().translation();
        observations.push(Observation { q, tool, target: Target::Point(p), stated_sigma: None });
    }
    let fit = calibrate(&nominal, &observations, Scope::Full, &IdentificationOptions::default()).unwrap();
    assert_eq!(fit.model.tool_count(), 2);
    for tool in 0..2 {
        let q = common::random_q(&mut rng, &limits);
        let expected = truth2.forward(&q, tool).unwrap().translation();
        let got = fit.model.forward(&q, tool).unwrap().translation();
        assert!((expected - got).norm() < 1e-9, "tool {tool}");
    }
}

#[test]
fn a_fixed_block_is_left_untouched() {
    let (nominal, limits) = irb4400();
    let mut rng = rng(600);
    let truth = measured_robot(&nominal, &mut rng);
    let train = observe(&truth, &limits, 80, true, 0.0, 0.0, &mut rng);
    let start = calibrate(&nominal, &train, Scope::BaseTool, &IdentificationOptions::default()).unwrap().model;
    let mut mask = ParameterMask::all(start.layout());
    mask.set_block(start.layout(), Block::Joint(2), false);
    let fit = identify(&start, &train, &mask, &IdentificationOptions::default()).unwrap();
    assert_eq!(fit.model.joints()[2], start.joints()[2]);
    assert_ne!(fit.model.joints()[1], start.joints()[1]);
}

#[test]
fn identify_refuses_a_mask_of_the_wrong_length() {
    let (nominal, _) = irb4400();
    let mask = ParameterMask::from_flags(vec![true; 5]);
    let observation =
        Observation { q: vec![0.0; 6], tool: 0, target: Target::Point(Vector3::zeros()), stated_sigma: None };
    assert_eq!(
        identify(&nominal, &[observation], &mask, &IdentificationOptions::default()).unwrap_err(),
        poe::Error::MaskLength { given: 5, expected: 42 }
    );
}

#[test]
fn registration_refuses_too_few_rows() {
    let (nominal, _) = irb4400();
    let mut rng = rng(700);
    let observation = Observation {
        q: vec![0.0; 6],
        tool: 0,
        target: Target::Point(Vector3::new(gaussian(&mut rng), 0.0, 0.0)),
        stated_sigma: None,
    };
    assert!(matches!(
        calibrate(&nominal, &[observation], Scope::Full, &IdentificationOptions::default()),
        Err(poe::Error::TooFewForRegistration { observations: 1, needed: 13 })
    ));
}

/// One row a metre off among 300 good ones is named and left out, so that the model's
/// held-out error stays within 1.2 times that of the fit without it; under plain least squares
/// the same row spoils the model (the test can fail), and on clean data the robust loss changes
/// nothing.
#[test]
fn a_row_a_metre_off_is_named_and_left_out_and_clean_data_is_plain_least_squares() {
    let sigma = 2e-5;
    let plain = IdentificationOptions {
        position_sigma_m: sigma,
        rotation_sigma_rad: sigma,
        robust: RobustOptions { loss: Loss::Squared, ..RobustOptions::default() },
        ..Default::default()
    };
    let robust = IdentificationOptions { robust: RobustOptions::default(), ..plain.clone() };
    for case in &CASES {
        let (nominal, limits) = (case.robot)();
        let mut rng = rng(31 + case.identifiable as u64);
        let truth = measured_robot(&nominal, &mut rng);
        let clean = observe(&truth, &limits, 300, case.full_pose, sigma, sigma, &mut rng);
        let test = observe(&truth, &limits, 300, case.full_pose, sigma, sigma, &mut rng);
        let mut dirty = clean.clone();
        let moved = Vector3::new(0.6, -0.8, 0.0);
        dirty[17].target = match dirty[17].target {
            Target::Pose(t) => Target::Pose(SE3::new(t.rotation(), t.translation() + moved)),
            Target::Point(p) => Target::Point(p + moved),
        };
        let reference = calibrate(&nominal, &clean, Scope::Full, &plain).unwrap();
        let on_clean = calibrate(&nominal, &clean, Scope::Full, &robust).unwrap();
        assert_eq!(on_clean.model, reference.model, "{}: the robust loss moved a clean fit", case.name);
        assert!(on_clean.report.robust.outliers.is_empty() && on_clean.report.robust.reweightings == 0);
        let fit = calibrate(&nominal, &dirty, Scope::Full, &robust).unwrap();
        let named: Vec<usize> = fit.report.robust.outliers.iter().map(|o| o.observation).collect();
        assert_eq!(named, [17], "{}", case.name);
        assert!((fit.report.robust.outliers[0].position_m - 1.0).abs() < 1e-3, "{:?}", fit.report.robust);
        assert!(fit.report.robust.settled && fit.report.converged, "{}: {:?}", case.name, fit.report.robust);
        let (reference_error, error) =
            (mean_position_error(&reference.model, &test), mean_position_error(&fit.model, &test));
        assert!(error <= 1.2 * reference_error, "{}: {error:e} against {reference_error:e}", case.name);
        let spoiled = calibrate(&nominal, &dirty, Scope::Full, &plain).unwrap();
        assert_eq!(spoiled.report.robust.outliers.len(), 1, "{}: least squares names it too", case.name);
        let spoiled_error = mean_position_error(&spoiled.model, &test);
        assert!(spoiled_error > 3.0 * reference_error, "{}: {spoiled_error:e} against {reference_error:e}", case.name);
    }
}
