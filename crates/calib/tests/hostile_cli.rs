//! The hostile-input table (nothing lost, no fit that looks right and is not) through the
//! binary, the rows that the other files do not hold: inputs a model does not cover are counted
//! and named, one absurd cell or a degenerate robot is refused with its place and cause. (`cargo xtask hostile` runs the whole table against a built binary.)

use std::path::Path;

mod common;
use common::{fails, fixture, succeeds_with_stderr as succeeds, text};

/// `from` with column `name` of data row `row` (1-based, or every row for 0) set to `value`.
fn with_cell(from: &Path, to: &Path, name: &str, row: usize, value: &str) {
    let content = std::fs::read_to_string(from).unwrap();
    let header: Vec<&str> = content.lines().next().unwrap().split(',').collect();
    let column = header.iter().position(|h| *h == name).unwrap();
    let lines: Vec<String> = content
        .lines()
        .enumerate()
        .map(|(i, line)| {
            let mut cells: Vec<&str> = line.split(',').collect();
            if i > 0 && (row == 0 || i == row) {
                cells[column] = value;
            }
            cells.join(",")
        })
        .collect();
    std::fs::write(to, lines.join("\n") + "\n").unwrap();
}

/// A simulated IRB 4400 campaign (payloads 1 … 7.5 kg) and a model of `method` fitted on it.
fn fitted(dir: &Path, extra: &[&str]) -> (std::path::PathBuf, std::path::PathBuf) {
    let (data, model) = (dir.join("train.csv"), dir.join("model.ron"));
    let robot = fixture("irb4400.ron");
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&data), "--rows", "120", "--seed", "3"]);
    let mut args = vec!["fit", "--robot", &robot, "--data", data.to_str().unwrap(), "--method", "poe"];
    args.extend_from_slice(extra);
    args.extend(["--out", model.to_str().unwrap()]);
    succeeds(&args);
    (data, model)
}

#[test]
fn predict_at_q1_100_rad_warns_beyond_the_fitted_angles_and_the_robots_limits() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = fitted(dir.path(), &[]);
    let far = dir.path().join("far.csv");
    with_cell(&data, &far, "q1_rad", 3, "100");
    let (_, stderr) = succeeds(&["predict", "--model", &text(&model), "--data", &text(&far)]);
    let fitted_span = "1 of 120 rows (the first at line 4) put joint 1 outside the range the model was fitted on (";
    assert!(stderr.contains(fitted_span), "{stderr}");
    let limits = "warning: 1 of 120 rows (the first at line 4, 100.0000 rad) put joint 1 beyond the robot's limits \
                  (-2.8798 … 2.8798 rad): the arm cannot take these poses";
    assert!(stderr.contains(limits), "{stderr}");

    let (json, _) = succeeds(&["eval", "--model", &text(&model), "--data", &text(&far), "--json"]);
    let json: serde_json::Value = serde_json::from_str(&json).unwrap();
    let beyond = &json["beyond_joint_limits"];
    assert_eq!(beyond.as_array().map(Vec::len), Some(1), "{json}");
    assert_eq!((beyond[0]["joint"].as_u64(), beyond[0]["first_line"].as_u64()), (Some(1), Some(4)), "{json}");
    assert_eq!(beyond[0]["first_value"].as_f64(), Some(100.0));

    // The training data itself is within everything: no warning.
    let (_, quiet) = succeeds(&["predict", "--model", &text(&model), "--data", &text(&data)]);
    assert!(!quiet.contains("warning"), "{quiet}");
}

#[test]
fn a_joint_compliance_model_used_at_a_million_kilograms_warns_of_the_payload() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = fitted(dir.path(), &["--joint-compliance"]);
    let heavy = dir.path().join("heavy.csv");
    with_cell(&data, &heavy, "payload_kg", 0, "1e6");
    let (_, stderr) = succeeds(&["predict", "--model", &text(&model), "--data", &text(&heavy)]);
    let warning = "warning: 120 of 120 rows (the first at line 2) put payload_kg outside the range the model was \
                   fitted on (1.0000 … 7.5000 kg): there the model answers for inputs it never saw";
    assert!(stderr.contains(warning), "{stderr}");
    let (json, _) = succeeds(&["eval", "--model", &text(&model), "--data", &text(&heavy), "--json"]);
    let json: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(json["out_of_range"][0]["input"], "payload_kg", "{json}");
    assert_eq!(json["out_of_range"][0]["rows_outside"], 120, "{json}");
}

