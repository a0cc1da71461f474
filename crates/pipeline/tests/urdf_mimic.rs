//! Mimic joints folded into the joint that drives them: the description's forward
//! kinematics equal the URDF chain evaluated joint by joint, every mimic at `multiplier · q +
//! offset`; chains whose mimic joints do not fold are refused at the `<mimic>` element.

mod mimic_common;

use errors::ErrorKind;
use lie::Vector3;
use mimic_common::{assert_refused, chain, joint_by_joint, largest_difference, mimic_position, random_q, refusal};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot::{ChainEnds, JointType, RobotDescription, UrdfDocument};

#[test]
fn the_column_arm_folds_its_three_column_stages_into_one_joint_of_scale_three() {
    let robot = testkit::robot("column_arm.urdf");
    assert_eq!(robot.joint_count(), 7);
    let column = &robot.joints[0];
    assert_eq!(column.kind, JointType::Prismatic);
    assert!((column.scale - 3.0).abs() < 1e-12, "scale {}", column.scale);
    assert!((Vector3::from(column.axis) - Vector3::z()).norm() < 1e-12);
    assert_eq!(column.limits_m, Some((0.0, 0.8333333333333334)));
    assert!(robot.joints[1..].iter().all(|j| j.kind == JointType::Revolute && j.scale == 1.0));
    assert_eq!(robot.folded.len(), 1);
    let folded = &robot.folded[0];
    assert_eq!((folded.joint, folded.actuated.as_str()), (1, "lift"));
    let stages: Vec<&str> = folded.stages.iter().map(|s| s.joint.as_str()).collect();
    assert_eq!(stages, ["lift_stage_2", "lift_stage_3"]);
    let text = folded.to_string();
    assert!(text.contains("how it splits between the stages") && text.contains("'lift_stage_3'"), "{text}");
}

#[test]
fn the_folded_column_arm_moves_as_its_urdf_joint_by_joint() {
    let text = std::fs::read_to_string(testkit::robot_path("column_arm.urdf")).unwrap();
    let difference = largest_difference(&chain(&text, &ChainEnds::default()), 1);
    assert!(difference < 1e-12, "{difference:e}");
}

#[test]
fn from_the_column_foot_the_column_arm_is_column_ur10_with_the_lift_tripled() {
    let text = std::fs::read_to_string(testkit::robot_path("column_arm.urdf")).unwrap();
    let ends = ChainEnds { base_link: Some("column_foot".into()), tip_link: Some("tool0".into()) };
    let folded = chain(&text, &ends).description().nominal_model().unwrap();
    let ron = testkit::robot("column_ur10.ron");
    let reference = ron.nominal_model().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for _ in 0..50 {
        let q = random_q(&ron, &mut rng);
        let mut lift = q.clone();
        lift[0] = q[0] / 3.0;
        let difference =
            (folded.forward(&lift, 0).unwrap().to_matrix() - reference.forward(&q, 0).unwrap().to_matrix()).norm();
        assert!(difference < 1e-9, "{difference:e} at {q:?}");
    }
}

/// A column of two prismatic stages and an arm of one revolute joint with a coaxial revolute
/// stage; `STAGE` and `WRIST` are replaced per test.
const STAGED: &str = r#"<?xml version="1.0"?>
<robot name="staged">
  <link name="base"/>
  <link name="slide"/>
  <link name="turned"/>
  <link name="stage"/>
  <link name="arm"/>
  <link name="collar"/>
  <link name="wrist"/>
  <link name="tip"/>
  <joint name="push" type="prismatic">
    <parent link="base"/>
    <child link="slide"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.1 0.2 0.3"/>
    <axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/>
  </joint>
  <joint name="slide-turned" type="fixed">
    <parent link="slide"/>
    <child link="turned"/>
    <origin xyz="0 0.05 0.2" rpy="0.4 -0.3 1.0"/>
  </joint>
  STAGE
  <joint name="turn" type="revolute">
    <parent link="stage"/>
    <child link="arm"/>
    <origin xyz="0.3 0 0.1" rpy="0 0.5 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="arm-collar" type="fixed">
    <parent link="arm"/>
    <child link="collar"/>
    <origin xyz="0 0.25 0" rpy="0 0.7 0"/>
  </joint>
  WRIST
  <joint name="wrist-tip" type="fixed">
    <parent link="wrist"/>
    <child link="tip"/>
    <origin xyz="0.2 0.1 0.05" rpy="0.3 0.2 0.1"/>
  </joint>
</robot>
"#;

