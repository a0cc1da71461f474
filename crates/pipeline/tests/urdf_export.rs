//! `export_urdf`: the exported URDF, read back, has the calibrated model's forward kinematics to
//! 1e-9 m in the tracker and in the base frame; written like an existing URDF it keeps that file's
//! links and their meaning; what it cannot hold is measured or refused.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoiseModel};
use cell::{UrdfTemplate, export_urdf};
use lie::{SE3, Vector3};
use measurements::MeasurementSet;
use model::{CalibratedModel, Method};
use pipeline::FitOptions;
use poe::LocalPoe;
use robot::ErrorKind;
use robot::{ChainEnds, NominalTolerance, RobotDescription, UrdfDocument, in_base_frame};

/// Tracker data of a perturbed `robot` (noise only, so every method fits).
fn data(robot: &RobotDescription, rows: usize, full_pose: bool, seed: u64) -> MeasurementSet {
    let cell = campaign::simulated_cell(robot, &Perturbation::default(), seed).unwrap();
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..Effects::default() };
    let config = GeneratorConfig { sample_count: rows, seed, payloads_kg: vec![0.0], ..GeneratorConfig::default() };
    campaign::simulate(&cell, &effects, &campaign::joint_ranges(robot), &config, full_pose).unwrap()
}

fn fitted(robot: &RobotDescription, method: Method, full_pose: bool) -> (CalibratedModel, MeasurementSet) {
    let set = data(robot, 150, full_pose, 11);
    let (model, _) = pipeline::fit(robot, &set, method, &FitOptions::default()).unwrap();
    (model, set)
}

fn read_back(text: &str, base: &str, tip: &str) -> LocalPoe {
    let ends = ChainEnds { base_link: Some(base.into()), tip_link: Some(tip.into()) };
    let chain = UrdfDocument::parse(text, "out.urdf").unwrap().chain(&ends).unwrap_or_else(|e| panic!("{e}"));
    chain.description().nominal_model().unwrap()
}

fn configurations(n: usize) -> Vec<Vec<f64>> {
    (0..10).map(|k| (0..n).map(|j| ((k * 5 + j * 2) as f64 * 0.83).sin() * 2.0).collect()).collect()
}

