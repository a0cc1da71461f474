//! `fit` then `evaluate` on synthetic tracker data made here, through the files users write.

use errors::CommonKind;
use lie::{SE3, SO3, Twist, Vector3};
use measurements::ErrorKind;
use measurements::{Measurement, MeasurementSet, ReadOptions, parse_measurements};
use model::Method;
use pipeline::FitOptions;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot::RobotDescription;

fn twist(rng: &mut ChaCha8Rng, translation: f64, rotation: f64) -> Twist {
    let mut v = || Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    let (a, b) = (v(), v());
    Twist::new(a * translation, b * rotation)
}

/// Measurements of a robot whose every local frame is off by up to 2 mm / 2 mrad, seen from a
/// tracker 4 m away, with a tool 0.3 m from the flange per tool name.
fn synthetic(robot: &RobotDescription, rows: usize, tools: &[&str], full_pose: bool, seed: u64) -> MeasurementSet {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut truth = robot.nominal_model().unwrap();
    for joint in truth.joints_mut() {
        joint.previous_from_joint_zero = twist(&mut rng, 0.002, 0.002).exp() * joint.previous_from_joint_zero;
    }
    let flange = truth.tools()[0];
    let tool_poses: Vec<SE3> = tools.iter().map(|_| flange * twist(&mut rng, 0.3, 1.0).exp()).collect();
    truth.set_tools(tool_poses);
    truth.change_reference(SE3::new(SO3::exp(&Vector3::new(0.1, -0.2, 2.5)), Vector3::new(4.0, -1.0, 0.5)));
    let limits = robot.limits();
    let data = (0..rows)
        .map(|i| {
            let q: Vec<f64> = limits.iter().map(|&(lo, hi)| rng.random_range(0.8 * lo..0.8 * hi)).collect();
            let tool = i % tools.len();
            let pose = truth.forward(&q, tool).unwrap();
            Measurement {
                orientation: full_pose.then(|| pose.rotation()),
                tool,
                ..Measurement::at(q, pose.translation())
            }
        })
        .collect();
    MeasurementSet::from_rows("synthetic", data, tools.iter().map(|t| t.to_string()).collect())
}

/// Writes a set as CSV and reads it back, as a user's file would arrive.
fn through_csv(set: &MeasurementSet) -> MeasurementSet {
    let mut buffer = Vec::new();
    set.write_csv(&mut buffer).unwrap();
    parse_measurements(buffer.as_slice(), "data.csv", &ReadOptions::default()).unwrap()
}

/// The fit's options without the prior toward the nominal: these tests hold the identification
/// exact on noise-free rows (nanometres), which a prior, holding the links within the nominal's
/// tolerance, biases by a micrometre or so (`pipeline/tests/nominal_prior.rs` tests the prior).
fn exact() -> FitOptions {
    let mut options = FitOptions::default();
    options.nominal_prior.choose = false;
    options
}

#[test]
fn poe_fit_through_csv_and_model_file_reproduces_held_out_poses() {
    let robot = testkit::robot("irb4400.ron");
    for full_pose in [true, false] {
        let all = through_csv(&synthetic(&robot, 160, &["A", "B"], full_pose, 5));
        let train = all.subset(&(0..100).collect::<Vec<_>>());
        let test = all.subset(&(100..160).collect::<Vec<_>>());
        let (model, report) = pipeline::fit(&robot, &train, Method::Poe, &exact()).unwrap();
        assert!(report.before.mean_position_error_mm > 0.5, "{:?}", report.before);
        assert_eq!(report.identification.rank, if full_pose { 36 } else { 30 });
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("model.ron");
        model::write_model(&path, &model).unwrap();
        let model = model::read_model(&path).unwrap();
        let evaluation = model::evaluate(&model, &model.bind(&test).unwrap()).unwrap();
        assert!(evaluation.summary.mean_position_error_mm < 1e-6, "{:?}", evaluation.summary);
        assert_eq!(evaluation.summary.mean_rotation_error_mrad.is_some(), full_pose);
    }
}

#[test]
fn base_tool_fit_cannot_absorb_joint_errors_but_poe_can() {
    let robot = testkit::robot("irb4400.ron");
    let all = synthetic(&robot, 150, &["T"], true, 6);
    let train = all.subset(&(0..100).collect::<Vec<_>>());
    let test = all.subset(&(100..150).collect::<Vec<_>>());
    let (base_tool, report) = pipeline::fit(&robot, &train, Method::BaseTool, &FitOptions::default()).unwrap();
    assert_eq!(report.identification.rank, 12);
    let (poe, _) = pipeline::fit(&robot, &train, Method::Poe, &exact()).unwrap();
    let bt = model::evaluate(&base_tool, &base_tool.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm;
    let full = model::evaluate(&poe, &poe.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm;
    assert!(bt > 0.1 && full < 1e-6, "base-tool {bt} mm, poe {full} mm");
}

#[test]
fn binding_refuses_a_tool_the_model_does_not_know() {
    let robot = testkit::robot("irb4400.ron");
    let train = through_csv(&synthetic(&robot, 60, &["A"], true, 7));
    let (model, _) = pipeline::fit(&robot, &train, Method::BaseTool, &FitOptions::default()).unwrap();
    let other = through_csv(&synthetic(&robot, 10, &["Z"], true, 8));
    let error = model.bind(&other).unwrap_err();
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::UnknownTool { .. }))
            && matches!(error.position(), Some((2, _))),
        "{error}"
    );
    assert!(error.to_string().starts_with("data.csv:2:"), "{error}");
}

