//! Tracker exports as they come (SPEC v2): `;` separators and decimal commas detected and reported,
//! Euler angle columns, and a column map for any other header; every refusal at its file, line
//! and column.

use errors::Error;
use lie::{Matrix3, SO3};
use measurements::{ColumnMap, Decimal, Delimiter, ReadOptions, parse_measurements};
use measurements::{ColumnMapFault, DecimalFault, ErrorKind};
use poe::JointKind;

fn two_joints() -> ReadOptions {
    ReadOptions::for_joints(vec![JointKind::Revolute; 2])
}

fn read(text: &str, options: &ReadOptions) -> measurements::MeasurementSet {
    parse_measurements(text.as_bytes(), "export.csv", options).unwrap_or_else(|e| panic!("{e}"))
}

fn refuse(text: &str, options: &ReadOptions) -> (Error, String) {
    let error = parse_measurements(text.as_bytes(), "export.csv", options).expect_err("the file must be refused");
    let message = error.to_string();
    (error, message)
}

fn map(text: &str) -> ColumnMap {
    text.parse().unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn semicolons_and_decimal_commas_are_detected_and_reported() {
    let set = read("q1_rad;q2_rad;x_mm;y_mm;z_mm\n0,5;-1,25;1000,5;2;3E+2\n0;1;2;3;4\n", &two_joints());
    assert_eq!(set.format.dialect.delimiter, Delimiter::Semicolon);
    assert_eq!(set.format.dialect.decimal, Some(Decimal::Comma));
    assert_eq!(set.format.to_string(), "';'-separated, decimal comma");
    assert_eq!(set.rows[0].q, vec![0.5, -1.25]);
    assert!((set.rows[0].position - lie::Vector3::new(1.0005, 0.002, 0.3)).norm() < 1e-15);
}

#[test]
fn semicolons_with_decimal_points_and_whole_numbers_are_told_apart() {
    let set = read("q1_rad;q2_rad;x_mm;y_mm;z_mm\n0.5;-1.25;1000.5;2;3\n", &two_joints());
    assert_eq!(set.format.dialect.decimal, Some(Decimal::Point));
    let set = read("q1_rad;q2_rad;x_mm;y_mm;z_mm\n0;1;1000;2;3\n", &two_joints());
    assert_eq!(set.format.to_string(), "';'-separated, whole numbers only");
    let set = read("q1_rad,q2_rad,x_mm,y_mm,z_mm\n0,1,1000.5,2,3\n", &two_joints());
    assert_eq!(set.format.to_string(), "','-separated, decimal point");
}

#[test]
fn a_decimal_comma_in_a_comma_separated_file_is_refused_at_its_cell() {
    // Unquoted, the comma splits the number into two fields.
    let (error, message) = refuse("q1_rad,q2_rad,x_mm,y_mm,z_mm\n0,1,1000,5,2,3\n", &two_joints());
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::FieldCount { found: 6, expected: 5, .. }))
            && matches!(error.position(), Some((2, 6))),
        "{message}"
    );
    assert!(message.starts_with("export.csv:2:6: row has 6 fields, the header has 5 (decimal commas"), "{message}");
    // Quoted, it is one cell with a decimal comma.
    let (error, message) = refuse("q1_rad,q2_rad,x_mm,y_mm,z_mm\n0,1,\"1000,5\",2,3\n", &two_joints());
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::DecimalMark { fault: DecimalFault::CommaInCommaFile, .. }))
            && matches!(error.position(), Some((2, 3))),
        "{message}"
    );
    assert!(message.starts_with("export.csv:2:3: column 'x_mm': '1000,5' has a decimal comma"), "{message}");
}