/// A second prismatic stage whose axis, through the fixed joint's rotation, is not parallel to
/// the first's: the stages' sum is still a translation, along a direction of its own.
const SKEW_STAGE: &str = r#"<joint name="push_stage" type="prismatic">
    <parent link="turned"/>
    <child link="stage"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/>
    <axis xyz="1 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="push" multiplier="2" offset="0.05"/>
  </joint>"#;

/// A revolute stage on the same line as `turn` (through `collar`, which only slides along and
/// turns about that line), turning the other way round its axis.
const COAXIAL_WRIST: &str = r#"<joint name="turn_stage" type="revolute">
    <parent link="collar"/>
    <child link="wrist"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="0 -1 0"/>
    <mimic joint="turn" multiplier="-0.5" offset="0.3"/>
  </joint>"#;

fn staged(stage: &str, wrist: &str) -> String {
    STAGED.replace("STAGE", stage).replace("WRIST", wrist)
}

#[test]
fn skew_prismatic_stages_and_coaxial_revolute_stages_fold_exactly() {
    let chain = chain(&staged(SKEW_STAGE, COAXIAL_WRIST), &ChainEnds::default());
    let robot = chain.description();
    assert_eq!(robot.joint_count(), 2);
    // push moves 1 along its z, the stage 2·(1, 0, 1)/√2 along a turned axis: |sum| is their
    // resultant; turn_stage turns −0.5 · (−1) = +0.5 per unit about turn's line.
    assert!(robot.joints[0].scale > 1.0 && robot.joints[0].scale < 3.0, "{}", robot.joints[0].scale);
    assert!((robot.joints[1].scale - 1.5).abs() < 1e-12, "{}", robot.joints[1].scale);
    let difference = largest_difference(&chain, 3);
    assert!(difference < 1e-12, "{difference:e}");
}

#[test]
fn the_scaled_joints_twists_are_the_derivatives_of_the_urdf_chain() {
    let chain = chain(&staged(SKEW_STAGE, COAXIAL_WRIST), &ChainEnds::default());
    let model = chain.description().nominal_model().unwrap();
    let q = [0.21, -0.7];
    let twists = model.spatial_twists(&q).unwrap();
    let h = 1e-6;
    for (i, twist) in twists.iter().enumerate() {
        let (mut up, mut down) = (q, q);
        up[i] += h;
        down[i] -= h;
        let moved = joint_by_joint(&chain, &up) * joint_by_joint(&chain, &down).inverse();
        let numeric = moved.log().to_vector() / (2.0 * h);
        assert!((numeric - twist.to_vector()).norm() < 1e-7, "joint {i}: {numeric} against {}", twist.to_vector());
    }
}

#[test]
fn a_revolute_mimic_on_a_parallel_offset_axis_is_refused_as_a_parallelogram() {
    let wrist =
        COAXIAL_WRIST.replace("<origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>", "<origin xyz=\"0.4 0 0\" rpy=\"0 0 0\"/>");
    let text = staged(SKEW_STAGE, &wrist);
    assert_refused(&text, "turn_stage", &["parallel to the axis of joint 'turn'", "0.4", "parallelogram"]);
}

#[test]
fn a_revolute_mimic_on_a_crossing_axis_is_refused() {
    let text = staged(SKEW_STAGE, &COAXIAL_WRIST.replace("<axis xyz=\"0 -1 0\"/>", "<axis xyz=\"1 0 0\"/>"));
    assert_refused(&text, "turn_stage", &["90.0000 deg to the axis of joint 'turn'"]);
}

#[test]
fn a_mimic_of_an_undefined_joint_is_refused() {
    // Joints beside the chain drive stages too (`urdf_mimic_beside.rs`); a name the URDF lacks does not.
    let undefined = staged(SKEW_STAGE, &COAXIAL_WRIST.replace("joint=\"turn\"", "joint=\"nowhere\""));
    assert_refused(&undefined, "turn_stage", &["'nowhere', which the URDF does not define"]);
}

#[test]
fn a_mimic_with_a_movable_joint_between_it_and_the_joint_it_follows_is_refused() {
    // turn_stage follows push, with turn (and push_stage) between them.
    let text = staged(SKEW_STAGE, &COAXIAL_WRIST.replace("joint=\"turn\"", "joint=\"push\""));
    let (_, _, message) = refusal(&text);
    // Its kind differs from push's as well; the joint in between is named first.
    assert_refused(&text, "turn_stage", &["follows joint 'push', but joint 'turn' moves between them"]);
    assert!(!message.contains("prismatic joint"), "{message}");
}

