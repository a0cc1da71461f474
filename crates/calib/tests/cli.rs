//! The `calib` binary end to end: predict and diagnose on simulated data, and every error as one
//! line on stderr with a non-zero exit.

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

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs a command that must fail and returns its stderr, checked to be exactly one line.
fn fails(args: &[&str]) -> String {
    let out = calib(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: not one line:\n{stderr}");
    stderr.trim_end().to_owned()
}

fn simulated(dir: &Path, rows: usize, seed: u64) -> PathBuf {
    let path = dir.join(format!("sim{seed}.csv"));
    succeeds(&[
        "simulate",
        "--robot",
        &fixture("irb4400.ron"),
        "--out",
        &text(&path),
        "--rows",
        &rows.to_string(),
        "--seed",
        &seed.to_string(),
    ]);
    path
}

#[test]
fn predict_gives_a_pose_and_the_gp_spread_for_joints_without_positions() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 120, 5);
    let model = dir.path().join("model.ron");
    succeeds(&[
        "fit",
        "--robot",
        &fixture("irb4400.ron"),
        "--data",
        &text(&data),
        "--method",
        "poe-gp-load",
        "--out",
        &text(&model),
    ]);
    // The same joints with the measured positions removed.
    let content = std::fs::read_to_string(&data).unwrap();
    let mut lines = content.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len()).filter(|&i| !header[i].ends_with("_mm")).collect();
    let project = |line: &str| {
        let cells: Vec<&str> = line.split(',').collect();
        keep.iter().map(|&i| cells[i]).collect::<Vec<_>>().join(",")
    };
    let joints = dir.path().join("joints.csv");
    let body: Vec<String> =
        std::iter::once(project(content.lines().next().unwrap())).chain(lines.map(project)).collect();
    std::fs::write(&joints, body.join("\n") + "\n").unwrap();

    let out = succeeds(&["predict", "--model", &text(&model), "--data", &text(&joints)]);
    let mut rows = out.lines();
    assert_eq!(rows.next().unwrap(), "line,x_mm,y_mm,z_mm,std_x_mm,std_y_mm,std_z_mm");
    let rows: Vec<Vec<f64>> = rows.map(|l| l.split(',').map(|c| c.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 120);
    assert!(rows.iter().all(|r| r[4] > 0.0 && r[4] < 1.0), "a GP spread in millimetres");

    // With the positions, predict also reports the error, which is the training error here.
    let out = succeeds(&["predict", "--model", &text(&model), "--data", &text(&data)]);
    let errors: Vec<f64> = out.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect();
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    assert!(mean < 0.2, "training error {mean} mm");
}

#[test]
fn diagnose_prints_the_spec_json_and_writes_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 150, 6);
    let out = succeeds(&["diagnose", "--robot", &fixture("irb4400.ron"), "--data", &text(&data), "--json"]);
    let json: serde_json::Value = serde_json::from_str(&out).expect("one JSON object");
    for key in ["verdict", "heldout_before_mm", "heldout_after_mm", "candidates"] {
        assert!(json.get(key).is_some(), "{key} missing");
    }
    assert!(json["verdict"]["effect"].is_string() && json["verdict"]["joints"].is_array());
    let first = &json["candidates"][0];
    assert!(first["effect"].is_string() && first["joints"].is_array() && first["heldout_after_mm"].is_number());
    let report = dir.path().join("report");
    let summary =
        succeeds(&["diagnose", "--robot", &fixture("irb4400.ron"), "--data", &text(&data), "--report", &text(&report)]);
    assert!(summary.contains("verdict:") && summary.contains("held-out error:"), "{summary}");
    assert!(report.join("diagnosis.md").exists() && report.join("joint2.svg").exists());
}

#[test]
fn every_error_is_one_line_with_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 60, 7);
    let model = dir.path().join("m.ron");
    let robot = fixture("irb4400.ron");
    let message =
        fails(&["fit", "--robot", "missing.ron", "--data", &text(&data), "--method", "poe", "--out", &text(&model)]);
    assert!(message.contains("missing.ron"), "{message}");
    let message =
        fails(&["fit", "--robot", &robot, "--data", &text(&data), "--method", "poe+gp", "--out", &text(&model)]);
    assert!(message.contains("poe+gp"), "{message}");
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,x_mm,y_mm,z_mm\n0,0,0,0,0,0,1,2,oops\n").unwrap();
    let message = fails(&["fit", "--robot", &robot, "--data", &text(&bad), "--method", "poe", "--out", &text(&model)]);
    assert!(message.contains("bad.csv:2:9"), "{message}");
    let message = fails(&[
        "fit",
        "--robot",
        &fixture("iiwa7.ron"),
        "--data",
        &text(&data),
        "--method",
        "poe",
        "--out",
        &text(&model),
    ]);
    assert!(message.contains("the robot has 7 joints"), "{message}");
    fails(&["eval", "--data", &text(&data)]);
    fails(&["eval", "--model", &text(&dir.path().join("none.ron")), "--data", &text(&data)]);
    fails(&["diagnose", "--robot", &robot, "--data", &text(&data), "--noise-mm", "-1"]);
    fails(&["frobnicate"]);
    assert!(!model.exists(), "no model is written when the fit fails");
}