#[test]
fn a_decimal_mark_that_changes_within_a_file_is_refused_at_its_cell() {
    let (error, message) = refuse("q1_rad;q2_rad;x_mm;y_mm;z_mm\n0,5;1;2;3;4\n0;1;2.5;3;4\n", &two_joints());
    assert!(
        matches!(
            error.kind::<ErrorKind>(),
            Some(ErrorKind::DecimalMark { fault: DecimalFault::Other { expected: ',' }, .. })
        ) && matches!(error.position(), Some((3, 3))),
        "{message}"
    );
    assert_eq!(
        message,
        "export.csv:3:3: column 'x_mm': '2.5' does not use the file's decimal mark ',' (set by its first numbers)"
    );
    // Thousands separators are not guessed at.
    let (error, message) = refuse("q1_rad;q2_rad;x_mm;y_mm;z_mm\n0;1;1.000,5;3;4\n", &two_joints());
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::NotANumber { .. }))
            && matches!(error.position(), Some((2, 3))),
        "{message}"
    );
}

/// `Rx(a) · Ry(b) · Rz(c)` written out element by element.
fn rx_ry_rz(a: f64, b: f64, c: f64) -> Matrix3 {
    let (sa, ca, sb, cb, sc, cc) = (a.sin(), a.cos(), b.sin(), b.cos(), c.sin(), c.cos());
    let x = Matrix3::new(1.0, 0.0, 0.0, 0.0, ca, -sa, 0.0, sa, ca);
    let y = Matrix3::new(cb, 0.0, sb, 0.0, 1.0, 0.0, -sb, 0.0, cb);
    let z = Matrix3::new(cc, -sc, 0.0, sc, cc, 0.0, 0.0, 0.0, 1.0);
    x * y * z
}

#[test]
fn euler_angle_columns_give_r_equal_rx_ry_rz_in_either_unit() {
    let set = read(
        "q1_rad;q2_rad;x_mm;y_mm;z_mm;rx_deg;ry_deg;rz_deg\n0;0;1;2;3;-90,179563;-20,112975;-90,157388\n",
        &two_joints(),
    );
    assert!(set.full_pose && set.format.euler_angles);
    assert!(set.format.to_string().ends_with("; orientation from Euler angles (R = Rx·Ry·Rz)"));
    let expected = rx_ry_rz((-90.179563f64).to_radians(), (-20.112975f64).to_radians(), (-90.157388f64).to_radians());
    assert!((set.rows[0].orientation.unwrap().matrix() - expected).norm() < 1e-14);
    let set = read("q1_rad,q2_rad,x_mm,y_mm,z_mm,rz_rad,ry_rad,rx_rad\n0,0,1,2,3,0.3,-0.2,0.1\n", &two_joints());
    assert!((set.rows[0].orientation.unwrap().matrix() - rx_ry_rz(0.1, -0.2, 0.3)).norm() < 1e-14);
}

#[test]
fn a_huge_euler_angle_gives_a_rotation_not_a_nan() {
    let set = read("q1_rad,q2_rad,x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg\n0,0,1,2,3,1e300,0,-1e300\n", &two_joints());
    let r = set.rows[0].orientation.unwrap();
    assert!(r.matrix().iter().all(|v| v.is_finite()));
    assert!((r.matrix().transpose() * r.matrix() - Matrix3::identity()).norm() < 1e-12);
}

#[test]
fn euler_angles_together_with_a_quaternion_are_refused() {
    let header = "q1_rad,q2_rad,x_mm,y_mm,z_mm,qw,qx,qy,qz,rx_deg,ry_deg,rz_deg";
    let (error, message) = refuse(&format!("{header}\n0,0,1,2,3,1,0,0,0,0,0,0\n"), &two_joints());
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::OrientationTwice { .. }))
            && matches!(error.position(), Some((1, 10))),
        "{message}"
    );
    assert!(message.starts_with("export.csv:1:10: column 'rx_deg': the orientation is already given by 'qw'"));
    let (error, message) = refuse("q1_rad,q2_rad,x_mm,y_mm,z_mm,rx_deg,rz_deg\n0,0,1,2,3,0,0\n", &two_joints());
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::MissingColumn { name, .. }) if name == "ry_deg")
            && matches!(error.position(), Some((_, 8))),
        "{message}"
    );
}

const EXPORT: &str = "Timestamp;Joint 1;Joint 2;X  [mm];Y [mm];Z [mm];Q0;Q1;Q2;Q3;Operator\n\
                      2,02011E+13;0,1;0,2;1000,5;-3,25;7;1;0;0;0;ann\n";

