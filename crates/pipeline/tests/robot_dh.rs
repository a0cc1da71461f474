//! DH tables in the robot RON: a flange given with a table, and every refusal at its line and
//! column (the forward kinematics of every form are in `robot_forms.rs`).

use errors::CommonKind;
use robot::RobotDescription;

const TABLE: &str = r#"Robot(
    name: "three",
    dh: (
        convention: CONVENTION,
        rows: [
            (kind: Revolute, a_m: 0.1, alpha_deg: 90.0, d_m: 0.3, theta_deg: 10.0, limits_deg: (-90.0, 90.0)),
            (kind: Prismatic, a_m: 0.4, alpha_rad: -0.3, d_m: 0.05, theta_rad: 0.2, limits_m: (0.0, 0.5)),
            (kind: Revolute, a_m: -0.2, alpha_deg: -45.0, d_m: 0.1, theta_deg: -30.0, limits_deg: (-170.0, 170.0)),
        ],
    ),
)
"#;

#[test]
fn a_flange_given_with_a_table_replaces_the_last_dh_frame() {
    let text = TABLE.replace("CONVENTION", "Standard").replace(
        "    ),\n)",
        "    ),\n    flange: (position: (1.0, 2.0, 3.0), x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0)),\n)",
    );
    let robot = RobotDescription::parse(&text, "three.ron").unwrap();
    let zero = robot.nominal_model().unwrap().forward(&[0.0; 3], 0).unwrap();
    assert!((zero.translation() - lie::Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
}

fn refuse(text: &str) -> (usize, usize, String) {
    let e = RobotDescription::parse(text, "three.ron").expect_err("a RON error");
    let shown = e.to_string();
    assert!(shown.starts_with("three.ron:"), "{shown}");
    let (Some((line, column)), Some(CommonKind::RonFormat { message })) = (e.position(), e.kind::<CommonKind>()) else {
        panic!("expected a RON error, got {e:?}")
    };
    (line as usize, column, message.clone())
}

#[test]
fn a_row_with_a_wrong_column_is_refused_at_it() {
    let text = TABLE.replace("CONVENTION", "Standard").replace("d_m: 0.05", "dd_m: 0.05");
    let (line, column, message) = refuse(&text);
    assert_eq!(line, 7, "{message}");
    assert!(column > 30, "{column}");
    assert!(message.contains("dd_m"), "{message}");
}

#[test]
fn a_row_without_a_column_is_refused_at_it() {
    let text = TABLE.replace("CONVENTION", "Standard").replace("a_m: 0.4, ", "");
    let (line, _, message) = refuse(&text);
    assert_eq!(line, 7, "{message}");
    assert!(message.contains("a_m"), "{message}");
}

#[test]
fn an_angle_given_twice_or_not_at_all_is_refused_at_its_row() {
    let text = TABLE.replace("CONVENTION", "Standard").replace("alpha_rad: -0.3,", "alpha_rad: -0.3, alpha_deg: 2.0,");
    let (line, column, message) = refuse(&text);
    assert_eq!((line, column), (7, 31), "{message}");
    assert!(message.contains("DH row 2: give alpha_deg or alpha_rad, not both"), "{message}");
    let text = TABLE.replace("CONVENTION", "Standard").replace(" theta_deg: -30.0,", "");
    let (line, _, message) = refuse(&text);
    assert_eq!(line, 8, "{message}");
    assert!(message.contains("DH row 3: theta_deg (or theta_rad) is required"), "{message}");
}

#[test]
fn an_unknown_convention_is_refused_at_it() {
    let (line, column, message) = refuse(&TABLE.replace("CONVENTION", "Distal"));
    assert_eq!((line, column), (4, 21), "{message}");
}

#[test]
fn limits_in_a_table_are_checked_like_axes_limits() {
    let text = TABLE.replace("CONVENTION", "Standard").replace("(-170.0, 170.0)", "(170.0, -170.0)");
    let (line, _, message) = refuse(&text);
    assert_eq!(line, 8, "{message}");
    assert!(message.contains("increasing"), "{message}");
}

#[test]
fn joints_and_a_table_together_or_neither_are_refused() {
    let text = TABLE.replace("CONVENTION", "Standard").replace("    dh: (", "    joints: [],\n    dh: (");
    let (line, _, message) = refuse(&text);
    assert_eq!(line, 4, "{message}");
    assert!(message.contains("not both"), "{message}");
    let (line, _, message) = refuse("Robot(\n    name: \"none\",\n)");
    assert_eq!(line, 2, "{message}");
    assert!(message.contains("no kinematics"), "{message}");
}
