//! A linear axis driven by a ball screw errs periodically in its own position, with the
//! screw's lead as period. Simulated on the column of `column_ur10.ron` (a 10 mm lead, 2.5 m of
//! lift) with the tracker's noise, `screw_periodic` takes the held-out error to the noise where the
//! geometry alone cannot, its parameters are reported in mm, its model file reads back, a bad item
//! is refused, and the diagnosis offers it only where the robot file states the pitch.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoiseModel, joint_ranges, simulate, simulated_cell};
use diagnose::{DiagnoseOptions, Effect, diagnose};
use effects::{EffectSelection, IdentifiedEffect};
use loadsim::{ScrewHarmonic, ScrewPeriodicModel};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use robot::RobotDescription;

/// The column's screw: a 10 mm lead, 50 µm once per turn and 20 µm twice (a rolled screw's
/// periodic deviation; ISO 3408-3 allows a ground class-10 screw 40 µm per turn).
fn screw() -> ScrewPeriodicModel {
    let harmonic = |order: f64, amplitude_m: f64, phase_rad: f64| ScrewHarmonic {
        joint_index: 0,
        pitch_m: 0.010,
        order,
        amplitude_m,
        phase_rad,
    };
    ScrewPeriodicModel { harmonics: vec![harmonic(1.0, 50e-6, 0.4), harmonic(2.0, 20e-6, -1.1)] }
}

/// 500 poses with `effects` and the tracker's noise, position only: 300 to train on, 200 held out.
fn split(robot: &RobotDescription, effects: &Effects, seed: u64) -> (MeasurementSet, MeasurementSet) {
    let cell = simulated_cell(robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: 500, seed, ..GeneratorConfig::default() };
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..effects.clone() };
    let all = simulate(&cell, &effects, &joint_ranges(robot), &config, false).unwrap();
    (all.subset(&(0..300).collect::<Vec<_>>()), all.subset(&(300..500).collect::<Vec<_>>()))
}

fn fit(
    robot: &RobotDescription,
    train: &MeasurementSet,
    selection: &str,
) -> (model::CalibratedModel, pipeline::FitReport) {
    let selection = if selection.is_empty() { EffectSelection::None } else { selection.parse().unwrap() };
    let options = FitOptions::default().with_effects(selection);
    pipeline::fit(robot, train, Method::Poe, &options).unwrap_or_else(|e| panic!("{e}"))
}

fn heldout(model: &model::CalibratedModel, test: &MeasurementSet) -> f64 {
    model::evaluate(model, &model.bind(test).unwrap()).unwrap().summary.mean_position_error_mm
}

#[test]
fn a_screw_error_is_identified_down_to_the_noise_and_its_model_file_reads_back() {
    let robot = testkit::robot("column_ur10.ron");
    for seed in [51, 52] {
        let (train, test) = split(&robot, &Effects { screw_periodic: Some(screw()), ..Effects::default() }, seed);
        let (quiet_train, quiet_test) = split(&robot, &Effects::default(), seed);
        let floor = heldout(&fit(&robot, &quiet_train, "").0, &quiet_test);
        let poe = heldout(&fit(&robot, &train, "").0, &test);
        let (model, report) = fit(&robot, &train, "screw_periodic:1:10:4");
        let with = heldout(&model, &test);
        eprintln!("seed {seed}: poe {poe:.4} mm, screw_periodic:1:10:4 {with:.4} mm, noise alone {floor:.4} mm");
        assert!(poe > 1.3 * floor, "seed {seed}: the screw is not visible: poe {poe} mm, noise {floor} mm");
        assert!(with < 1.2 * floor, "seed {seed}: screw_periodic {with} mm against the noise's {floor} mm");

        // Reported in mm, the model file's metres; the once-per-turn amplitude found.
        let reported = report.effects.iter().find(|e| e.effect == "screw_periodic").unwrap();
        assert_eq!(reported.label, "screw_periodic:1:10:4");
        assert!(reported.parameters.iter().all(|p| p.unit == "mm"), "{:?}", reported.parameters);
        let Some(IdentifiedEffect::ScrewPeriodic(fitted)) = model.effects.first() else {
            panic!("{:?}", model.effects)
        };
        let amplitude =
            (0..100).map(|k| fitted.position_error(1.0 + 0.01 * f64::from(k) / 100.0).abs()).fold(0.0, f64::max);
        assert!((amplitude - 65e-6).abs() < 15e-6, "seed {seed}: largest fitted error {amplitude} m");

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.ron");
        model::write_model(&path, &model).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("screw_periodic(") && text.contains("pitch_m: 0.01"), "{text}");
        let again = model::read_model(&path).unwrap();
        let bound = model.bind(&test).unwrap();
        for (a, b) in model.predict(&bound).unwrap().iter().zip(&again.predict(&bound).unwrap()) {
            assert!((a.pose.translation() - b.pose.translation()).norm() < 1e-10);
        }
        // A pitch of zero in the file is refused at its line.
        let at = text.find("pitch_m: 0.01").unwrap();
        let bad = format!("{}pitch_m: 0.0{}", &text[..at], &text[at + "pitch_m: 0.01".len()..]);
        let message = model::parse_model(&bad, "m.ron").map(|_| ()).unwrap_err().to_string();
        let line = text[..at].lines().count();
        assert!(message.starts_with(&format!("m.ron:{line}:")) && message.contains("pitch_m"), "{message}");
    }
}

