//! `--robot arm.urdf` on the command line: the same fit as the RON description of the same robot,
//! and the chain flags refused where they do not apply, as one line on stderr.

use std::path::PathBuf;
use std::process::{Command, Output};

fn calib(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_calib")).args(args).output().expect("the calib binary runs")
}

fn fixture(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name).display().to_string()
}

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn fails(args: &[&str]) -> String {
    let out = calib(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr).trim_end().to_owned();
    assert_eq!(stderr.lines().count(), 1, "{args:?}: not one line:\n{stderr}");
    stderr
}

/// The "training error after" line of `calib fit`'s summary.
fn training_error(summary: &str) -> String {
    summary.lines().find(|l| l.contains("training error after")).unwrap_or_default().to_owned()
}

#[test]
fn a_urdf_robot_fits_like_its_ron_description() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("sim.csv").display().to_string();
    let model = dir.path().join("m.ron").display().to_string();
    succeeds(&["simulate", "--robot", &fixture("irb4400.ron"), "--out", &data, "--rows", "150", "--seed", "3"]);
    let ron =
        succeeds(&["fit", "--robot", &fixture("irb4400.ron"), "--data", &data, "--method", "poe", "--out", &model]);
    let urdf = succeeds(&[
        "fit",
        "--robot",
        &fixture("irb4400.urdf"),
        "--tip-link",
        "tool0",
        "--data",
        &data,
        "--method",
        "poe",
        "--out",
        &model,
    ]);
    assert!(!training_error(&ron).is_empty(), "{ron}");
    assert_eq!(training_error(&ron), training_error(&urdf), "{ron}\n{urdf}");
}

#[test]
fn chain_flags_on_a_ron_robot_and_a_bad_tip_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sim.csv").display().to_string();
    let message = fails(&["simulate", "--robot", &fixture("irb4400.ron"), "--base-link", "base_link", "--out", &out]);
    assert!(message.contains("irb4400.ron:1:1: --base-link and --tip-link choose the chain of a URDF"), "{message}");
    let message = fails(&["simulate", "--robot", &fixture("ur10.urdf"), "--tip-link", "hand", "--out", &out]);
    assert!(message.contains("ur10.urdf:21:1: --tip-link: no link named 'hand'"), "{message}");
}
