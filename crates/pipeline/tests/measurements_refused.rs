//! Every bad measurement file the SPEC lists is refused with its file, line and column.

use errors::Error;
use measurements::ErrorKind;
use measurements::{ReadOptions, parse_measurements};
use poe::JointKind;

/// Reading for a robot of `joints` revolute joints, or for any robot.
fn revolute(joints: Option<usize>) -> ReadOptions {
    joints.map_or_else(ReadOptions::default, |n| ReadOptions::for_joints(vec![JointKind::Revolute; n]))
}

fn refuse(text: &str, joints: Option<usize>) -> (Error, String) {
    refuse_with(text, &revolute(joints))
}

fn refuse_with(text: &str, options: &ReadOptions) -> (Error, String) {
    let error = parse_measurements(text.as_bytes(), "cell.csv", options).expect_err("the file must be refused");
    let message = error.to_string();
    (error, message)
}

const HEADER2: &str = "q1_rad,q2_rad,x_mm,y_mm,z_mm";

#[test]
fn an_empty_file_is_refused() {
    let (error, message) = refuse("", None);
    assert!(matches!(error.kind::<ErrorKind>(), Some(ErrorKind::EmptyFile)), "{message}");
    assert_eq!(message, "cell.csv:1:1: the file has no header or no data row");
}

#[test]
fn a_header_without_rows_is_refused() {
    let (error, message) = refuse(&format!("{HEADER2}\n"), Some(2));
    assert!(matches!(error.kind::<ErrorKind>(), Some(ErrorKind::EmptyFile)), "{message}");
}

#[test]
fn a_missing_position_column_is_refused_at_the_end_of_the_header() {
    let (error, message) = refuse("q1_rad,q2_rad,x_mm,z_mm\n0,0,1,2\n", Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::MissingColumn { name, .. }) if name == "y_mm")
            && matches!(error.position(), Some((1, 5))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:1:5: missing required column 'y_mm'");
}

#[test]
fn a_gap_in_the_joint_columns_is_refused() {
    let (error, message) = refuse("q1_rad,q3_rad,x_mm,y_mm,z_mm\n0,0,1,2,3\n", None);
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::MissingColumn { name, .. }) if name == "q2_rad"),
        "{message}"
    );
}

#[test]
fn a_partial_quaternion_is_refused() {
    let (error, message) = refuse(&format!("{HEADER2},qw,qx,qy\n0,0,1,2,3,1,0,0\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::MissingColumn { name, .. }) if name == "qz"),
        "{message}"
    );
}

#[test]
fn a_duplicate_header_is_refused_at_its_second_occurrence() {
    let (error, message) = refuse("q1_rad,q2_rad,x_mm,y_mm,z_mm,y_mm\n0,0,1,2,3,4\n", Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::DuplicateColumn { .. }))
            && matches!(error.position(), Some((1, 6))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:1:6: column 'y_mm' appears more than once");
}

#[test]
fn one_quantity_in_two_units_is_a_duplicate() {
    let (error, message) = refuse("q1_rad,q1_deg,x_mm,y_mm,z_mm\n0,0,1,2,3\n", None);
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::DuplicateColumn { .. }))
            && matches!(error.position(), Some((_, 2))),
        "{message}"
    );
    let (error, message) = refuse("q1_rad,x_mm,x_m,y_mm,z_mm\n0,0,1,2,3\n", None);
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::DuplicateColumn { .. }))
            && matches!(error.position(), Some((_, 3))),
        "{message}"
    );
}