#[test]
fn a_mimic_of_another_kind_of_a_mimic_and_stages_that_cancel_are_refused() {
    let revolute_on_prismatic = staged(
        &SKEW_STAGE.replace("type=\"prismatic\"", "type=\"revolute\""),
        "<joint name=\"turn_stage\" type=\"fixed\"><parent link=\"collar\"/><child link=\"wrist\"/></joint>",
    );
    assert_refused(&revolute_on_prismatic, "push_stage", &["a revolute joint following the prismatic joint 'push'"]);
    let of_a_mimic = staged(SKEW_STAGE, &COAXIAL_WRIST.replace("joint=\"turn\"", "joint=\"push_stage\""));
    assert_refused(&of_a_mimic, "turn_stage", &["'push_stage', itself a mimic joint"]);
    // The stage turns the other way round the same line at the same rate: nothing moves.
    let cancelling = staged(SKEW_STAGE, &COAXIAL_WRIST.replace("multiplier=\"-0.5\"", "multiplier=\"1\""));
    assert_refused(&cancelling, "turn_stage", &["the stages cancel"]);
    let not_finite = staged(SKEW_STAGE, &COAXIAL_WRIST.replace("multiplier=\"-0.5\"", "multiplier=\"inf\""));
    let (line, column, message) = refusal(&not_finite);
    assert_eq!((line, column), mimic_position(&not_finite, "turn_stage"), "{message}");
    assert!(message.contains("must be finite"), "{message}");
}

#[test]
fn a_mimic_before_the_joint_it_follows_is_refused() {
    let text = staged(
        &SKEW_STAGE.replace("joint=\"push\"", "joint=\"turn\"").replace("type=\"prismatic\"", "type=\"revolute\""),
        "<joint name=\"turn_stage\" type=\"fixed\"><parent link=\"collar\"/><child link=\"wrist\"/></joint>",
    );
    assert_refused(&text, "push_stage", &["follows joint 'turn', further from the base"]);
}

mod export {
    use super::*;
    use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoise};
    use cell::{UrdfTemplate, export_urdf};
    use model::Method;
    use pipeline::FitOptions;
    use poe::LocalPoe;
    use robot::NominalTolerance;

    /// A poe fit of the column arm on simulated data (noise only) and the URDF text.
    pub(super) fn fitted() -> (model::CalibratedModel, pipeline::FitReport, String, RobotDescription) {
        let text = std::fs::read_to_string(testkit::robot_path("column_arm.urdf")).unwrap();
        let robot = chain(&text, &ChainEnds::default()).description();
        let cell = campaign::simulated_cell(&robot, &Perturbation::default(), 7).unwrap();
        let effects = Effects { tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
        let config =
            GeneratorConfig { sample_count: 150, seed: 7, payloads_kg: vec![0.0], ..GeneratorConfig::default() };
        let set = campaign::simulate(&cell, &effects, &campaign::joint_ranges(&robot), &config, true).unwrap();
        let (model, report) = pipeline::fit(&robot, &set, Method::Poe, &FitOptions::default()).unwrap();
        (model, report, text, robot)
    }

    fn read_back(text: &str, base: &str, tip: &str) -> LocalPoe {
        let ends = ChainEnds { base_link: Some(base.into()), tip_link: Some(tip.into()) };
        chain(text, &ends).description().nominal_model().unwrap()
    }

    fn largest_difference_m(a: &LocalPoe, b: &LocalPoe) -> f64 {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        (0..20)
            .map(|_| {
                let q: Vec<f64> = (0..a.joint_count())
                    .map(|j| if j == 0 { rng.random_range(0.0..0.8) } else { rng.random_range(-3.0..3.0) })
                    .collect();
                (a.forward(&q, 0).unwrap().to_matrix() - b.forward(&q, 0).unwrap().to_matrix()).norm()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn the_fit_report_says_the_split_between_the_stages_is_not_observed() {
        let (model, report, _, _) = fitted();
        assert_eq!(model.kinematics.joints()[0].scale, 3.0);
        assert_eq!(report.folded.len(), 1);
        assert!(report.folded[0].to_string().contains("only their summed motion is observed"));
    }

    #[test]
    fn export_like_the_urdf_keeps_its_mimic_joints_and_reads_back_to_the_model() {
        let (model, _, text, _) = fitted();
        let document = UrdfDocument::parse(&text, "column_arm.urdf").unwrap();
        let nominal_chain = document.chain(&ChainEnds::default()).unwrap();
        let template = UrdfTemplate::Like { document: &document, chain: &nominal_chain };
        let export =
            export_urdf(&model, template, None, &NominalTolerance::default()).unwrap_or_else(|e| panic!("{e}"));
        // The stages, their origins and their <mimic> elements are as written.
        for joint in ["lift_stage_2", "lift_stage_3"] {
            let element = |t: &str| {
                let start = t.find(&format!("<joint name=\"{joint}\"")).unwrap();
                t[start..start + t[start..].find("</joint>").unwrap()].to_owned()
            };
            assert_eq!(element(&export.text), element(&text));
        }
        assert_eq!(export.text.matches("<mimic joint=\"lift\" multiplier=\"1\" offset=\"0\"/>").count(), 2);
        assert_eq!(export.report.axis_changes.len(), 7);
        assert_eq!(export.report.axis_changes[0].joint, "lift");
        let tracker = read_back(&export.text, "tracker", "tool");
        assert!((tracker.joints()[0].scale - 3.0).abs() < 1e-12, "{}", tracker.joints()[0].scale);
        let difference = largest_difference_m(&tracker, &model.kinematics);
        assert!(difference < 1e-9, "{difference:e}");
    }

    #[test]
    fn a_plain_export_writes_a_scaled_joint_as_a_joint_and_a_mimic_stage() {
        let (model, _, _, robot) = fitted();
        let template = UrdfTemplate::Plain { nominal: Some((&robot, "column_arm.urdf")) };
        let export = export_urdf(&model, template, None, &NominalTolerance::default()).unwrap();
        assert!(export.text.contains("<limit lower=\"0.0\" upper=\"1.6666666666666667\""), "{}", export.text);
        assert!(export.text.contains("<mimic joint=\"joint_1\" multiplier=\"2.0\" offset=\"0\"/>"), "{}", export.text);
        let tracker = read_back(&export.text, "tracker", "tool");
        let difference = largest_difference_m(&tracker, &model.kinematics);
        assert!(difference < 1e-9, "{difference:e}");
    }
}

/// A robot file whose column moves three times its joint value, like the folded column.
const SCALED_RON: &str = "Robot(
    name: \"column\",
    joints: [
        (kind: Prismatic, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.0), limits_m: (0.0, 0.8), scale: 3.0),
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 1.5), limits_deg: (-180.0, 180.0)),
    ],
    flange: (position: (0.5, 0.0, 1.5), x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0)),
)";

