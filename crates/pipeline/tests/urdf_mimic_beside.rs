//! Mimic stages driven from beside the chain: a shipped URDF draws a telescopic column
//! as one actuated joint moving a pseudo link, the chain running through mimic stages of it. The
//! stages fold into one joint whose value is the driver's; the shipped column arm loads, moves as
//! its URDF joint by joint, equals the same chain folded by hand, fits to the same numbers and
//! exports back in its own shape. What cannot fold is refused at the `<mimic>` element.

mod mimic_common;

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoise};
use cell::{UrdfTemplate, export_urdf};
use errors::ErrorKind;
use lie::Vector3;
use measurements::MeasurementSet;
use mimic_common::{assert_refused, chain, joint_by_joint, largest_difference, random_q};
use model::Method;
use pipeline::FitOptions;
use poe::LocalPoe;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robot::{ChainEnds, JointType, NominalTolerance, RobotDescription, UrdfDocument};

fn shipped_text() -> String {
    std::fs::read_to_string(testkit::robot_path("column_arm_shipped.urdf")).unwrap()
}

/// `element` (`<joint name="name" …>…</joint>`) of `text` replaced by `with`.
fn replace_joint(text: &str, name: &str, with: &str) -> String {
    let start = text.find(&format!("<joint name=\"{name}\"")).unwrap_or_else(|| panic!("joint {name}"));
    let end = start + text[start..].find("</joint>").unwrap() + "</joint>".len();
    format!("{}{with}{}", &text[..start], &text[end..])
}

/// The shipped column arm folded by hand: stage 1 is the actuated joint (its offset in its
/// origin, the motor's limits), stage 2 a fixed joint at its offset, the motor and its nut left
/// beside the chain with nothing following them.
fn folded_by_hand() -> String {
    let stage_1 = r#"<joint name="column_stage_1" type="prismatic">
    <parent link="column_foot"/>
    <child link="column_stage_1"/>
    <origin xyz="0 0 0.95" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="0.0" upper="2.0" effort="20000.0" velocity="0.2"/>
  </joint>"#;
    let stage_2 = r#"<joint name="column_stage_2" type="fixed">
    <parent link="column_collar"/>
    <child link="column_stage_2"/>
    <origin xyz="0 0 0.25" rpy="0 0 -1.5707963267948966"/>
  </joint>"#;
    replace_joint(&replace_joint(&shipped_text(), "column_stage_1", stage_1), "column_stage_2", stage_2)
}

