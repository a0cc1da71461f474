//! A drift fitted on some measuring sessions and used on a later one is either held at
//! the end of its span or falls back to the geometry, chosen by leaving one training session out at
//! a time. Simulated: four sessions on days 0, 1, 3 and 8, each with the placement drifting from
//! its own start and an offset of its own; fitted on the first three, evaluated on the fourth.
//! Where the offsets scatter (a tracker re-sighted each day) the geometry's average placement is
//! nearer the next session, and zero is chosen; where they trend (a foundation settling) the end of
//! the span is nearer, and the hold is chosen. Either way the choice beats the other rule on the
//! later session and `time_drift` (and `--effects auto`) is no worse than without it.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoiseModel, joint_ranges, simulate, simulated_cell};
use effects::{BeyondSpan, EffectSelection, IdentifiedEffect};
use loadsim::TimeDriftModel;
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use robot::RobotDescription;

const DAY_S: f64 = 86_400.0;
const DAYS: [f64; 4] = [0.0, 1.0, 3.0, 8.0];

/// The four sessions (120 poses each, 30 s apart) with the placement offset by `offsets_mm[k]` in
/// session `k`: the first three joined to train on, the last to evaluate.
fn campaign(robot: &RobotDescription, offsets_mm: [[f64; 3]; 4], seed: u64) -> (MeasurementSet, MeasurementSet) {
    let effects = Effects {
        time_drift: Some(TimeDriftModel { twist_per_s: [2e-8, -1.5e-8, 1e-8, 0.0, 0.0, 0.0] }),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    let cell = simulated_cell(robot, &Perturbation::default(), seed).unwrap();
    let session = |k: usize| {
        let config = GeneratorConfig { sample_count: 120, seed: seed + k as u64, ..GeneratorConfig::default() };
        let mut set = simulate(&cell, &effects, &joint_ranges(robot), &config, false).unwrap();
        let offset = lie::Vector3::from(offsets_mm[k]) * 1e-3;
        for row in &mut set.rows {
            row.t_s = row.t_s.map(|t| t + DAYS[k] * DAY_S);
            row.position += offset;
        }
        set
    };
    let mut train = session(0);
    for k in 1..3 {
        train.rows.extend(session(k).rows);
    }
    (train, session(3))
}

fn fit(
    robot: &RobotDescription,
    train: &MeasurementSet,
    selection: &str,
) -> (model::CalibratedModel, pipeline::FitReport) {
    let selection = if selection.is_empty() { EffectSelection::None } else { selection.parse().unwrap() };
    pipeline::fit(robot, train, Method::Poe, &FitOptions::default().with_effects(selection))
        .unwrap_or_else(|e| panic!("{e}"))
}

fn error(model: &model::CalibratedModel, test: &MeasurementSet) -> f64 {
    model::evaluate(model, &model.bind(test).unwrap()).unwrap().summary.mean_position_error_mm
}

/// The model with its drift's rule beyond the span set to `rule`.
fn with_rule(model: &model::CalibratedModel, rule: BeyondSpan) -> model::CalibratedModel {
    let mut model = model.clone();
    for effect in &mut model.effects {
        if matches!(effect, IdentifiedEffect::TimeDrift(_)) {
            effect.set_beyond_span(rule);
        }
    }
    model
}

/// Fits `time_drift` and `auto` on the three sessions and checks them on the fourth; returns the
/// rule chosen for the drift.
fn check(offsets_mm: [[f64; 3]; 4], seed: u64) -> BeyondSpan {
    let robot = testkit::robot("irb4400.ron");
    let (train, test) = campaign(&robot, offsets_mm, seed);
    assert_eq!(pipeline::sessions(&train.rows, 20.0).len(), 3);
    let alone = error(&fit(&robot, &train, "").0, &test);
    let (drift, report) = fit(&robot, &train, "time_drift");
    let choice = &report.beyond_span[0];
    eprintln!("{choice}");
    assert_eq!((choice.effect.as_str(), choice.sessions), ("time_drift", 3));
    let chosen = error(&drift, &test);
    let other = error(&with_rule(&drift, choice.rule.other()), &test);
    let (auto, auto_report) = fit(&robot, &train, "auto");
    let auto_error = error(&auto, &test);
    let chosen_auto: Vec<String> = auto_report.auto.unwrap().chosen.iter().map(ToString::to_string).collect();
    eprintln!(
        "day 8: poe {alone:.4} mm; time_drift {} {chosen:.4} mm, {} {other:.4} mm; auto {chosen_auto:?} {auto_error:.4} mm",
        choice.rule.name(),
        choice.rule.other().name()
    );
    // The rule chosen on the training sessions is the better one on the later session too.
    assert!(chosen < other, "{} chosen: {chosen} mm against {other} mm", choice.rule.name());
    assert!(chosen <= 1.02 * alone, "time_drift {chosen} mm against {alone} mm without it");
    assert!(auto_error <= 1.02 * alone, "--effects auto {auto_error} mm against {alone} mm without it");
    choice.rule
}

#[test]
fn scattered_session_offsets_fall_back_to_the_geometry_beyond_the_span() {
    // A tracker re-sighted each day: offsets of 0.1-0.2 mm in any direction.
    let offsets = [[0.15, -0.10, 0.05], [-0.10, 0.12, -0.08], [0.12, 0.05, 0.10], [-0.05, -0.12, 0.02]];
    assert_eq!(check(offsets, 71), BeyondSpan::Zero);
}

#[test]
fn a_settling_cell_holds_the_drift_at_the_end_of_its_span() {
    // A foundation settling 0.1 mm a day along x (and a little along y and z).
    let offsets = DAYS.map(|d| [0.10 * d, -0.05 * d, 0.03 * d]);
    assert_eq!(check(offsets, 72), BeyondSpan::Hold);
}

#[test]
fn with_one_session_the_drift_is_dropped_and_a_later_session_gets_the_fit_without_effects() {
    let robot = testkit::robot("irb4400.ron");
    let (train, test) = campaign(&robot, [[0.0; 3]; 4], 73);
    let first: Vec<usize> = (0..120).collect();
    let (drift, report) = fit(&robot, &train.subset(&first), "time_drift");
    let choice = &report.beyond_span[0];
    assert_eq!((choice.rule, choice.sessions, choice.heldout_mm), (BeyondSpan::Drop, 1, None));
    assert!(choice.reason.starts_with("one session"), "{}", choice.reason);
    assert!(choice.reason.contains("nothing could decide"), "{}", choice.reason);
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["beyond_span"][0]["rule"], "drop");
    // On a later day the model is the geometry fitted alone, row for row (the rule's promise:
    // never worse there than the fit without effects); on its own session it is not.
    let alone = model::CalibratedModel {
        kinematics: drift.fallback_kinematics.clone().expect("a fit with effects keeps the geometry fitted alone"),
        ..drift.geometry_only()
    };
    let errors = |m: &model::CalibratedModel, set: &MeasurementSet| -> Vec<f64> {
        model::evaluate(m, &m.bind(set).unwrap()).unwrap().errors.iter().map(|e| e.position_mm).collect()
    };
    let (later, later_alone) = (errors(&drift, &test), errors(&alone, &test));
    for (a, b) in later.iter().zip(&later_alone) {
        assert!((a - b).abs() < 1e-9, "{a} mm against {b} mm with the geometry fitted alone");
    }
    let own = train.subset(&first);
    assert_ne!(errors(&drift, &own), errors(&alone, &own));
}
