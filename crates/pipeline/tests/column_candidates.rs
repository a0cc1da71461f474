//! No candidate without meaning on a joint kind. A lifting column carries the weight of
//! everything above it, so the gravity force along its axis never changes sign: a backlash term
//! there is `b · sign(F)`, one constant over every pose, a joint offset the geometry already
//! holds. The diagnosis does not offer it (nor `--effects auto` pick it), while a shoulder whose
//! torque changes sign keeps its backlash candidate.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoise, joint_ranges, simulate, simulated_cell};
use diagnose::{DiagnoseOptions, Effect, diagnose};
use loadsim::{Backlash, JointBacklash, Payload};

#[test]
fn a_vertical_column_whose_force_never_changes_sign_is_offered_no_backlash() {
    let robot = testkit::robot("column_arm.urdf");
    // A backlash of the shoulder (joint 3, the UR10's joint 2) and of the column: the column's
    // band is a constant offset in the data, since its force keeps its sign.
    let backlash = Backlash {
        joints: vec![
            JointBacklash { joint_index: 0, half_band_rad: 2e-4 },
            JointBacklash { joint_index: 2, half_band_rad: 1e-4 },
        ],
    };
    let effects =
        Effects { backlash: Some(backlash), tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
    let cell = simulated_cell(&robot, &Perturbation::default(), 47).unwrap();
    let config = GeneratorConfig { sample_count: 250, seed: 47, ..GeneratorConfig::default() };
    let data = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();

    // The premise: the static force on the column has one sign on every row, the shoulder's
    // torque both.
    let dynamics = robot.dynamics.clone().expect("column_arm.urdf gives masses");
    let nominal = robot.nominal_model().unwrap();
    let signs = |joint: usize| -> (usize, usize) {
        data.rows.iter().fold((0, 0), |(plus, minus), row| {
            let payload = Payload::at_tool(row.payload_kg);
            let tau = loadsim::static_torque(&nominal, &dynamics, &row.q, 0, &payload).unwrap()[joint];
            (plus + usize::from(tau > 0.0), minus + usize::from(tau < 0.0))
        })
    };
    let (column, shoulder) = (signs(0), signs(2));
    eprintln!("static force on the column: {column:?} rows (+, −); shoulder torque: {shoulder:?}");
    assert!(column.0 == 0 || column.1 == 0, "the column's force changed sign: {column:?}");
    assert!(shoulder.0 > 0 && shoulder.1 > 0, "the shoulder's torque kept its sign: {shoulder:?}");

    let diagnosis = diagnose(&robot, &data, &DiagnoseOptions::default()).unwrap();
    let on_column: Vec<String> = diagnosis
        .candidates
        .iter()
        .filter(|c| c.joints.contains(&1))
        .map(|c| format!("{} {:?}", c.effect.name(), c.joints))
        .collect();
    eprintln!("candidates on the column: {on_column:?}\n{}", diagnosis.summary());
    let backlash_on =
        |joint: usize| diagnosis.candidates.iter().any(|c| c.effect == Effect::Backlash && c.joints.contains(&joint));
    assert!(!backlash_on(1), "a backlash of the column is offered: {on_column:?}");
    // The paper's five payloads, drawn per pose, change the column's force: its axial compliance
    // is offered.
    assert!(
        diagnosis.candidates.iter().any(|c| c.effect == Effect::JointCompliance && c.joints.contains(&1)),
        "no compliance of the column with five payloads: {on_column:?}"
    );
    assert!(backlash_on(3), "the shoulder's backlash is not offered:\n{}", diagnosis.summary());
    assert!(
        !diagnosis.selected.iter().any(|s| s.effect == Effect::Backlash && s.joints.contains(&1)),
        "{}",
        diagnosis.summary()
    );

    // Named in `--effects`, the column's backlash is fitted, with a warning that it means nothing.
    let options = pipeline::FitOptions::default().with_effects("backlash:1,backlash:3".parse().unwrap());
    let (_, report) = pipeline::fit(&robot, &data, model::Method::Poe, &options).unwrap();
    let constant: Vec<&str> = report
        .warnings
        .iter()
        .filter_map(|w| match w {
            pipeline::FitWarning::ConstantEffect { effect } => Some(effect.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(constant.len(), 1, "{:?}", report.warnings);
    assert!(constant[0].starts_with("backlash:1 "), "{constant:?}");
    assert!(report.warnings.iter().any(|w| w.to_string().contains("its parameters mean nothing; leave it out")));
}

/// With one payload the column's force is the same weight on every row: its axial compliance is
/// then one constant offset, like the backlash, and is not offered (the filter is on features
/// that never change, not on the joint's kind: with several payloads it is, test above).
#[test]
fn a_column_carrying_one_payload_is_offered_no_compliance() {
    let robot = testkit::robot("column_arm.urdf");
    let effects = Effects { tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
    let cell = simulated_cell(&robot, &Perturbation::default(), 48).unwrap();
    let config = GeneratorConfig { sample_count: 150, seed: 48, payloads_kg: vec![5.0], ..GeneratorConfig::default() };
    let data = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();
    let diagnosis = diagnose(&robot, &data, &DiagnoseOptions::default()).unwrap();
    let on = |effect: Effect, joint: usize| {
        diagnosis.candidates.iter().any(|c| c.effect == effect && c.joints.contains(&joint))
    };
    assert!(!on(Effect::JointCompliance, 1), "{}", diagnosis.summary());
    // The shoulder's compliance, whose torque changes with the arm's pose, stays.
    assert!(on(Effect::JointCompliance, 3), "{}", diagnosis.summary());
}