/// Largest distance between the poses (origin and 1 m axes) of two models, one tool each.
fn largest_difference_m(a: &LocalPoe, a_tool: usize, b: &LocalPoe, b_tool: usize) -> f64 {
    let points = [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()];
    configurations(a.joint_count())
        .iter()
        .map(|q| {
            let (ta, tb): (SE3, SE3) = (a.forward(q, a_tool).unwrap(), b.forward(q, b_tool).unwrap());
            points.iter().map(|p| (ta.transform_point(p) - tb.transform_point(p)).norm()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_plain_export_reads_back_to_the_model_in_the_tracker_and_the_base_frame() {
    let irb = testkit::robot("irb4400.ron");
    let (model, _) = fitted(&irb, Method::Poe, true);
    let nominal = irb.nominal_model().unwrap();
    for description in [None, Some((&irb, "irb4400.ron"))] {
        let export =
            export_urdf(&model, UrdfTemplate::Plain { nominal: description }, None, &NominalTolerance::default())
                .unwrap();
        let tracker = read_back(&export.text, "tracker", "tool");
        let difference = largest_difference_m(&tracker, 0, &model.kinematics, 0);
        assert!(difference < 1e-9, "tracker frame: {difference:e} m");
        let base = read_back(&export.text, "base_link", "tool");
        let expected = in_base_frame(&model.kinematics, description.map(|_| &nominal));
        let difference = largest_difference_m(&base, 0, &expected, 0);
        assert!(difference < 1e-9, "base frame: {difference:e} m");
        assert_eq!(export.report.tool_links, ["tool"]);
        assert!(export.report.not_in_urdf.is_empty() && export.report.training_error.is_none());
    }
    // With the nominal description, joint 1 is the nominal joint 1 and the limits are written.
    let export = export_urdf(
        &model,
        UrdfTemplate::Plain { nominal: Some((&irb, "irb4400.ron")) },
        None,
        &NominalTolerance::default(),
    )
    .unwrap();
    let change = &export.report.axis_changes;
    assert_eq!(change.len(), 6);
    assert!(change[0].offset_mm < 1e-9 && change[0].angle_mrad < 1e-9, "{change:?}");
    assert!(change.iter().any(|c| c.offset_mm > 0.01), "{change:?}");
    let limits = RobotDescription::read_with(
        &write(&export.text),
        &ChainEnds { base_link: None, tip_link: Some("tool".into()) },
    )
    .unwrap()
    .limits();
    for (read, given) in limits.iter().zip(irb.limits()) {
        assert!((read.0 - given.0).abs() < 1e-12 && (read.1 - given.1).abs() < 1e-12, "{read:?} {given:?}");
    }
}

/// `text` in a temporary `.urdf` file, deleted when the returned path is dropped.
fn write(text: &str) -> tempfile::TempPath {
    let path = tempfile::Builder::new().suffix(".urdf").tempfile().unwrap().into_temp_path();
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn an_export_like_the_ur10_urdf_keeps_its_links_and_their_meaning() {
    let urdf = testkit::robot("ur10.urdf");
    let (model, _) = fitted(&urdf, Method::Poe, true);
    let original = std::fs::read_to_string(testkit::robot_path("ur10.urdf")).unwrap();
    let document = UrdfDocument::parse(&original, "ur10.urdf").unwrap();
    let chain = document.chain(&ChainEnds::default()).unwrap();
    let export = export_urdf(
        &model,
        UrdfTemplate::Like { document: &document, chain: &chain },
        None,
        &NominalTolerance::default(),
    )
    .unwrap();
    assert_eq!((export.report.base_link.as_str(), export.report.tracker_link.as_str()), ("base_link", "tracker"));
    // The calibrated geometry, read back through the original's links.
    let tracker = read_back(&export.text, "tracker", "tool");
    let difference = largest_difference_m(&tracker, 0, &model.kinematics, 0);
    assert!(difference < 1e-9, "tracker frame: {difference:e} m");
    // Everything but the six movable joints' origins is as it was: visuals, inertias, limits.
    for line in original.lines().filter(|l| !l.trim().is_empty()) {
        assert!(export.text.contains(line) || line.trim_start().starts_with("<origin"), "lost: {line}");
    }
    let changed =
        original.lines().filter(|l| l.trim_start().starts_with("<origin") && !export.text.contains(*l)).count();
    assert!((4..=6).contains(&changed), "{changed} origins changed");
    // Links keep their meaning: tool0 moves by the calibration (millimetres), not by a turn.
    let calibrated_tool0 = read_back(&export.text, "base_link", "tool0");
    let nominal_tool0 = read_back(&original, "base_link", "tool0");
    let moved = largest_difference_m(&calibrated_tool0, 0, &nominal_tool0, 0);
    assert!(moved > 1e-4 && moved < 0.02, "tool0 moved {moved} m");
}

#[test]
fn a_description_the_model_was_not_fitted_with_is_refused() {
    let (model, _) = fitted(&testkit::robot("ur10.ron"), Method::Poe, false);
    let original = std::fs::read_to_string(testkit::robot_path("ur10.urdf")).unwrap();
    let document = UrdfDocument::parse(&original, "ur10.urdf").unwrap();
    let chain = document.chain(&ChainEnds::default()).unwrap();
    let template = UrdfTemplate::Like { document: &document, chain: &chain };
    match export_urdf(&model, template, None, &NominalTolerance::default()) {
        Err(e) if matches!(e.kind::<ErrorKind>(), Some(ErrorKind::NominalMismatch { .. })) => {
            assert!(e.to_string().contains("give the robot description the model was fitted with"), "{e}")
        }
        other => panic!("expected a mismatch, got {other:?}"),
    }
}

#[test]
fn what_a_urdf_cannot_hold_is_measured_on_the_training_data_or_refused() {
    let irb = testkit::robot("irb4400.ron");
    let (model, training) = fitted(&irb, Method::PoeGp, false);
    let template = UrdfTemplate::Plain { nominal: Some((&irb, "irb4400.ron")) };
    match export_urdf(&model, template, None, &NominalTolerance::default()) {
        Err(e) if matches!(e.kind::<cell::ErrorKind>(), Some(cell::ErrorKind::ExportNeedsData { .. })) => {
            assert!(e.to_string().contains("gaussian_process"), "{e}")
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    let export = export_urdf(&model, template, Some(&training), &NominalTolerance::default()).unwrap();
    assert_eq!(export.report.not_in_urdf, ["gaussian_process"]);
    assert!(!export.report.tool_orientation_calibrated);
    let errors = export.report.training_error.unwrap();
    let geometric =
        model::evaluate(&model.geometry_only(), &model.geometry_only().bind(&training).unwrap()).unwrap().summary;
    assert_eq!(errors.urdf, geometric);
    assert_eq!(errors.model.n, 150);
}