#[test]
fn one_cell_of_1e308_or_an_angle_of_1e20_rad_is_refused_at_its_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let robot = fixture("irb4400.ron");
    let data = dir.path().join("train.csv");
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&data), "--rows", "60", "--seed", "5"]);
    for (column, index, value, what) in
        [("y_mm", 8, "1e308", "1e308"), ("q2_rad", 2, "1e20", "1e20 rad"), ("z_mm", 9, "-1e308", "-1e308")]
    {
        let bad = dir.path().join(format!("bad_{column}.csv"));
        with_cell(&data, &bad, column, 7, value);
        let model = dir.path().join("never.ron");
        let message =
            fails(&["fit", "--robot", &robot, "--data", &text(&bad), "--method", "poe", "--out", &text(&model)]);
        let place = format!("{}:8:{}:", text(&bad), index);
        assert!(message.starts_with(&format!("error: {place}")), "{what}: {message}");
        assert!(message.contains(column) && message.contains("beyond"), "{what}: {message}");
        assert!(!model.exists());
    }
}

const COAXIAL: &str = r#"Robot(
    name: "two coaxial joints",
    joints: [
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.0), limits_deg: (-165.0, 165.0)),
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.68), limits_deg: (-70.0, 95.0)),
        (kind: Revolute, axis: (0.0, 1.0, 0.0), point: (0.2, 0.0, 1.57), limits_deg: (-60.0, 65.0)),
        (kind: Revolute, axis: (1.0, 0.0, 0.0), point: (1.08, 0.0, 1.72), limits_deg: (-200.0, 200.0)),
        (kind: Revolute, axis: (0.0, 1.0, 0.0), point: (1.08, 0.0, 1.72), limits_deg: (-120.0, 120.0)),
        (kind: Revolute, axis: (1.0, 0.0, 0.0), point: (1.22, 0.0, 1.72), limits_deg: (-400.0, 400.0)),
    ],
    flange: (position: (1.22, 0.0, 1.72), x_axis: (0.0, 0.0, -1.0), z_axis: (1.0, 0.0, 0.0)),
)
"#;

#[test]
fn a_robot_with_two_identical_axes_is_refused_naming_the_file_and_both_joints() {
    let dir = tempfile::tempdir().unwrap();
    let robot = dir.path().join("coaxial.ron");
    std::fs::write(&robot, COAXIAL).unwrap();
    let data = dir.path().join("sim.csv");
    let expected = format!(
        "error: {}:5:26: joints 1 and 2 turn about the same line (direction (0, 0, 1) through (0, 0, 0.68) m): no \
         joint between them moves one off the other, so their columns in the identification Jacobian are equal at \
         every pose and their angles cannot be told apart; correct the axis or merge the two joints",
        text(&robot)
    );
    assert_eq!(fails(&["simulate", "--robot", &text(&robot), "--out", &text(&data)]), expected);
    assert!(!data.exists());
    // The same robot file given to fit, with any data: refused before the data is read.
    succeeds(&["simulate", "--robot", &fixture("irb4400.ron"), "--out", &text(&data), "--rows", "40"]);
    let model = dir.path().join("m.ron");
    let args = ["fit", "--robot", &text(&robot), "--data", &text(&data), "--method", "poe", "--out", &text(&model)];
    assert_eq!(fails(&args), expected);
}

#[test]
fn a_planar_chain_asked_for_a_three_dimensional_campaign_is_refused_naming_its_axis() {
    let dir = tempfile::tempdir().unwrap();
    let robot = dir.path().join("planar.ron");
    let planar = r#"Robot(
    name: "planar three-link arm",
    joints: [
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.0), limits_deg: (-165.0, 165.0)),
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.5, 0.0, 0.0), limits_deg: (-150.0, 150.0)),
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.9, 0.0, 0.0), limits_deg: (-150.0, 150.0)),
    ],
    flange: (position: (1.1, 0.0, 0.0), x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0)),
)
"#;
    std::fs::write(&robot, planar).unwrap();
    let data = dir.path().join("sim.csv");
    let message = fails(&["simulate", "--robot", &text(&robot), "--out", &text(&data), "--rows", "50"]);
    assert_eq!(
        message,
        format!(
            "error: {}: the chain is planar: all 3 joints turn about axes parallel to (0, 0, 1) (prismatic ones slide \
             across it), so the tool moves in a plane and 3-D positions cannot be drawn for it; check the joint axes",
            text(&robot)
        )
    );
    assert!(!data.exists());
}