fn largest_pose_difference(a: &LocalPoe, b: &LocalPoe, robot: &RobotDescription) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    (0..30)
        .map(|_| {
            let q = random_q(robot, &mut rng);
            (a.forward(&q, 0).unwrap().to_matrix() - b.forward(&q, 0).unwrap().to_matrix()).norm()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_shipped_column_folds_its_two_stages_into_one_joint_of_the_motor_beside_the_chain() {
    let robot = testkit::robot("column_arm_shipped.urdf");
    assert_eq!(robot.joint_count(), 7);
    let column = &robot.joints[0];
    assert_eq!(column.kind, JointType::Prismatic);
    // 0.5 + 0.5 per metre of the motor, along the column; the motor's limits.
    assert!((column.scale - 1.0).abs() < 1e-12, "scale {}", column.scale);
    assert!((Vector3::from(column.axis) - Vector3::z()).norm() < 1e-12);
    assert_eq!(column.limits_m, Some((0.0, 2.0)));
    assert_eq!(robot.folded.len(), 1);
    let folded = &robot.folded[0];
    assert_eq!((folded.joint, folded.actuated.as_str()), (1, "column_drive"));
    let stages: Vec<(&str, f64, f64)> =
        folded.stages.iter().map(|s| (s.joint.as_str(), s.multiplier, s.offset)).collect();
    assert_eq!(stages, [("column_stage_1", 0.5, 0.05), ("column_stage_2", 0.5, 0.1)]);
    assert!(robot.dynamics.is_some(), "the URDF's masses make the load model");
    let difference = largest_difference(&chain(&shipped_text(), &ChainEnds::default()), 1);
    assert!(difference < 1e-12, "{difference:e}");
}

#[test]
fn the_shipped_column_arm_is_the_same_chain_folded_by_hand() {
    let shipped = chain(&shipped_text(), &ChainEnds::default()).description();
    let by_hand = chain(&folded_by_hand(), &ChainEnds::default()).description();
    assert!(by_hand.folded.is_empty());
    assert_eq!(shipped.limits(), by_hand.limits());
    let (a, b) = (shipped.nominal_model().unwrap(), by_hand.nominal_model().unwrap());
    let difference = largest_pose_difference(&a, &b, &shipped);
    assert!(difference < 1e-12, "{difference:e}");
    // The same bodies: the nut beside the chain carries nothing, the stages ride on joint 1.
    let (Some(a), Some(b)) = (&shipped.dynamics, &by_hand.dynamics) else { panic!("masses") };
    for (x, y) in a.links.iter().zip(&b.links) {
        assert!((x.mass_kg - y.mass_kg).abs() < 1e-12, "{x:?} {y:?}");
        assert!((Vector3::from(x.com_m) - Vector3::from(y.com_m)).norm() < 1e-12, "{x:?} {y:?}");
    }
}

/// 200 simulated rows of the shipped column arm (a perturbed cell, tracker noise): 150 to fit,
/// 50 to test.
fn simulated(robot: &RobotDescription) -> (MeasurementSet, MeasurementSet) {
    let cell = campaign::simulated_cell(robot, &Perturbation::default(), 11).unwrap();
    let effects = Effects { tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
    let config = GeneratorConfig { sample_count: 200, seed: 11, payloads_kg: vec![0.0], ..GeneratorConfig::default() };
    let set = campaign::simulate(&cell, &effects, &campaign::joint_ranges(robot), &config, true).unwrap();
    let (train, test) = set.rows.split_at(150);
    (MeasurementSet { rows: train.to_vec(), ..set.clone() }, MeasurementSet { rows: test.to_vec(), ..set.clone() })
}

#[test]
fn the_shipped_and_the_hand_folded_column_arm_fit_to_the_same_numbers() {
    let shipped = chain(&shipped_text(), &ChainEnds::default()).description();
    let by_hand = chain(&folded_by_hand(), &ChainEnds::default()).description();
    let (train, test) = simulated(&shipped);
    let held_out = |robot: &RobotDescription| {
        let (model, _) = pipeline::fit(robot, &train, Method::Poe, &FitOptions::default()).unwrap();
        let bound = model.bind(&test).unwrap();
        let errors: Vec<f64> = model::evaluate(&model, &bound).unwrap().errors.iter().map(|e| e.position_mm).collect();
        (model, errors)
    };
    let ((a, from_shipped), (b, from_hand)) = (held_out(&shipped), held_out(&by_hand));
    let mean = from_shipped.iter().sum::<f64>() / from_shipped.len() as f64;
    // The nominal geometry is off by millimetres; the fit leaves the tracker noise.
    assert!(mean < 0.1, "{mean} mm");
    let largest = from_shipped.iter().zip(&from_hand).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(largest < 1e-6, "held-out errors differ by up to {largest:e} mm");
    let difference = largest_pose_difference(&a.kinematics, &b.kinematics, &shipped);
    assert!(difference < 1e-9, "{difference:e} m");
}

#[test]
fn export_like_the_shipped_urdf_keeps_its_shape_and_reads_back_to_the_model() {
    let text = shipped_text();
    let robot = chain(&text, &ChainEnds::default()).description();
    let (train, _) = simulated(&robot);
    let (model, _) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default()).unwrap();
    let document = UrdfDocument::parse(&text, "column_arm_shipped.urdf").unwrap();
    let nominal_chain = document.chain(&ChainEnds::default()).unwrap();
    let template = UrdfTemplate::Like { document: &document, chain: &nominal_chain };
    let export = export_urdf(&model, template, None, &NominalTolerance::default()).unwrap_or_else(|e| panic!("{e}"));
    let element = |t: &str, joint: &str| {
        let start = t.find(&format!("<joint name=\"{joint}\"")).unwrap();
        t[start..start + t[start..].find("</joint>").unwrap()].to_owned()
    };
    // The motor and its nut, the second stage and both <mimic> elements are as shipped; the first
    // stage carries the calibrated origin.
    for joint in ["column_drive", "column_stage_2"] {
        assert_eq!(element(&export.text, joint), element(&text, joint));
    }
    let first = element(&export.text, "column_stage_1");
    assert_ne!(first, element(&text, "column_stage_1"));
    assert!(first.contains("<mimic joint=\"column_drive\" multiplier=\"0.5\" offset=\"0.05\"/>"), "{first}");
    assert_eq!(export.report.axis_changes[0].joint, "column_drive");
    let ends = ChainEnds { base_link: Some("tracker".into()), tip_link: Some("tool".into()) };
    let again = chain(&export.text, &ends).description();
    assert_eq!(again.folded.len(), 1);
    assert_eq!(again.folded[0].actuated, "column_drive");
    let tracker = again.nominal_model().unwrap();
    let difference = largest_pose_difference(&tracker, &model.kinematics, &robot);
    assert!(difference < 1e-9, "{difference:e}");
}

/// A motor `motor` beside the chain (it moves `nut`), two stages of it on the chain, `s1` and
/// `s2`, joined by `MIDDLE`; `KIND` is the joints' type, `S2ORIGIN` where `s2` sits on `l2`.
const BESIDE: &str = r#"<?xml version="1.0"?>
<robot name="beside">
  <link name="base"/>
  <link name="nut"/>
  <link name="l1"/>
  <link name="l2"/>
  <link name="l3"/>
  <link name="tip"/>
  <joint name="motor" type="KIND">
    <parent link="base"/>
    <child link="nut"/>
    <origin xyz="0.5 0 0" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="s1" type="KIND">
    <parent link="base"/>
    <child link="l1"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.1 0.2 0.3"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="motor" multiplier="0.5" offset="0.2"/>
  </joint>
  MIDDLE
  <joint name="s2" type="KIND">
    <parent link="l2"/>
    <child link="l3"/>
    <origin xyz="S2ORIGIN" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="motor" multiplier="0.25" offset="-0.1"/>
  </joint>
  <joint name="l3-tip" type="fixed">
    <parent link="l3"/>
    <child link="tip"/>
    <origin xyz="0.2 0.1 0.05" rpy="0.3 0.2 0.1"/>
  </joint>
</robot>
"#;

/// A fixed joint that slides along and turns about `s1`'s axis.
const FIXED_MIDDLE: &str = r#"<joint name="l1-l2" type="fixed">
    <parent link="l1"/>
    <child link="l2"/>
    <origin xyz="0 0 0.4" rpy="0 0 0.7"/>
  </joint>"#;

fn beside(kind: &str, middle: &str, s2_origin: &str) -> String {
    BESIDE.replace("KIND", kind).replace("MIDDLE", middle).replace("S2ORIGIN", s2_origin)
}

fn tip() -> ChainEnds {
    ChainEnds { base_link: None, tip_link: Some("tip".into()) }
}

#[test]
fn prismatic_and_coaxial_revolute_stages_of_a_motor_beside_the_chain_fold_exactly() {
    for kind in ["prismatic", "revolute"] {
        let chain = chain(&beside(kind, FIXED_MIDDLE, "0 0 0.1"), &tip());
        let robot = chain.description();
        assert_eq!(robot.joint_count(), 1, "{kind}");
        // The motor moves nothing on the chain: 0.5 + 0.25 per unit of it, its limits.
        assert!((robot.joints[0].scale - 0.75).abs() < 1e-12, "{kind}: {}", robot.joints[0].scale);
        assert_eq!(robot.limits(), [(-1.0, 1.0)], "{kind}");
        assert_eq!(robot.folded[0].actuated, "motor");
        let difference = largest_difference(&chain, 5);
        assert!(difference < 1e-12, "{kind}: {difference:e}");
        // Its twist is the derivative of the URDF chain walked joint by joint.
        let twist = robot.nominal_model().unwrap().spatial_twists(&[0.3]).unwrap()[0];
        let h = 1e-6;
        let moved = joint_by_joint(&chain, &[0.3 + h]) * joint_by_joint(&chain, &[0.3 - h]).inverse();
        let numeric = moved.log().to_vector() / (2.0 * h);
        assert!((numeric - twist.to_vector()).norm() < 1e-7, "{kind}: {numeric} against {}", twist.to_vector());
    }
}

#[test]
fn revolute_stages_of_a_motor_beside_the_chain_on_different_lines_are_refused() {
    let text = beside("revolute", FIXED_MIDDLE, "0.3 0 0.1");
    assert_refused(&text, "s2", &["parallel to the axis of joint 's1' but 0.300000 m from it", "parallelogram"]);
}

#[test]
fn stages_of_a_motor_beside_the_chain_with_a_joint_moving_between_them_are_refused() {
    let elbow = r#"<joint name="elbow" type="revolute">
    <parent link="l1"/>
    <child link="l2"/>
    <origin xyz="0 0 0.4" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>"#;
    let text = beside("prismatic", elbow, "0 0 0.1");
    assert_refused(&text, "s2", &["follows joint 'motor' as stage 's1' does, but joint 'elbow' moves between them"]);
}

#[test]
fn a_motor_beside_the_chain_that_is_a_mimic_itself_or_of_another_kind_is_refused() {
    let text = beside("prismatic", FIXED_MIDDLE, "0 0 0.1");
    // The motor follows a joint further beside the chain.
    let of_a_mimic = text
        .replace(
            "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\n  </joint>\n  <joint name=\"s1\"",
            "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\n    <mimic joint=\"knob\"/>\n  </joint>\n  <joint name=\"s1\"",
        )
        .replace(
            "</robot>",
            "  <link name=\"dial\"/>\n  <joint name=\"knob\" type=\"prismatic\"><parent link=\"base\"/><child link=\"dial\"/><axis xyz=\"1 0 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n</robot>",
        );
    assert_refused(
        &of_a_mimic,
        "s1",
        &["follows joint 'motor', beside the chain, which is itself a mimic joint of 'knob'"],
    );
    let turning_motor = text.replacen("type=\"prismatic\"", "type=\"revolute\"", 1);
    assert_refused(&turning_motor, "s1", &["a prismatic joint following the revolute joint 'motor'"]);
    let fixed_motor = text.replacen("type=\"prismatic\"", "type=\"fixed\"", 1);
    assert_refused(&fixed_motor, "s1", &["follows joint 'motor', a fixed joint"]);
    // The stages turn opposite ways at one rate: nothing moves.
    let cancelling = text.replace("multiplier=\"0.25\"", "multiplier=\"-0.5\"");
    assert_refused(&cancelling, "s2", &["the stages cancel"]);
}

#[test]
fn a_stage_of_a_joint_above_the_chains_base_is_refused() {
    // From `l1`, the chain's base rides on `s1`, which `s2` follows as a stage of the motor.
    let text = beside("prismatic", FIXED_MIDDLE, "0 0 0.1")
        .replace("<mimic joint=\"motor\" multiplier=\"0.25\"", "<mimic joint=\"s1\" multiplier=\"0.25\"");
    let text = text.replace("<mimic joint=\"motor\" multiplier=\"0.5\" offset=\"0.2\"/>", "");
    let ends = ChainEnds { base_link: Some("l1".into()), tip_link: Some("tip".into()) };
    let error = UrdfDocument::parse(&text, "arm.urdf").and_then(|d| d.chain(&ends)).unwrap_err();
    let ErrorKind::UrdfFormat { message } = error.kind() else { panic!("{error:?}") };
    assert!(
        message.starts_with("mimic joint 's2': follows joint 's1', which moves the chain's base link itself"),
        "{message}"
    );
    assert_eq!(error.position().map(|(line, _)| line as usize), Some(mimic_common::mimic_position(&text, "s2").0));
}
