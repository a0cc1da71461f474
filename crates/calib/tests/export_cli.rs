//! `calib export` end to end: a URDF that `calib` reads back, its JSON report, and each refusal as
//! one line on stderr.

use std::path::{Path, PathBuf};

mod common;
use common::{calib, fixture, text};

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

/// Simulated data of the IRB 4400 and a model fitted on it with `method`.
fn fitted(dir: &Path, method: &str) -> (PathBuf, PathBuf) {
    let data = dir.join("sim.csv");
    let model = dir.join(format!("{method}.ron"));
    succeeds(&["simulate", "--robot", &fixture("irb4400.ron"), "--out", &text(&data), "--rows", "120", "--seed", "4"]);
    succeeds(&[
        "fit",
        "--robot",
        &fixture("irb4400.ron"),
        "--data",
        &text(&data),
        "--method",
        method,
        "--out",
        &text(&model),
    ]);
    (data, model)
}

#[test]
fn an_exported_urdf_fits_like_the_model_it_came_from() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = fitted(dir.path(), "poe");
    let urdf = dir.path().join("calibrated.urdf");
    let json = succeeds(&[
        "export",
        "--model",
        &text(&model),
        "--urdf",
        &text(&urdf),
        "--robot",
        &fixture("irb4400.ron"),
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(report["base_link"], "base_link");
    assert_eq!(report["tool_links"][0], "tool");
    assert_eq!(report["axis_changes"].as_array().map(Vec::len), Some(6));
    // Without --robot, the description the model keeps: the same URDF.
    let kept = dir.path().join("kept.urdf");
    succeeds(&["export", "--model", &text(&model), "--urdf", &text(&kept), "--json"]);
    assert_eq!(std::fs::read_to_string(&kept).unwrap(), std::fs::read_to_string(&urdf).unwrap());
    // The calibrated URDF is a robot description: a base-tool fit on it needs nothing more.
    let refit = dir.path().join("refit.ron");
    let summary = succeeds(&[
        "fit",
        "--robot",
        &text(&urdf),
        "--tip-link",
        "tool",
        "--data",
        &text(&data),
        "--method",
        "base-tool",
        "--out",
        &text(&refit),
    ]);
    let poe_eval: serde_json::Value =
        serde_json::from_str(&succeeds(&["eval", "--model", &text(&model), "--data", &text(&data), "--json"])).unwrap();
    let refit_eval: serde_json::Value =
        serde_json::from_str(&succeeds(&["eval", "--model", &text(&refit), "--data", &text(&data), "--json"])).unwrap();
    let (a, b) =
        (poe_eval["mean_position_error_mm"].as_f64().unwrap(), refit_eval["mean_position_error_mm"].as_f64().unwrap());
    assert!((a - b).abs() < 1e-3 * a.max(1e-3), "poe {a} mm, base-tool on its URDF {b} mm\n{summary}");
}

#[test]
fn a_gp_model_needs_its_training_data_to_say_what_the_urdf_leaves() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = fitted(dir.path(), "poe-gp");
    let urdf = text(&dir.path().join("out.urdf"));
    let message = fails(&["export", "--model", &text(&model), "--urdf", &urdf]);
    assert!(message.contains("gaussian_process that a URDF cannot hold: give its training data (--data)"), "{message}");
    let summary = succeeds(&["export", "--model", &text(&model), "--urdf", &urdf, "--data", &text(&data)]);
    assert!(summary.contains("not in the URDF: gaussian_process"), "{summary}");
    assert!(summary.contains("URDF geometry mean"), "{summary}");
}

#[test]
fn export_refusals_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let (_, model) = fitted(dir.path(), "poe");
    let urdf = text(&dir.path().join("out.urdf"));
    let message = fails(&["export", "--model", &text(&model), "--urdf", &urdf, "--base-link", "base"]);
    // The shared robot group's refusal, as compensate and report give it.
    assert!(message.contains("--base-link and --tip-link need --robot"), "{message}");
    let message = fails(&["export", "--model", &text(&model), "--urdf", &urdf, "--like", &fixture("ur10.urdf")]);
    assert!(message.contains("ur10.urdf: joint"), "{message}");
    let message = fails(&["export", "--model", &text(&model), "--urdf", &urdf, "--robot", &fixture("iiwa7.ron")]);
    assert!(message.contains("the robot has 7 joints, the model 6"), "{message}");
    let help = succeeds(&["export", "--help"]);
    assert!(help.contains("--like"), "{help}");
    // --robot, --base-link and --tip-link are the group compensate and report take.
    for command in ["compensate", "report"] {
        let other = succeeds(&[command, "--help"]);
        for flag in ["--robot <ROBOT>", "--base-link <BASE_LINK>", "--tip-link <TIP_LINK>"] {
            // The flag's description, whichever layout clap chose for the help.
            let block = |help: &str| {
                let after = help.split(flag).nth(1).unwrap_or_default();
                let lines = after.lines().take_while(|l| !l.trim_start().starts_with('-'));
                lines.flat_map(str::split_whitespace).collect::<Vec<_>>().join(" ")
            };
            assert_eq!(block(&help), block(&other), "{flag} in export and {command}");
        }
    }
}