#[test]
fn bad_screw_items_are_refused_with_what_is_wrong() {
    let robot = testkit::robot("column_ur10.ron");
    let (train, _) = split(&robot, &Effects::default(), 53);
    let refuse = |item: &str| {
        let options = FitOptions::default().with_effects(item.parse().unwrap());
        pipeline::fit(&robot, &train, Method::Poe, &options).map(|_| ()).unwrap_err().to_string()
    };
    let message = refuse("screw_periodic:2:10:4");
    assert!(message.contains("joint 2 is revolute") && message.contains("gear_periodic:JOINT:HARMONICS"), "{message}");
    let message = refuse("gear_periodic:1:4");
    assert!(message.contains("joint 1 is prismatic") && message.contains("screw_periodic:JOINT:PITCH_MM"), "{message}");
    let message = refuse("screw_periodic:9:10:4");
    assert!(message.contains("joint 9"), "{message}");
    let message = "screw_periodic:1:0.001:4".parse::<EffectSelection>().unwrap_err().to_string();
    assert!(message.starts_with("--effects:1:1: 'screw_periodic:1:0.001:4'") && message.contains("pitch"), "{message}");
}

#[test]
fn the_diagnosis_offers_the_screw_only_where_the_pitch_is_known_and_names_it() {
    let mut robot = testkit::robot("column_ur10.ron");
    let (train, test) = split(&robot, &Effects { screw_periodic: Some(screw()), ..Effects::default() }, 54);
    let options = DiagnoseOptions::default();
    let unknown = diagnose(&robot, &train, &options).unwrap();
    assert!(!unknown.candidates.iter().any(|c| c.effect == Effect::ScrewPeriodic), "{}", unknown.summary());

    robot.joints[0].pitch_mm = Some(10.0);
    let diagnosis = diagnose(&robot, &train, &options).unwrap();
    eprintln!("{}", diagnosis.summary());
    assert_eq!((diagnosis.verdict.effect, diagnosis.verdict.joints.as_slice()), (Effect::ScrewPeriodic, &[1][..]));
    // Only the column gets one: the arm's joints are revolute.
    assert!(diagnosis.candidates.iter().filter(|c| c.effect == Effect::ScrewPeriodic).all(|c| c.joints == [1]));
    let (auto, report) = fit(&robot, &train, "auto");
    let chosen = report.auto.as_ref().unwrap().chosen.iter().map(ToString::to_string).collect::<Vec<_>>();
    let (quiet_train, quiet_test) = split(&robot, &Effects::default(), 54);
    let floor = heldout(&fit(&robot, &quiet_train, "").0, &quiet_test);
    let with = heldout(&auto, &test);
    eprintln!("auto chose {chosen:?}: {with:.4} mm held out, noise alone {floor:.4} mm");
    assert!(chosen.iter().any(|c| c.starts_with("screw_periodic:1:10:")), "{chosen:?}");
    assert!(chosen.iter().all(|c| c.parse::<EffectSelection>().is_ok()), "{chosen:?}");
    assert!(with < 1.2 * floor, "--effects auto {with} mm against the noise's {floor} mm");
}
