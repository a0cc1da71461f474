//! `calib fit` end to end: `--effects` lists and their refusals, `--options` files, and data too
//! thin for the parameters.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{calib, fixture, text};

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn simulated(dir: &Path, rows: usize, seed: u64) -> PathBuf {
    let path = dir.join(format!("sim{seed}.csv"));
    let (rows, seed) = (rows.to_string(), seed.to_string());
    succeeds(&[
        "simulate",
        "--robot",
        &fixture("irb4400.ron"),
        "--out",
        &text(&path),
        "--rows",
        &rows,
        "--seed",
        &seed,
    ]);
    path
}

/// `calib fit … --method poe` with `extra` arguments.
fn fit(data: &Path, model: &Path, extra: &[&str]) -> Output {
    let robot = fixture("irb4400.ron");
    let mut args = vec!["fit", "--robot", &robot, "--data"];
    let (data, model) = (text(data), text(model));
    args.extend([data.as_str(), "--method", "poe", "--out", model.as_str()]);
    args.extend(extra);
    calib(&args)
}

fn fit_fails(data: &Path, model: &Path, extra: &[&str]) -> String {
    let out = fit(data, model, extra);
    assert!(!out.status.success(), "{extra:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(stderr.trim_end().lines().count(), 1, "{extra:?}: not one line:\n{stderr}");
    stderr.trim_end().to_owned()
}

#[test]
fn an_effects_list_is_fitted_and_each_bad_item_is_refused_where_it_stands() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 80, 41);
    let model = dir.path().join("m.ron");
    let out = fit(&data, &model, &["--effects", "gear_periodic:2:3,thermal"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("effect gear_periodic:2:3: 6 parameters"), "{stdout}");
    assert!(stdout.contains("effect thermal: 1 parameters"), "{stdout}");
    let cases = [
        ("thermal,gear_periodic:2", "--effects:1:9: 'gear_periodic:2' takes 2 ':' argument(s), 1 given"),
        ("backlash:0", "--effects:1:1: 'backlash:0' has a joint that is not a whole number from 1"),
        ("compliance", "--effects:1:1: 'compliance' is not an effect"),
        ("thermal,thermal", "--effects:1:9: 'thermal' is named twice"),
        ("auto,thermal", "--effects:1:1: 'auto' stands alone"),
    ];
    for (list, expected) in cases {
        let message = fit_fails(&data, &model, &["--effects", list]);
        assert!(message.contains(expected), "{list}: {message}");
    }
    let message = fit_fails(&data, &model, &["--effects", "backlash:9"]);
    assert_eq!(message, "error: effect on joint 9: the robot has joints 1 to 6");
    let message = fit_fails(&data, &model, &["--effects", "thermal", "--joint-compliance"]);
    assert!(message.contains("cannot be used with"), "{message}");
}

#[test]
fn an_options_file_sets_any_solver_field_and_refuses_an_unknown_one_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 80, 42);
    let model = dir.path().join("m.ron");
    let options = dir.path().join("fit.ron");
    std::fs::write(&options, "(\n  identification: (max_iterations: 1),\n)\n").unwrap();
    let out = fit(&data, &model, &["--options", &text(&options)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("NOT converged: stopped at the iteration limit (1)"), "{stdout}");
    std::fs::write(&options, "(\n  identification: (\n    max_iteration: 1,\n  ),\n)\n").unwrap();
    let message = fit_fails(&data, &model, &["--options", &text(&options)]);
    assert!(message.contains("fit.ron:3:5") && message.contains("max_iteration"), "{message}");
    std::fs::write(&options, "(effects: (prior_sigma: -1.0))\n").unwrap();
    let message = fit_fails(&data, &model, &["--options", &text(&options)]);
    assert!(message.contains("fit.ron:1:12") && message.contains("prior_sigma is -1"), "{message}");
    std::fs::write(&options, "(identification: (rcond: 2.0))\n").unwrap();
    let message = fit_fails(&data, &model, &["--options", &text(&options)]);
    assert!(message.contains("fit.ron:1:19") && message.contains("rcond is 2"), "{message}");
}

#[test]
fn thirteen_position_only_poses_of_a_six_axis_arm_are_refused_with_both_counts() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 13, 43);
    let model = dir.path().join("m.ron");
    let message = fit_fails(&data, &model, &[]);
    assert!(message.contains("13 measurements give 39 residual rows, fewer than the 42 free parameters"), "{message}");
    assert!(!model.exists());
}

