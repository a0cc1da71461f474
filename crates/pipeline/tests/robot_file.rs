//! The robot description files: the committed fixtures, and the bad inputs refused.

use errors::ErrorKind;
use poe::{DhConvention, DhRow, JointKind, LocalPoe};
use robot::RobotDescription;
use std::f64::consts::FRAC_PI_2;

#[test]
fn every_fixture_robot_reads_and_builds_its_model() {
    for (name, joints) in [("irb4400.ron", 6), ("ur10.ron", 6), ("iiwa7.ron", 7)] {
        let robot = testkit::robot(name);
        assert_eq!(robot.joint_count(), joints, "{name}");
        let model = robot.nominal_model().unwrap();
        let zero = model.forward(&vec![0.0; joints], 0).unwrap();
        assert!((zero.to_matrix() - robot.base_from_flange_zero().to_matrix()).norm() < 1e-12, "{name}");
    }
}

#[test]
fn ur10_fixture_matches_the_published_dh_table() {
    let d = [0.1273, 0.0, 0.0, 0.163941, 0.1157, 0.0922];
    let a = [0.0, -0.612, -0.5723, 0.0, 0.0, 0.0];
    let alpha = [FRAC_PI_2, 0.0, 0.0, FRAC_PI_2, -FRAC_PI_2, 0.0];
    let rows: Vec<DhRow> =
        (0..6).map(|i| DhRow { kind: JointKind::Revolute, a: a[i], alpha: alpha[i], d: d[i], theta: 0.0 }).collect();
    let dh = LocalPoe::from_dh(&rows, DhConvention::Standard);
    let fixture = testkit::robot("ur10.ron").nominal_model().unwrap();
    let qs = [[0.0; 6], [0.3, -1.2, 0.8, 2.0, -0.5, 1.1], [-2.5, 0.4, -2.9, -1.0, 3.0, -0.2]];
    for q in qs {
        let a = dh.forward(&q, 0).unwrap();
        let b = fixture.forward(&q, 0).unwrap();
        assert!((a.to_matrix() - b.to_matrix()).norm() < 1e-9, "q = {q:?}");
    }
}

#[test]
fn irb4400_positive_joint_two_tilts_the_arm_forward() {
    let model = testkit::robot("irb4400.ron").nominal_model().unwrap();
    let up = model.forward(&[0.0; 6], 0).unwrap().translation();
    let tilted = model.forward(&[0.0, 0.3, 0.0, 0.0, 0.0, 0.0], 0).unwrap().translation();
    assert!(tilted.x > up.x && tilted.z < up.z);
}

const GOOD: &str = r#"// a two-joint robot
Robot(
    name: "two",
    joints: [
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.0), limits_deg: (-90.0, 90.0)),
        (kind: Prismatic, axis: (1.0, 0.0, 0.0), point: (0.0, 0.0, 1.0), limits_m: (0.0, 0.5)),
    ],
    flange: (position: (1.0, 0.0, 1.0), x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0)),
    tool: (0.0, 0.0, 0.1),
)
"#;

fn refuse(text: &str) -> (usize, usize, String) {
    let e = RobotDescription::parse(text, "robot.ron").expect_err("a RON error");
    let (Some((line, column)), ErrorKind::RonFormat { message }) = (e.position(), e.kind()) else {
        panic!("expected a RON error, got {e:?}")
    };
    (line as usize, column, message.clone())
}

#[test]
fn a_good_description_reads_with_si_limits_and_its_tool() {
    let robot = RobotDescription::parse(GOOD, "robot.ron").unwrap();
    assert_eq!(robot.limits()[1], (0.0, 0.5));
    assert!((robot.limits()[0].1 - FRAC_PI_2).abs() < 1e-15);
    let model = robot.nominal_model().unwrap();
    let tool = model.forward(&[0.0, 0.2], 0).unwrap().translation();
    assert!((tool - lie::Vector3::new(1.2, 0.0, 1.1)).norm() < 1e-12, "{tool}");
}

#[test]
fn a_syntax_error_is_refused_at_its_line_and_column() {
    let (line, column, message) = refuse(&GOOD.replace("point: (0.0, 0.0, 1.0)", "point: (0.0, 0.0 1.0)"));
    assert_eq!(line, 6, "{message}");
    assert!(column > 40, "{column}: {message}");
}

#[test]
fn an_unknown_field_is_refused() {
    let (line, _, message) = refuse(&GOOD.replace("tool:", "toll:"));
    assert_eq!(line, 9, "{message}");
    assert!(message.contains("toll"), "{message}");
}

#[test]
fn a_non_unit_axis_is_refused_at_that_axis() {
    let (line, column, message) = refuse(&GOOD.replace("axis: (1.0, 0.0, 0.0)", "axis: (2.0, 0.0, 0.0)"));
    assert_eq!((line, column), (6, 27), "{message}");
    assert!(message.contains("joint 2: axis has norm 2"), "{message}");
}