#[test]
fn a_non_number_is_refused_at_its_cell() {
    let (error, message) = refuse(&format!("{HEADER2}\n0,0,1,2,3\n0,0.5,1,abc,3\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::NotANumber { .. }))
            && matches!(error.position(), Some((3, 4))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:3:4: column 'y_mm': 'abc' is not a finite number");
}

#[test]
fn nan_and_infinity_are_refused() {
    for bad in ["NaN", "nan", "inf", "-Infinity", ""] {
        let (error, message) = refuse(&format!("{HEADER2}\n0,{bad},1,2,3\n"), Some(2));
        assert!(
            matches!(error.kind::<ErrorKind>(), Some(ErrorKind::NotANumber { .. }))
                && matches!(error.position(), Some((2, 2))),
            "{bad}: {message}"
        );
    }
}

#[test]
fn a_bad_optional_column_is_refused_too() {
    let (error, message) = refuse(&format!("{HEADER2},payload_kg,temp_c\n0,0,1,2,3,five,20\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::NotANumber { .. }))
            && matches!(error.position(), Some((_, 6))),
        "{message}"
    );
}

#[test]
fn a_joint_count_that_does_not_match_the_robot_is_refused() {
    let (error, message) = refuse(&format!("{HEADER2}\n0,0,1,2,3\n"), Some(6));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::JointCountMismatch { found: 2, expected: 6, .. }))
            && matches!(error.position(), Some((1, _))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:1:6: 2 joint columns, the robot has 6 joints");
    let (error, message) = refuse("q1_rad,q2_rad,q3_rad,x_mm,y_mm,z_mm\n0,0,0,1,2,3\n", Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::JointCountMismatch { .. }))
            && matches!(error.position(), Some((_, 3))),
        "{message}"
    );
}

#[test]
fn a_quaternion_off_unit_norm_is_refused() {
    let (error, message) =
        refuse(&format!("{HEADER2},qw,qx,qy,qz\n0,0,1,2,3,1,0,0,0\n0,0,1,2,3,1.01,0,0,0\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::QuaternionNorm { .. }))
            && matches!(error.position(), Some((3, 6))),
        "{message}"
    );
    assert!(message.starts_with("cell.csv:3:6: quaternion"), "{message}");
}

#[test]
fn a_row_with_a_missing_field_is_refused_at_its_line() {
    let (error, message) = refuse(&format!("{HEADER2}\n0,0,1,2,3\n0,0,1,2\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::FieldCount { found: 4, expected: 5, .. }))
            && matches!(error.position(), Some((3, 5))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:3:5: row has 4 fields, the header has 5");
}

#[test]
fn a_good_file_is_read_in_si_units_with_its_extras() {
    let text = "tool,q2_deg,q1_rad,x_m,y_mm,z_mm,qw,qx,qy,qz,payload_kg,temp_c,t_s,operator\n\
                A,90,0.5,1.5,2000,3,1,0,0,0,2.5,21.5,10,ann\n\
                B,0,0,0,0,0,0,1,0,0,0,22,20,bob\n\
                A,0,0,0,0,0,0,0,1,0,0,22,30,bob\n";
    let set = parse_measurements(text.as_bytes(), "good.csv", &revolute(Some(2))).unwrap();
    assert_eq!(set.rows.len(), 3);
    assert!(set.full_pose);
    assert_eq!(set.tools, vec!["A".to_owned(), "B".to_owned()]);
    assert_eq!(set.rows.iter().map(|r| r.tool).collect::<Vec<_>>(), vec![0, 1, 0]);
    let first = &set.rows[0];
    assert_eq!(first.line, 2);
    assert!((first.q[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(first.q[0], 0.5);
    assert!((first.position - lie::Vector3::new(1.5, 2.0, 0.003)).norm() < 1e-15);
    assert_eq!((first.payload_kg, first.temp_c, first.t_s), (2.5, Some(21.5), Some(10.0)));
    assert_eq!(set.ignored_columns, vec!["operator".to_owned()]);
}

#[test]
fn written_sets_read_back_unchanged() {
    let text = "q1_rad,q2_rad,x_mm,y_mm,z_mm,qw,qx,qy,qz,payload_kg,tool,temp_c,t_s\n\
                0.1,-0.2,1000.5,-3.25,7,0.8,0.6,0,0,1.5,T1,20,0\n\
                0.3,0.4,999,3,-7,0,0,0.6,0.8,0,T2,21,60\n";
    let set = parse_measurements(text.as_bytes(), "a.csv", &revolute(Some(2))).unwrap();
    let mut buffer = Vec::new();
    set.write_csv(&mut buffer).unwrap();
    let again = parse_measurements(buffer.as_slice(), "a.csv", &revolute(Some(2))).unwrap();
    assert_eq!(again.tools, set.tools);
    for (a, b) in set.rows.iter().zip(&again.rows) {
        assert_eq!(a.q, b.q);
        assert!((a.position - b.position).norm() < 1e-15);
        let (ra, rb) = (a.orientation.unwrap(), b.orientation.unwrap());
        assert!((ra.matrix() - rb.matrix()).norm() < 1e-15);
        assert_eq!((a.payload_kg, a.temp_c, a.t_s, a.tool), (b.payload_kg, b.temp_c, b.t_s, b.tool));
    }
}

#[test]
fn an_angle_unit_on_a_prismatic_joint_is_refused_at_its_column() {
    let options = ReadOptions::for_joints(vec![JointKind::Revolute, JointKind::Prismatic]);
    for name in ["q2_deg", "q2_rad"] {
        let (error, message) = refuse_with(&format!("q1_rad,{name},x_mm,y_mm,z_mm\n0,0,1,2,3\n"), &options);
        assert!(
            matches!(error.kind::<ErrorKind>(), Some(ErrorKind::JointUnit { joint: 2, .. }))
                && matches!(error.position(), Some((1, 2))),
            "{message}"
        );
        assert_eq!(message, "cell.csv:1:2: joint 2 is prismatic: its column is q2_m or q2_mm, not an angle");
    }
    let (error, message) = refuse_with("q1_mm,q2_m,x_mm,y_mm,z_mm\n0,0,1,2,3\n", &options);
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::JointUnit { joint: 1, .. }))
            && matches!(error.position(), Some((_, 1))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:1:1: joint 1 is revolute: its column is q1_rad or q1_deg, not a length");
}

#[test]
fn a_prismatic_joint_in_millimetres_is_read_in_metres() {
    let options = ReadOptions::for_joints(vec![JointKind::Revolute, JointKind::Prismatic]);
    let set = parse_measurements("q1_deg,q2_mm,x_mm,y_mm,z_mm\n90,250,1,2,3\n".as_bytes(), "p.csv", &options).unwrap();
    assert_eq!(set.rows[0].q[1], 0.25);
    assert!((set.rows[0].q[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(set.joint_columns[1].kind, JointKind::Prismatic);
}

#[test]
fn a_negative_payload_is_refused_at_its_cell() {
    let (error, message) = refuse(&format!("{HEADER2},payload_kg\n0,0,1,2,3,0\n0,0,1,2,3,-2\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::NegativePayload { .. }))
            && matches!(error.position(), Some((3, 6))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:3:6: column 'payload_kg': -2 kg, a payload cannot be negative");
}

#[test]
fn a_huge_joint_number_in_a_header_is_refused_without_allocating_for_it() {
    // Each of these once sized a vector by the joint number: 2.4 TB and an abort, or 80 s and
    // 21 GB before the refusal.
    for name in ["q99999999999_rad", "q900000000_rad", "q99999999999999999999999_deg"] {
        let text = format!("q1_rad,q2_rad,{name},x_mm,y_mm,z_mm\n0,0,0,1,2,3\n");
        let (error, message) = refuse(&text, Some(2));
        assert!(
            matches!(error.kind::<ErrorKind>(), Some(ErrorKind::JointCountMismatch { found: 3, expected: 2, .. }))
                && matches!(error.position(), Some((_, 3))),
            "{message}"
        );
        let (error, message) = refuse(&text, None);
        assert!(
            matches!(error.kind::<ErrorKind>(), Some(ErrorKind::MissingColumn { name, .. }) if name == "q3_rad")
                && matches!(error.position(), Some((_, 7))),
            "{message}"
        );
    }
    let (error, message) = refuse(&format!("{HEADER2},tau1_nm,tau99999999999_nm\n0,0,1,2,3,0,0\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::ColumnBeyondJoints { index: 99999999999, joints: 2, .. }))
            && matches!(error.position(), Some((_, 7))),
        "{message}"
    );
    assert_eq!(message, "cell.csv:1:7: column 'tau99999999999_nm' is for joint 99999999999, the data has 2 joints");
}

#[test]
fn torque_columns_must_cover_every_joint() {
    let (error, message) = refuse(&format!("{HEADER2},tau2_nm\n0,0,1,2,3,0\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::MissingColumn { name, .. }) if name == "tau1_nm")
            && matches!(error.position(), Some((_, 7))),
        "{message}"
    );
}

#[test]
fn invalid_utf8_is_refused_at_its_line_and_field() {
    let mut bytes = format!("{HEADER2},tool\n0,0,1,2,3,A\n0,0,1,2,3,").into_bytes();
    bytes.extend([0xff, 0xfe, b'\n']);
    let error = parse_measurements(bytes.as_slice(), "cell.csv", &revolute(Some(2))).unwrap_err();
    assert!(
        matches!(error.kind::<errors::CommonKind>(), Some(errors::CommonKind::InvalidUtf8))
            && matches!(error.position(), Some((3, 6))),
        "{error}"
    );
    assert_eq!(error.to_string(), "cell.csv:3:6: the text is not UTF-8");
}

#[test]
fn a_position_beyond_a_kilometre_is_refused_at_its_cell() {
    // 1e6 mm is 1 km, the bound itself: read. A tracker's range is under 100 m.
    let at_bound = format!("{HEADER2}\n0,0,1e6,0,0\n");
    assert!(parse_measurements(at_bound.as_bytes(), "cell.csv", &revolute(Some(2))).is_ok());
    let (error, message) = refuse(&format!("{HEADER2}\n0,0,1,2,3\n0,0,1,-1.5e6,3\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::BeyondPhysicalRange { name, .. }) if name == "y_mm")
            && matches!(error.position(), Some((3, 4))),
        "{message}"
    );
    assert_eq!(
        message,
        "cell.csv:3:4: column 'y_mm': -1.5e3 m is beyond any physical position (at most 1e3 m in magnitude): \
         check the column's unit"
    );
    let (error, _) = refuse("q1_rad,q2_rad,x_m,y_m,z_m\n0,0,0,0,2000\n", Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::BeyondPhysicalRange { .. }))
            && matches!(error.position(), Some((2, 5))),
        "{error}"
    );
}

#[test]
fn a_joint_angle_beyond_a_thousand_radians_is_refused_after_unit_conversion() {
    // 57,000 degrees is 994.8 rad: read; 58,000 degrees is 1012.3 rad: refused.
    let header = "q1_rad,q2_deg,x_mm,y_mm,z_mm";
    assert!(
        parse_measurements(format!("{header}\n1000,57000,1,2,3\n").as_bytes(), "cell.csv", &revolute(Some(2))).is_ok()
    );
    let (error, message) = refuse(&format!("{header}\n0,58000,1,2,3\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::BeyondPhysicalRange { name, .. }) if name == "q2_deg")
            && matches!(error.position(), Some((2, 2))),
        "{message}"
    );
    assert!(
        message.starts_with("cell.csv:2:2: column 'q2_deg': 1.0122")
            && message.contains("rad is beyond any physical joint angle (at most 1e3 rad in magnitude)"),
        "{message}"
    );
    let (error, message) = refuse(&format!("{header}\n-1000.5,0,1,2,3\n"), Some(2));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::BeyondPhysicalRange { .. }))
            && matches!(error.position(), Some((2, 1))),
        "{message}"
    );
}
