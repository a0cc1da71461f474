//! DH tables in the robot RON: the fixtures against their axes form, a table against poe's own
//! DH construction, and every refusal at its line and column.

use pipeline::{Error, RobotDescription};
use poe::{DhConvention, DhRow, JointKind, LocalPoe};
use std::path::PathBuf;

fn fixture(name: &str) -> RobotDescription {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name);
    RobotDescription::read(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Configurations spread over the joint ranges, the same for every form of a robot.
fn configurations(n: usize) -> Vec<Vec<f64>> {
    let mut qs = vec![vec![0.0; n]];
    for k in 1..8 {
        qs.push((0..n).map(|j| ((k * 7 + j * 3) as f64 * 0.61).sin() * 2.7).collect());
    }
    qs
}

fn largest_difference_m(a: &LocalPoe, b: &LocalPoe) -> f64 {
    configurations(a.joint_count())
        .iter()
        .map(|q| {
            let (ta, tb) = (a.forward(q, 0).unwrap(), b.forward(q, 0).unwrap());
            // Position of the flange and of points 1 m out along its axes: orientation in metres.
            [lie::Vector3::zeros(), lie::Vector3::x(), lie::Vector3::y(), lie::Vector3::z()]
                .iter()
                .map(|p| (ta.transform_point(p) - tb.transform_point(p)).norm())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

#[test]
fn dh_fixtures_have_the_forward_kinematics_of_their_axes_form() {
    for (dh, axes) in [("ur10_dh.ron", "ur10.ron"), ("iiwa7_dh.ron", "iiwa7.ron")] {
        let (a, b) = (fixture(dh), fixture(axes));
        assert_eq!(a.name, b.name);
        assert_eq!(a.limits(), b.limits(), "{dh}");
        let difference = largest_difference_m(&a.nominal_model().unwrap(), &b.nominal_model().unwrap());
        assert!(difference < 1e-9, "{dh}: {difference:e} m");
    }
}

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
fn a_table_in_either_convention_moves_like_poes_dh_model() {
    let rows = [
        DhRow { kind: JointKind::Revolute, a: 0.1, alpha: 90f64.to_radians(), d: 0.3, theta: 10f64.to_radians() },
        DhRow { kind: JointKind::Prismatic, a: 0.4, alpha: -0.3, d: 0.05, theta: 0.2 },
        DhRow { kind: JointKind::Revolute, a: -0.2, alpha: -45f64.to_radians(), d: 0.1, theta: -30f64.to_radians() },
    ];
    for (name, convention) in [("Standard", DhConvention::Standard), ("Modified", DhConvention::Modified)] {
        let robot = RobotDescription::parse(&TABLE.replace("CONVENTION", name), "three.ron").unwrap();
        let expected = LocalPoe::from_dh(&rows, convention);
        let difference = largest_difference_m(&robot.nominal_model().unwrap(), &expected);
        assert!(difference < 1e-12, "{name}: {difference:e} m");
        assert_eq!(robot.limits()[1], (0.0, 0.5));
    }
}

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
    match RobotDescription::parse(text, "three.ron") {
        Err(e @ Error::RonFormat { .. }) => {
            let message = e.to_string();
            assert!(message.starts_with("three.ron:"), "{message}");
            match e {
                Error::RonFormat { line, column, message, .. } => (line, column, message),
                _ => unreachable!(),
            }
        }
        other => panic!("expected a RON error, got {other:?}"),
    }
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