#[test]
fn limits_of_the_wrong_unit_or_order_are_refused() {
    let (line, _, message) = refuse(&GOOD.replace("limits_m: (0.0, 0.5)", "limits_deg: (0.0, 0.5)"));
    assert_eq!(line, 6, "{message}");
    assert!(message.contains("limits_deg does not fit"), "{message}");
    let (line, column, message) = refuse(&GOOD.replace("(-90.0, 90.0)", "(90.0, -90.0)"));
    assert_eq!((line, column), (5, 73), "{message}");
    assert!(message.contains("increasing"), "{message}");
    // Limits of 1e308 degrees are finite and increasing, and sampled poses overflowed into NaN
    // (found by `cargo xtask fuzz`): refused at the limits, for either kind of joint.
    let (line, column, message) = refuse(&GOOD.replace("(-90.0, 90.0)", "(-1e308, 90.0)"));
    assert_eq!((line, column), (5, 73), "{message}");
    assert!(message.contains("joint 1: limits (-1e308, 9e1) reach beyond ±1e6 rad"), "{message}");
    let (line, _, message) = refuse(&GOOD.replace("limits_m: (0.0, 0.5)", "limits_m: (0.0, 5000.0)"));
    assert_eq!(line, 6, "{message}");
    assert!(message.contains("beyond ±1e3 m"), "{message}");
}

#[test]
fn flange_axes_that_are_not_perpendicular_are_refused() {
    let (line, _, message) = refuse(&GOOD.replace("x_axis: (1.0, 0.0, 0.0)", "x_axis: (0.0, 0.0, 1.0)"));
    assert_eq!(line, 8, "{message}");
    assert!(message.contains("perpendicular"), "{message}");
}

#[test]
fn dynamics_of_the_wrong_length_are_refused() {
    let text = GOOD.replace(
        "    tool: (0.0, 0.0, 0.1),\n",
        "    dynamics: (links: [(mass_kg: 1.0, com_m: (0.0, 0.0, 0.5))], stiffness_nm_per_rad: [1e5, 1e5]),\n",
    );
    let (line, _, message) = refuse(&text);
    assert_eq!(line, 9, "{message}");
    assert!(message.contains("1 links given"), "{message}");
}

/// A `dynamics` block may leave the stiffness out (masses only, as a URDF gives them): it reads,
/// and a stiffness list of the wrong length is still refused.
#[test]
fn dynamics_without_stiffness_read_and_a_short_stiffness_list_is_refused() {
    let masses =
        "    dynamics: (links: [(mass_kg: 1.0, com_m: (0.0, 0.0, 0.5)), (mass_kg: 2.0, com_m: (0.5, 0.0, 1.0))]),\n";
    let robot = RobotDescription::parse(&GOOD.replace("    tool: (0.0, 0.0, 0.1),\n", masses), "robot.ron").unwrap();
    let dynamics = robot.dynamics.expect("masses read");
    assert_eq!(dynamics.links[1].mass_kg, 2.0);
    assert!(dynamics.stiffness_nm_per_rad.is_empty());
    assert!(dynamics.stiffness("joint compliance").is_err());
    let short = masses.replace("]),", "], stiffness_nm_per_rad: [1e5]),");
    let (line, _, message) = refuse(&GOOD.replace("    tool: (0.0, 0.0, 0.1),\n", &short));
    assert_eq!(line, 9, "{message}");
    assert!(message.contains("1 stiffness values given"), "{message}");
}

/// The refusal of a value that must be finite: its field and where it is.
fn refuse_not_finite(text: &str) -> (usize, usize, String, String) {
    let e = RobotDescription::parse(text, "robot.ron").expect_err("a NotFinite error");
    let (Some((line, column)), ErrorKind::NotFinite { field, .. }) = (e.position(), e.kind()) else {
        panic!("expected a NotFinite error, got {e:?}")
    };
    (line as usize, column, field.clone(), e.to_string())
}

#[test]
fn a_nan_flange_position_is_refused_at_the_flange_not_downstream() {
    // Once accepted, then "refused" by the fit as "the poses are too alike to register the
    // tracker: rank 0 of 13", which sent the user to the data file.
    let (line, column, field, message) =
        refuse_not_finite(&GOOD.replace("position: (1.0, 0.0, 1.0)", "position: (NaN, 0.0, 1.0)"));
    assert_eq!((line, column, field.as_str()), (8, 14, "flange.position"), "{message}");
    assert_eq!(message, "robot.ron:8:14: flange.position is NaN, a finite number is needed");
    let (line, _, field, message) =
        refuse_not_finite(&GOOD.replace("z_axis: (0.0, 0.0, 1.0)", "z_axis: (0.0, NaN, 1.0)"));
    assert_eq!((line, field.as_str()), (8, "flange.z_axis"), "{message}");
}

#[test]
fn an_infinite_tool_is_refused_at_the_tool() {
    let (line, column, field, message) =
        refuse_not_finite(&GOOD.replace("tool: (0.0, 0.0, 0.1)", "tool: (0.0, inf, 0.1)"));
    assert_eq!((line, column, field.as_str()), (9, 5, "tool"), "{message}");
}

