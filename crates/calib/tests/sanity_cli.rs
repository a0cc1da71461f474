//! No fit that looks right and is not, through the binary: a model is never credited
//! with what it did not calibrate, and input that cannot be physical is refused with its place.

use std::path::Path;

mod common;
use common::{fails, fixture, succeeds_with_stderr as succeeds, text};

/// Writes `from` to `to` with the columns `drop` left out.
fn without_columns(from: &Path, to: &Path, drop: &[&str]) {
    let content = std::fs::read_to_string(from).unwrap();
    let header: Vec<&str> = content.lines().next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len()).filter(|&i| !drop.contains(&header[i])).collect();
    let body: Vec<String> = content
        .lines()
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            keep.iter().map(|&i| cells[i]).collect::<Vec<_>>().join(",")
        })
        .collect();
    std::fs::write(to, body.join("\n") + "\n").unwrap();
}

#[test]
fn a_position_only_model_reports_no_rotation_error_on_full_pose_data() {
    let dir = tempfile::tempdir().unwrap();
    let (full, positions, model) =
        (dir.path().join("full.csv"), dir.path().join("positions.csv"), dir.path().join("model.ron"));
    let robot = fixture("irb4400.ron");
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&full), "--rows", "80", "--seed", "4", "--full-pose"]);
    without_columns(&full, &positions, &["qw", "qx", "qy", "qz"]);
    succeeds(&["fit", "--robot", &robot, "--data", &text(&positions), "--method", "poe", "--out", &text(&model)]);

    let (json, stderr) = succeeds(&["eval", "--model", &text(&model), "--data", &text(&full), "--json"]);
    let json: serde_json::Value = serde_json::from_str(&json).expect("eval prints JSON");
    assert!(json.get("mean_rotation_error_mrad").is_none(), "a rotation error for an uncalibrated rotation: {json}");
    assert!(json.get("max_rotation_error_mrad").is_none(), "{json}");
    assert_eq!(json["full_pose"], false, "{json}");
    assert_eq!(json["orientations_not_evaluated"], true, "{json}");
    let note = "the model was fitted on positions only: orientations in the data are not evaluated";
    assert!(stderr.contains(note), "{stderr}");

    let (table, _) = succeeds(&["eval", "--model", &text(&model), "--data", &text(&full)]);
    assert!(!table.contains("rotation error"), "{table}");
    assert!(table.contains(note), "{table}");
}

/// Writes `from` to `to` with the column `name` set to `value` on every row (appended if absent).
fn with_constant_column(from: &Path, to: &Path, name: &str, value: &str) {
    let content = std::fs::read_to_string(from).unwrap();
    let header: Vec<&str> = content.lines().next().unwrap().split(',').collect();
    let at = header.iter().position(|c| *c == name);
    let body: Vec<String> = content
        .lines()
        .enumerate()
        .map(|(i, line)| {
            let mut cells: Vec<&str> = line.split(',').collect();
            let cell = if i == 0 { name } else { value };
            match at {
                Some(k) => cells[k] = cell,
                None => cells.push(cell),
            }
            cells.join(",")
        })
        .collect();
    std::fs::write(to, body.join("\n") + "\n").unwrap();
}

#[test]
fn a_constant_time_or_temperature_column_is_refused_as_unobservable_and_auto_leaves_it_out() {
    let dir = tempfile::tempdir().unwrap();
    let (simulated, constant, model) =
        (dir.path().join("sim.csv"), dir.path().join("constant.csv"), dir.path().join("m.ron"));
    let robot = fixture("irb4400.ron");
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&simulated), "--rows", "80", "--seed", "5"]);
    with_constant_column(&simulated, &constant, "temp_c", "21.5");
    with_constant_column(&constant, &constant, "t_s", "600");
    let fit = |effects: &str| {
        vec!["fit", "--robot", &robot, "--data", constant.to_str().unwrap(), "--method", "poe", "--effects", effects]
            .into_iter()
            .map(String::from)
            .chain(["--out".into(), text(&model)])
            .collect::<Vec<String>>()
    };
    let cases = [
        (
            "time_drift",
            "time_drift needs the column 't_s' to vary, but its values do not vary (t_s = 600 on all 80 rows)",
        ),
        (
            "thermal",
            "thermal needs the column 'temp_c' to vary, but its values do not vary (temp_c = 21.5 on all 80 rows)",
        ),
    ];
    for (effect, expected) in cases {
        let args = fit(effect);
        let message = fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(message.contains(expected), "{effect}: {message}");
        assert!(message.contains("unobservable") && message.contains("lines 2-81"), "{effect}: {message}");
        assert!(!model.exists(), "{effect}: a model was written");
    }
    // The diagnosis behind `auto` never proposes them: the fit goes through without either.
    let args = fit("auto");
    let (stdout, _) = succeeds(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(!stdout.contains("time_drift") && !stdout.contains("thermal"), "{stdout}");
}

#[test]
fn export_like_a_urdf_whose_joint_kind_differs_from_the_model_is_refused_at_that_joint() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model, out) = (dir.path().join("sim.csv"), dir.path().join("m.ron"), dir.path().join("out.urdf"));
    let robot = fixture("irb4400.ron");
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&data), "--rows", "80", "--seed", "6"]);
    succeeds(&["fit", "--robot", &robot, "--data", &text(&data), "--method", "poe", "--out", &text(&model)]);
    // The same URDF, its third joint sliding: its limits stay numbers, so it reads as a chain.
    let original = std::fs::read_to_string(fixture("irb4400.urdf")).unwrap();
    let changed =
        original.replace("<joint name=\"joint_3\" type=\"revolute\">", "<joint name=\"joint_3\" type=\"prismatic\">");
    assert_ne!(changed, original);
    let like = dir.path().join("arm.urdf");
    std::fs::write(&like, changed).unwrap();
    // The unchanged URDF is accepted: the refusal is the kind, not the file.
    succeeds(&["export", "--model", &text(&model), "--urdf", &text(&out), "--like", &fixture("irb4400.urdf")]);
    std::fs::remove_file(&out).unwrap();

    let message = fails(&["export", "--model", &text(&model), "--urdf", &text(&out), "--like", &text(&like)]);
    assert!(
        message.contains(&format!(
            "{}:28:3: joint 'joint_3' (movable joint 3) is prismatic in the URDF but revolute in the model",
            text(&like)
        )),
        "{message}"
    );
    assert!(!out.exists(), "a URDF was written");
}