#[test]
fn a_robot_file_may_give_a_joint_scale_and_a_scale_out_of_bounds_is_refused_at_it() {
    let robot = RobotDescription::parse(SCALED_RON, "column.ron").unwrap_or_else(|e| panic!("{e}"));
    let flange = robot.nominal_model().unwrap().forward(&[0.5, 0.0], 0).unwrap();
    assert!((flange.translation() - Vector3::new(0.5, 0.0, 3.0)).norm() < 1e-12, "{}", flange.translation());
    for bad in ["0.0", "-3.0", "1e9", "inf"] {
        let text = SCALED_RON.replace("scale: 3.0", &format!("scale: {bad}"));
        let e = RobotDescription::parse(&text, "column.ron").expect_err(bad);
        let (Some((line, column)), ErrorKind::RonFormat { message }) = (e.position(), e.kind()) else {
            panic!("{bad}: {e:?}")
        };
        assert_eq!((line as usize, column), position_of(&text, &format!("scale: {bad}")), "{bad}: {message}");
        assert!(message.contains("joint 1: scale"), "{message}");
    }
}

#[test]
fn a_model_file_with_a_scale_out_of_bounds_is_refused_at_it() {
    let (model, _, _, _) = export::fitted();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.ron");
    model::write_model(&path, &model).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // Once in the kinematics, for joint 1 alone (and once more in the robot description the model
    // keeps, last in the file).
    let kinematics = &text[..text.find("robot_description:").unwrap()];
    assert_eq!(kinematics.matches("scale: 3.0").count(), 1, "written once, for joint 1 alone");
    assert_eq!(model::parse_model(&text, "model.ron").unwrap().kinematics.joints()[0].scale, 3.0);
    let broken = text.replacen("scale: 3.0", "scale: 0.0", 1);
    let (line, column) = position_of(&broken, "scale: 0.0");
    let e = model::parse_model(&broken, "model.ron").expect_err("a refusal");
    let (Some((l, c)), ErrorKind::RonFormat { message }) = (e.position(), e.kind()) else { panic!("{e:?}") };
    assert_eq!((l as usize, c), (line, column), "{message}");
    assert!(message.contains("scale is 0e0"), "{message}");
}

/// The 1-based line and column of the first `needle` in `text`.
fn position_of(text: &str, needle: &str) -> (usize, usize) {
    let before = &text[..text.find(needle).expect("the needle")];
    (before.matches('\n').count() + 1, before.rsplit('\n').next().unwrap_or("").chars().count() + 1)
}