const DYNAMICS: &str = "    dynamics: (\n        links: [(mass_kg: 1.0, com_m: (0.0, 0.0, 0.5)), (mass_kg: 1.0, com_m: (0.5, 0.0, 1.0))],\n        stiffness_nm_per_rad: [1e5, 1e5],\n        gravity_m_per_s2: (0.0, 0.0, -9.81),\n        counterbalance: (joint_index: 0, anchor_radius_m: 0.3, attachment_radius_m: 0.2, angle_at_zero_rad: 0.0, force_at_zero_n: 100.0, stiffness_n_per_m: 1000.0),\n    ),\n";

fn with_dynamics(edit: (&str, &str)) -> String {
    GOOD.replace(
        "    tool: (0.0, 0.0, 0.1),\n",
        &format!("    tool: (0.0, 0.0, 0.1),\n{}", DYNAMICS.replace(edit.0, edit.1)),
    )
}

#[test]
fn good_dynamics_are_read() {
    let robot = RobotDescription::parse(&with_dynamics(("", "")), "robot.ron").unwrap();
    assert_eq!(robot.dynamics.unwrap().links.len(), 2);
}

#[test]
fn non_finite_load_data_is_refused_at_its_field() {
    let (line, _, field, message) =
        refuse_not_finite(&with_dynamics(("com_m: (0.5, 0.0, 1.0)", "com_m: (0.5, NaN, 1.0)")));
    assert_eq!((line, field.as_str()), (11, "links[1].com_m"), "{message}");
    let (line, column, field, message) = refuse_not_finite(&with_dynamics((
        "gravity_m_per_s2: (0.0, 0.0, -9.81)",
        "gravity_m_per_s2: (0.0, 0.0, -inf)",
    )));
    assert_eq!((line, column, field.as_str()), (13, 9, "gravity_m_per_s2"), "{message}");
    let (line, _, field, message) =
        refuse_not_finite(&with_dynamics(("force_at_zero_n: 100.0", "force_at_zero_n: NaN")));
    assert_eq!((line, field.as_str()), (14, "counterbalance.force_at_zero_n"), "{message}");
}

#[test]
fn a_balancer_out_of_range_is_refused_at_its_field() {
    let (line, column, message) = refuse(&with_dynamics(("anchor_radius_m: 0.3", "anchor_radius_m: -0.3")));
    assert_eq!(line, 14, "{message}");
    assert!(column > 40 && message.contains("anchor_radius_m = -0.3"), "{column}: {message}");
    let (line, column, message) = refuse(&with_dynamics(("joint_index: 0", "joint_index: 5")));
    assert_eq!((line, column), (14, 26), "{message}");
    assert!(message.contains("names joint 6 but the robot has 2 joints"), "{message}");
}

#[test]
fn finite_but_absurd_geometry_is_refused_at_its_field() {
    // Found by `cargo xtask fuzz` (seed 2026): a joint point of 1e308 m was read, and the forward
    // kinematics overflowed to infinity.
    let (line, column, message) = refuse(&GOOD.replace("point: (0.0, 0.0, 1.0)", "point: (0.0, 1e308, 1.0)"));
    assert_eq!(line, 6, "{message}");
    assert!(column > 1 && message.contains("joint 2: point coordinate 1e308 m is beyond ±1e3 m"), "{message}");
    let text = GOOD.replace("position: (1.0, 0.0, 1.0)", "position: (1.0, 0.0, 2e3)");
    let error = RobotDescription::parse(&text, "robot.ron").unwrap_err();
    assert!(
        matches!(error.kind(), ErrorKind::ModelValue { field, .. } if field == "flange.position")
            && matches!(error.position(), Some((8, _))),
        "{error}"
    );
}

/// A linear axis may state its screw lead; older files without it read as before, and a
/// lead on a revolute joint or out of bounds is refused at it.
#[test]
fn a_screw_pitch_reads_on_a_prismatic_joint_and_is_refused_elsewhere_or_out_of_bounds() {
    assert_eq!(RobotDescription::parse(GOOD, "robot.ron").unwrap().joints[1].pitch_mm, None);
    let pitched = GOOD.replace("limits_m: (0.0, 0.5)", "limits_m: (0.0, 0.5), pitch_mm: 10.0");
    assert_eq!(RobotDescription::parse(&pitched, "robot.ron").unwrap().joints[1].pitch_mm, Some(10.0));
    let (line, column, message) =
        refuse(&GOOD.replace("limits_deg: (-90.0, 90.0)", "limits_deg: (-90.0, 90.0), pitch_mm: 5.0"));
    assert_eq!((line, column), (5, 100), "{message}");
    assert!(message.contains("joint 1: pitch_mm is a linear axis's screw lead, and joint 1 is Revolute"), "{message}");
    let (line, _, message) = refuse(&GOOD.replace("limits_m: (0.0, 0.5)", "limits_m: (0.0, 0.5), pitch_mm: 0.0"));
    assert_eq!(line, 6, "{message}");
    assert!(message.contains("pitch_mm 0e0 must be a number from 0.01 to 10000 mm"), "{message}");
}