#[test]
fn the_fit_report_is_one_json_object_on_stdout_with_the_solver_and_the_effects() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 80, 44);
    let model = dir.path().join("m.ron");
    let out = fit(&data, &model, &["--effects", "gear_periodic:2:2", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.trim_end().lines().count(), 1, "{stdout}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(json["method"], "poe");
    assert!(
        json["before"]["mean_position_error_mm"].as_f64().unwrap()
            > json["after"]["mean_position_error_mm"].as_f64().unwrap()
    );
    let id = &json["identification"];
    for key in ["rank", "condition_number", "free_parameters", "final_cost", "gradient_cosine", "converged"] {
        assert!(!id[key].is_null(), "identification.{key} missing: {id}");
    }
    assert!(id["iterations"].as_array().unwrap().len() > 1);
    assert!(id["termination"]["criterion"].is_string(), "{id}");
    assert!(id["unidentifiable"][0].as_str().unwrap().contains("joint 1"), "{id}");
    let effect = &json["effects"][0];
    assert_eq!(effect["effect"], "gear_periodic");
    assert_eq!(effect["joints"], serde_json::json!([2]));
    let names: Vec<&str> =
        effect["parameters"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["cos(1 q2)", "sin(1 q2)", "cos(2 q2)", "sin(2 q2)"]);
    // The summary a person reads goes to stderr.
    assert!(String::from_utf8_lossy(&out.stderr).contains("training error after"));
}

#[test]
fn few_rows_per_parameter_fit_with_a_warning_and_enough_without() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m.ron");
    // 20 position-only poses: 60 residual rows for 42 free parameters.
    let thin = simulated(dir.path(), 20, 45);
    let out = fit(&thin, &model, &["--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("warning: 60 residual rows for") && stderr.contains("below 3)"), "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    let warning = &json["warnings"][0];
    assert_eq!(warning["kind"], "low_redundancy", "{json}");
    assert!(warning["redundancy"].as_f64().unwrap() < 3.0, "{warning}");
    // 80 poses: 240 rows, about six per parameter.
    let enough = simulated(dir.path(), 80, 46);
    let out = fit(&enough, &model, &["--json"]);
    let json: serde_json::Value = serde_json::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    assert_eq!(json["warnings"].as_array().map(Vec::len), Some(0), "{json}");
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning:"));
}

/// `--effects auto` with a GP method also predicts the held-out error with the GP on
/// top (a line, and `auto.predicted_with_gp` in `--json`); a method without a GP prints and carries
/// nothing new.
#[test]
fn effects_auto_with_a_gp_predicts_the_held_out_error_with_the_gp_on_top() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 120, 45);
    let (robot, data) = (fixture("irb4400.ron"), text(&data));
    let model = text(&dir.path().join("m.ron"));
    let run = |method: &str| {
        let args = ["fit", "--robot", &robot, "--data", &data, "--method", method, "--effects", "auto"];
        let out = calib(&[&args[..], &["--out", &model, "--json"]].concat());
        assert!(out.status.success(), "{method}: {}", String::from_utf8_lossy(&out.stderr));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (json, String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (json, summary) = run("poe-gp");
    let with_gp = &json["auto"]["predicted_with_gp"];
    let on = with_gp["on_poses_mm"].as_f64().unwrap();
    assert!(on.is_finite() && on > 0.0, "{with_gp}");
    let arcs = with_gp["arcs"].as_array().unwrap();
    assert!(!arcs.is_empty() && arcs.iter().all(|a| a["joint"].as_u64().is_some() && a["mean_mm"].as_f64().is_some()));
    let mean = arcs.iter().map(|a| a["mean_mm"].as_f64().unwrap()).sum::<f64>() / arcs.len() as f64;
    assert!((with_gp["off_poses_mm"].as_f64().unwrap() - mean).abs() < 1e-12, "{with_gp}");
    assert!(summary.contains("predicted held out with the GP on top:"), "{summary}");
    assert!(summary.contains("hyperparameters held fixed"), "{summary}");
    let (json, summary) = run("poe");
    assert!(json["auto"].is_object() && json["auto"].get("predicted_with_gp").is_none(), "{}", json["auto"]);
    assert!(!summary.contains("with the GP on top"), "{summary}");
}