#[test]
fn a_column_map_reads_any_header_and_is_reported() {
    let columns =
        map("q1_rad=Joint 1, q2_rad=\"Joint 2\",x_mm=\"X  [mm]\",y_mm=Y [mm],z_mm=Z [mm],qw=Q0,qx=Q1,qy=Q2,qz=Q3");
    assert_eq!(columns.entries()[2], ("x_mm".to_owned(), "X  [mm]".to_owned()));
    let set = read(EXPORT, &two_joints().with_columns(columns));
    assert_eq!(set.rows[0].q, vec![0.1, 0.2]);
    assert!((set.rows[0].position - lie::Vector3::new(1.0005, -0.00325, 0.007)).norm() < 1e-15);
    assert_eq!(set.rows[0].orientation, Some(SO3::identity()));
    assert_eq!(set.ignored_columns, vec!["Timestamp".to_owned(), "Operator".to_owned()]);
    assert_eq!(set.format.mapped_columns.len(), 9);
    assert_eq!(set.format.to_string(), "';'-separated, decimal comma; 9 columns named by --columns");
}

#[test]
fn a_column_map_naming_a_header_the_file_lacks_is_refused() {
    let columns = map("q1_rad=Joint 1,q2_rad=Joint 2,x_mm=X [mm],y_mm=Y [mm],z_mm=Z [mm]");
    let (error, message) = refuse(EXPORT, &two_joints().with_columns(columns));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::MappedHeaderMissing { .. }))
            && matches!(error.position(), Some((1, 12))),
        "{message}"
    );
    assert_eq!(message, "export.csv:1:12: --columns maps x_mm to the header 'X [mm]', which the file does not have");
}

#[test]
fn a_column_map_onto_a_name_the_file_already_has_is_a_duplicate() {
    let columns = map("x_mm=X");
    let (error, message) = refuse("q1_rad,q2_rad,x_mm,X,y_mm,z_mm\n0,0,1,1,2,3\n", &two_joints().with_columns(columns));
    assert!(
        matches!(error.kind::<ErrorKind>(), Some(ErrorKind::DuplicateColumn { .. }))
            && matches!(error.position(), Some((1, 4))),
        "{message}"
    );
}

#[test]
fn bad_column_maps_are_refused_at_their_character() {
    let cases: [(&str, usize, ColumnMapFault); 8] = [
        ("", 1, ColumnMapFault::Empty),
        ("x_mm=X,x_cm=Y", 8, ColumnMapFault::UnknownTarget),
        ("x_mm=X, y_mm", 9, ColumnMapFault::MissingEquals),
        ("x_mm=", 1, ColumnMapFault::EmptyHeader),
        ("x_mm=\"X, mm", 6, ColumnMapFault::UnclosedQuote),
        ("x_mm=\"X\" mm", 1, ColumnMapFault::TextAfterQuote),
        ("x_mm=X,x_mm=Y", 8, ColumnMapFault::DuplicateTarget),
        ("x_mm=X,y_mm=X", 8, ColumnMapFault::DuplicateHeader),
    ];
    for (text, column, fault) in cases {
        let error = text.parse::<ColumnMap>().expect_err(text);
        assert!(
            matches!(error.kind::<ErrorKind>(), Some(ErrorKind::ColumnMap { fault: f, .. }) if *f == fault)
                && error.position() == Some((1, column)),
            "{text}: {error}"
        );
        assert!(error.to_string().starts_with(&format!("--columns:1:{column}: ")), "{error}");
    }
    let error = "x_mm=X,x_cm=Y".parse::<ColumnMap>().unwrap_err();
    assert!(error.to_string().starts_with("--columns:1:8: 'x_cm=Y' is not a SPEC column name"), "{error}");
}

#[test]
fn a_byte_order_mark_before_the_header_is_not_part_of_its_first_name() {
    let set = read("\u{feff}q1_rad;q2_rad;x_mm;y_mm;z_mm\n0;1;2;3;4\n", &two_joints());
    assert_eq!(set.rows.len(), 1);
}
