//! The effects on a prismatic joint read in its units. A lifting column's backlash is
//! a half band in mm and its compliance is along the axis under the force, where a revolute
//! joint's are in rad under a torque; the model file keeps SI units either way.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoise, joint_ranges, simulate, simulated_cell};
use effects::IdentifiedEffect;
use loadsim::{Backlash, JointBacklash};
use model::Method;
use pipeline::FitOptions;

#[test]
fn a_prismatic_joints_backlash_and_compliance_are_reported_in_mm_under_a_force() {
    // column_arm.urdf: joint 1 is the lifting column (prismatic), joint 3 the UR10's shoulder.
    let robot = testkit::robot("column_arm.urdf");
    let backlash = Backlash { joints: vec![JointBacklash { joint_index: 2, half_band_rad: 1e-4 }] };
    let effects =
        Effects { backlash: Some(backlash), tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
    let cell = simulated_cell(&robot, &Perturbation::default(), 8).unwrap();
    let config = GeneratorConfig { sample_count: 200, seed: 8, ..GeneratorConfig::default() };
    let data = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();
    let options = FitOptions::default().with_effects("backlash:1,backlash:3,joint_compliance".parse().unwrap());
    let (model, report) = pipeline::fit(&robot, &data, Method::Poe, &options).unwrap_or_else(|e| panic!("{e}"));
    let json: serde_json::Value = serde_json::to_value(&report.effects).unwrap();
    eprintln!("{}", serde_json::to_string_pretty(&json[0]).unwrap());
    eprintln!("{}", serde_json::to_string_pretty(&json[1]).unwrap());

    let theta = |joint: usize| {
        model
            .effects
            .iter()
            .find_map(|e| match e {
                IdentifiedEffect::Backlash(b) if b.joint == joint => Some(e.theta()[0]),
                _ => None,
            })
            .unwrap()
    };
    let column = report.effects.iter().find(|e| e.effect == "backlash" && e.joints == [1]).unwrap();
    assert!(column.label.contains("force") && !column.label.contains("torque"), "{}", column.label);
    let half_band = &column.parameters[0];
    assert_eq!((half_band.name.as_str(), half_band.unit), ("joint 1 half band", "mm"));
    assert_eq!(half_band.value, theta(0) * 1e3, "the model file's metres, shown in mm");
    let shoulder = report.effects.iter().find(|e| e.effect == "backlash" && e.joints == [3]).unwrap();
    assert!(shoulder.label.contains("torque"), "{}", shoulder.label);
    assert_eq!((shoulder.parameters[0].unit, shoulder.parameters[0].value), ("rad", theta(2)));
    // The simulated 0.1 mrad half band of the shoulder is found (its sign changes over the poses).
    assert!((shoulder.parameters[0].value.abs() - 1e-4).abs() < 3e-5, "{:?}", shoulder.parameters[0]);

    // Compliance of every joint: the column's terms along its axis under a force, in mm; the arm's in rad.
    let compliance = report.effects.iter().find(|e| e.effect == "joint_compliance").unwrap();
    assert!(compliance.label.contains("torque"), "a label over revolute joints too: {}", compliance.label);
    let (column, arm): (Vec<_>, Vec<_>) = compliance.parameters.iter().partition(|p| p.name.starts_with("joint 1 "));
    assert!(!column.is_empty() && !arm.is_empty());
    for p in &column {
        assert!(p.unit == "mm" && p.name.contains("force") && !p.name.contains("torque"), "{p:?}");
    }
    for p in &arm {
        assert!(p.unit == "rad" && p.name.contains("torque"), "{p:?}");
    }
}
