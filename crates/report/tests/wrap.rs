//! Rows a turn away from the fitted range: the report applies the model at the wrapped angles, as
//! `calib eval` does, and gives the numbers it gives for the same rows a turn back.

use campaign::{GeneratorConfig, Perturbation, joint_ranges, simulate, simulated_cell};
use loadsim::{Effects, TrackerNoiseModel};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;

#[test]
fn rows_a_turn_away_are_reported_at_the_wrapped_angles() {
    let robot = testkit::robot("ur10.ron");
    let cell = simulated_cell(&robot, &Perturbation::default(), 4).unwrap();
    let mut ranges = joint_ranges(&robot);
    // Joint 1 within ±170°: a turn on, every angle lies outside, within the ±360° limits.
    ranges[0].lower_rad = -170f64.to_radians();
    ranges[0].upper_rad = 170f64.to_radians();
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..Effects::default() };
    let config = GeneratorConfig { sample_count: 160, seed: 4, ..GeneratorConfig::default() };
    let all = simulate(&cell, &effects, &ranges, &config, true).unwrap();
    let train = all.subset(&(0..110).collect::<Vec<_>>());
    let (model, _) = pipeline::fit(&robot, &train, Method::PoeGp, &FitOptions::default()).unwrap();
    let [low, high] = model.training_range.as_ref().unwrap().q[0];
    let inside: Vec<usize> = (110..160).filter(|&i| (low..=high).contains(&all.rows[i].q[0])).collect();
    assert!(inside.len() > 30, "{} rows", inside.len());
    let test = all.subset(&inside);
    let mut turned: MeasurementSet = test.clone();
    for row in &mut turned.rows {
        row.q[0] += if row.q[0] < 0.0 { std::f64::consts::TAU } else { -std::f64::consts::TAU };
    }
    let build = |data: &MeasurementSet| {
        let inputs = report::ReportInputs {
            model: &model,
            model_file: "model.ron",
            robot: &robot,
            robot_file: "ur10.ron",
            data,
            training: None,
        };
        report::Report::build(&inputs, None, &report::ReportOptions::default()).unwrap()
    };
    let (given, away) = (build(&test), build(&turned));
    // Other joints may be wrapped too (sampled over their ±360°), alike in both.
    let joint_1 = |r: &report::Report| r.eval.wrapped.iter().find(|w| w.joint == 1).map(|w| w.rows_wrapped);
    assert_eq!((joint_1(&given), joint_1(&away)), (None, Some(inside.len())), "{:?}", away.eval.wrapped);
    let (a, b) = (given.eval.errors.mean_position_error_mm, away.eval.errors.mean_position_error_mm);
    assert!((a - b).abs() < 1e-9, "{a} mm against {b} mm a turn away");
    assert!(away.eval.out_of_range.iter().all(|w| w.input != "joint 1"), "{:?}", away.eval.out_of_range);
    // The rows keep the angles given.
    assert_eq!(away.rows[0].q[0], turned.rows[0].q[0]);
}
