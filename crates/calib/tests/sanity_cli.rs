//! Issue 31, "no fit that looks right and is not", through the binary: a model is never credited
//! with what it did not calibrate, and input that cannot be physical is refused with its place.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn calib(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_calib")).args(args).output().expect("the calib binary runs")
}

fn fixture(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name).display().to_string()
}

fn text(path: &Path) -> String {
    path.display().to_string()
}

/// Runs a command that must succeed and returns its stdout and stderr.
fn succeeds(args: &[&str]) -> (String, String) {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Runs a command that must fail and returns its stderr, checked to be exactly one line.
fn fails(args: &[&str]) -> String {
    let out = calib(args);
    assert!(!out.status.success(), "{args:?} should fail: {}", String::from_utf8_lossy(&out.stdout));
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: not one line:\n{stderr}");
    stderr.trim_end().to_owned()
}

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
