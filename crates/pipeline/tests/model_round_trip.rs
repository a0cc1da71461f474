//! Every model `fit` writes, `eval` reads. `calib fit --method poe-gp-load --effects
//! auto` on a 7-axis campaign wrote a model that the check on reading refused (it probed the GP at
//! every joint at 1 rad, far from the wrist's 2 mrad). Over methods × effects × data shapes, the
//! model written by `write_model` reads back with `read_model` and predicts the same poses.

use campaign::{
    Effects, GeneratorConfig, Perturbation, Remount, TrackerNoise, joint_ranges, paper_effects, payload_run_campaign,
    simulate, simulate_campaign, simulated_cell,
};
use effects::EffectSelection;
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use robot::RobotDescription;

/// A data shape: its robot, its rows, and an explicit effects list that fits it.
struct Shape {
    name: &'static str,
    robot: RobotDescription,
    data: MeasurementSet,
    effects: &'static str,
}

const ROWS: usize = 100;

fn shapes() -> Vec<Shape> {
    let effects = Effects { tracker_noise: Some(TrackerNoise::default()), ..paper_effects() };
    let iiwa = testkit::robot("iiwa7.ron");
    // A real 7-axis campaign's shape: joints 1–2 moving, the others within 2 mrad of 0, four payload
    // runs with a tool each, measured torques; full pose and position only.
    let campaign = |full_pose: bool| {
        let config = payload_run_campaign(ROWS, 23);
        simulate_campaign(&iiwa, &effects, &Perturbation::default(), &Remount::default(), &config, full_pose).unwrap().1
    };
    // Every joint moving, one tool, no torques: the paper's shape.
    let irb = testkit::robot("irb4400.ron");
    let cell = simulated_cell(&irb, &Perturbation::default(), 23).unwrap();
    let config = GeneratorConfig { sample_count: ROWS, seed: 23, ..GeneratorConfig::default() };
    let paper = simulate(&cell, &effects, &joint_ranges(&irb), &config, false).unwrap();
    vec![
        Shape {
            name: "7-axis campaign, full pose",
            robot: iiwa.clone(),
            data: campaign(true),
            effects: "joint_compliance",
        },
        Shape {
            name: "7-axis campaign, positions",
            robot: iiwa.clone(),
            data: campaign(false),
            effects: "joint_compliance,gear_periodic:1:1",
        },
        Shape { name: "6-axis, all joints moving, positions", robot: irb, data: paper, effects: "gear_periodic:2:1" },
    ]
}

const METHODS: [Method; 4] = [Method::BaseTool, Method::Poe, Method::PoeGp, Method::PoeGpLoad];

/// Every pair of shape and method, shape and effects, method and effects, in 12 fits of the 36
/// (the effects list rotates with shape and method); the first shape's `poe-gp-load --effects
/// auto` is the fullest model a fit writes.
#[test]
fn every_method_shape_and_effects_pair_writes_reads_back_and_predicts_the_same() {
    let dir = tempfile::tempdir().unwrap();
    for (i, shape) in shapes().iter().enumerate() {
        for (j, method) in METHODS.into_iter().enumerate() {
            let effects = ["auto", shape.effects, ""][(i + j) % 3];
            round_trip(shape, method, effects, dir.path());
        }
    }
}

/// All 36 fits of methods × effects × data shapes: the test above covers each pair of them in a
/// third of the time, so `cargo xtask long-tests` runs this and CI does not.
#[test]
#[ignore = "long (every combination of the pairs the test above covers): cargo xtask long-tests"]
fn every_model_fit_writes_reads_back_and_predicts_the_same() {
    let dir = tempfile::tempdir().unwrap();
    for shape in shapes() {
        for method in METHODS {
            for effects in ["", "auto", shape.effects] {
                round_trip(&shape, method, effects, dir.path());
            }
        }
    }
}

/// Fits `shape` with `method` and `effects` ("" for none), writes the model, reads it back and
/// checks that both predict the same poses.
fn round_trip(shape: &Shape, method: Method, effects: &str, dir: &std::path::Path) {
    let case = format!("{} / {method} / effects '{effects}'", shape.name);
    let selection: EffectSelection = if effects.is_empty() { EffectSelection::None } else { effects.parse().unwrap() };
    let options = FitOptions::default().with_effects(selection);
    let (model, _) = pipeline::fit(&shape.robot, &shape.data, method, &options)
        .unwrap_or_else(|e| panic!("{case}: fit refused: {e}"));
    let path = dir.join("m.ron");
    model::write_model(&path, &model).unwrap();
    let again = model::read_model(&path).unwrap_or_else(|e| panic!("{case}: eval would refuse: {e}"));
    assert_rewritten_as_read(&path, &again, &case);
    let bound = model.bind(&shape.data).unwrap();
    let before = model.predict(&bound).unwrap();
    let after = again.predict(&bound).unwrap();
    for (a, b) in before.iter().zip(&after) {
        let moved = (a.pose.translation() - b.pose.translation()).norm();
        assert!(moved < 1e-10, "{case}: {moved} m apart after reading back");
    }
}