#[test]
fn model_files_of_another_schema_or_broken_are_refused_with_a_position() {
    let robot = testkit::robot("irb4400.ron");
    let train = synthetic(&robot, 60, &["A"], true, 9);
    let (model, _) = pipeline::fit(&robot, &train, Method::BaseTool, &FitOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.ron");
    model::write_model(&path, &model).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let error = model::parse_model(&text.replacen("schema_version: 2", "schema_version: 99", 1), "m.ron").unwrap_err();
    assert!(
        matches!(
            error.kind::<model::ErrorKind>(),
            Some(model::ErrorKind::SchemaVersion { found: 99, supported: 2, .. })
        ),
        "{error}"
    );
    let error = model::parse_model(&text.replacen("kinematics", "kinematic", 1), "m.ron").unwrap_err();
    assert!(
        matches!(error.kind::<CommonKind>(), Some(CommonKind::RonFormat { .. }))
            && matches!(error.position(), Some((line, _)) if line > 1),
        "{error}"
    );
    let error = model::parse_model("(schema_version: 1,", "m.ron").unwrap_err();
    assert!(error.to_string().starts_with("m.ron:"), "{error}");
}

#[test]
fn a_data_file_for_another_robot_is_refused() {
    let robot = testkit::robot("irb4400.ron");
    let text = "q1_rad,q2_rad,x_mm,y_mm,z_mm\n0,0,1,2,3\n";
    let set = parse_measurements(text.as_bytes(), "two.csv", &ReadOptions::default()).unwrap();
    let error = pipeline::fit(&robot, &set, Method::Poe, &FitOptions::default()).unwrap_err();
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::JointCountMismatch { found: 2, expected: 6, .. })),
        "{error}"
    );
}

#[test]
fn a_blank_tool_is_the_default_tool_in_the_fit_its_report_and_the_evaluation() {
    let robot = testkit::robot("irb4400.ron");
    // Rows alternate between tool "A" and a blank cell, 0.3 m and 1 rad apart.
    let all = through_csv(&synthetic(&robot, 160, &["A", ""], true, 10));
    assert_eq!(all.tools, vec!["A".to_owned(), String::new()]);
    let train = all.subset(&(0..100).collect::<Vec<_>>());
    let (model, report) = pipeline::fit(&robot, &train, Method::Poe, &exact()).unwrap();
    // The fit's own "after" report once sent the blank rows to tool "A": hundreds of mm.
    assert!(report.after.max_position_error_mm < 1e-6, "{:?}", report.after);
    let test = all.subset(&(100..160).collect::<Vec<_>>());
    let evaluation = model::evaluate(&model, &model.bind(&test).unwrap()).unwrap();
    assert!(evaluation.summary.max_position_error_mm < 1e-6, "{:?}", evaluation.summary);

    // A file without a tool column is the default tool too: the blank rows alone, written
    // without the column, evaluate the same.
    let blank_rows: Vec<usize> = (100..160).filter(|&i| all.rows[i].tool == 1).collect();
    let mut blank = all.subset(&blank_rows);
    blank.tools = vec![String::new()];
    blank.rows.iter_mut().for_each(|r| r.tool = 0);
    let blank = through_csv(&blank);
    assert_eq!(blank.tool_column, None);
    let evaluation = model::evaluate(&model, &model.bind(&blank).unwrap()).unwrap();
    assert!(evaluation.summary.max_position_error_mm < 1e-6, "{:?}", evaluation.summary);
}

#[test]
fn the_default_tool_is_refused_by_a_model_fitted_only_with_named_tools() {
    let robot = testkit::robot("irb4400.ron");
    let train = through_csv(&synthetic(&robot, 60, &["A", "B"], true, 11));
    let (model, _) = pipeline::fit(&robot, &train, Method::BaseTool, &FitOptions::default()).unwrap();
    let unnamed = through_csv(&synthetic(&robot, 10, &[""], true, 12));
    let error = model.bind(&unnamed).unwrap_err();
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::UnknownTool { tool, .. }) if tool.is_empty())
            && matches!(error.position(), Some((2, _))),
        "{error}"
    );
    assert_eq!(
        error.to_string(),
        "data.csv:2:1: a row without a tool name is the default tool, which the model was not fitted with \
         (it knows 'A', 'B'); name the tool in a 'tool' column"
    );
}

#[test]
fn a_joint_unit_that_does_not_fit_the_robot_is_refused_by_the_fit() {
    let robot = RobotDescription::parse(
        "Robot(name: \"two\", joints: [\
         (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.0), limits_deg: (-90.0, 90.0)),\
         (kind: Prismatic, axis: (1.0, 0.0, 0.0), point: (0.0, 0.0, 1.0), limits_m: (0.0, 0.5))],\
         flange: (position: (1.0, 0.0, 1.0), x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0)))",
        "two.ron",
    )
    .unwrap();
    let set =
        parse_measurements("q1_rad,q2_deg,x_mm,y_mm,z_mm\n0,0,1,2,3\n".as_bytes(), "two.csv", &ReadOptions::default())
            .unwrap();
    let error = pipeline::fit(&robot, &set, Method::Poe, &FitOptions::default()).unwrap_err();
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::JointUnit { joint: 2, .. }))
            && matches!(error.position(), Some((_, 2))),
        "{error}"
    );
}