/// The model read from `path`, written again, is the file's bytes (quaternions
/// differed in the last digit).
fn assert_rewritten_as_read(path: &std::path::Path, read: &model::CalibratedModel, case: &str) {
    let written = std::fs::read_to_string(path).unwrap();
    let again = model::model_text(read, "m.ron").unwrap() + "\n";
    if again != written {
        let (a, b) = written.lines().zip(again.lines()).find(|(a, b)| a != b).unwrap_or_default();
        panic!("{case}: written again differs: {a:?} became {b:?}");
    }
}

/// Every fixture robot's model (geometry and joint compliance; the GP's numbers are plain
/// floats, and the test above writes GP models again too) written, read and written again: the
/// same bytes.
#[test]
fn every_fixture_s_model_is_written_again_as_it_was_read() {
    let dir = tempfile::tempdir().unwrap();
    // Not every fixture has the stiffnesses the paper's compliance needs: noise alone.
    let effects = Effects { tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
    let mut fixtures: Vec<String> = std::fs::read_dir(testkit::robot_path(""))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    fixtures.sort();
    assert!(fixtures.len() >= 11, "{fixtures:?}");
    for name in fixtures {
        let robot = testkit::robot(&name);
        let cell = simulated_cell(&robot, &Perturbation::default(), 48).unwrap();
        let config = GeneratorConfig { sample_count: 40, seed: 48, ..GeneratorConfig::default() };
        let data = simulate(&cell, &effects, &joint_ranges(&robot), &config, true).unwrap();
        let options = FitOptions::default().with_effects("joint_compliance".parse().unwrap());
        let (model, _) =
            pipeline::fit(&robot, &data, Method::Poe, &options).unwrap_or_else(|e| panic!("{name}: fit refused: {e}"));
        let path = dir.path().join("m.ron");
        model::write_model(&path, &model).unwrap();
        let read = model::read_model(&path).unwrap_or_else(|e| panic!("{name}: read refused: {e}"));
        assert_rewritten_as_read(&path, &read, &name);
    }
}

#[test]
fn a_model_file_without_a_training_range_still_reads() {
    let shape = shapes().remove(0);
    let (model, _) = pipeline::fit(&shape.robot, &shape.data, Method::PoeGpLoad, &FitOptions::default()).unwrap();
    let older = model::CalibratedModel { training_range: None, ..model };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.ron");
    model::write_model(&path, &older).unwrap();
    assert!(!std::fs::read_to_string(&path).unwrap().contains("training_range"));
    let again = model::read_model(&path).unwrap();
    assert_eq!(again.training_range, None);
}

/// A `poe-gp-load` model of the 7-axis campaign (`shapes()`'s first) with joint compliance, and
/// its file text.
fn campaign_model() -> (model::CalibratedModel, String) {
    let shape = shapes().remove(0);
    let options = FitOptions::default().with_effects("joint_compliance".parse().unwrap());
    let (model, _) = pipeline::fit(&shape.robot, &shape.data, Method::PoeGpLoad, &options).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.ron");
    model::write_model(&path, &model).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    (model, text)
}

/// `text` with the first number after `field: ` (or `field: [`) replaced by `value`.
fn with_first(text: &str, field: &str, value: &str) -> String {
    let at = text.find(&format!("{field}: ")).unwrap_or_else(|| panic!("no {field}"));
    let first = at + text[at..].find(|c: char| c == '-' || c.is_ascii_digit()).unwrap();
    let end = first + text[first..].find([',', ')', ']']).unwrap();
    format!("{}{value}{}", &text[..first], &text[end..])
}

/// The refusal of `text`, checked to name the file and a line past the first.
fn refused_at_a_line(text: &str, case: &str) -> String {
    let message = match model::parse_model(text, "m.ron") {
        Ok(_) => panic!("{case}: read, not refused"),
        Err(e) => e.to_string(),
    };
    let line: usize = message.split(':').nth(1).and_then(|l| l.parse().ok()).unwrap_or(0);
    assert!(message.starts_with("m.ron:") && line > 1, "{message}");
    message
}

#[test]
fn absurd_finite_values_are_still_refused_at_a_line_and_column() {
    let (_, text) = campaign_model();
    model::parse_model(&text, "m.ron").unwrap();
    for (field, value) in [
        ("signal_variance", "1e200"),
        ("noise_variance", "1e200"),
        ("length_scales", "1e200"),
        ("length_scales", "1e-200"),
        ("training_outputs", "1e308"),
        ("translation", "1e9"),
    ] {
        let message = refused_at_a_line(&with_first(&text, field, value), &format!("{field} = {value}"));
        eprintln!("{field} = {value}: {message}");
    }
}

#[test]
fn an_edited_training_range_is_refused_at_its_field() {
    let (_, text) = campaign_model();
    for value in ["1e9", "inf", "NaN"] {
        let message = refused_at_a_line(&with_first(&text, "training_range", value), value);
        assert!(message.contains("training_range"), "{value}: {message}");
    }
}
