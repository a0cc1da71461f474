//! `calib simulate` through the binary: its CSV feeds `calib fit` and `calib eval`, and bad input
//! gets one line on stderr and a non-zero exit.

mod common;

use common::{calib, fixture, text};
use std::path::Path;

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Splits a CSV into its first `head` data rows and the rest, both with the header.
fn split_csv(path: &Path, head: usize, first: &Path, rest: &Path) {
    let content = std::fs::read_to_string(path).unwrap();
    let mut lines = content.lines();
    let header = lines.next().unwrap();
    let rows: Vec<&str> = lines.collect();
    let write = |to: &Path, part: &[&str]| std::fs::write(to, format!("{header}\n{}\n", part.join("\n"))).unwrap();
    write(first, &rows[..head]);
    write(rest, &rows[head..]);
}

/// `calib eval --json`'s mean position error, mm.
fn held_out_mm(model: &Path, data: &Path) -> f64 {
    let json: serde_json::Value =
        serde_json::from_str(&succeeds(&["eval", "--model", &text(model), "--data", &text(data), "--json"]))
            .expect("eval prints JSON");
    json["mean_position_error_mm"].as_f64().expect("a mean position error")
}

#[test]
fn simulated_data_round_trips_through_fit_and_eval_and_poe_beats_base_tool() {
    let dir = tempfile::tempdir().unwrap();
    let (all, train, test) = (dir.path().join("all.csv"), dir.path().join("train.csv"), dir.path().join("test.csv"));
    let robot = fixture("irb4400.ron");
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&all), "--rows", "160", "--seed", "3", "--full-pose"]);
    let header = std::fs::read_to_string(&all).unwrap().lines().next().unwrap().to_owned();
    for column in ["q6_rad", "x_mm", "qw", "payload_kg"] {
        assert!(header.split(',').any(|c| c == column), "{column} missing from {header}");
    }
    split_csv(&all, 120, &train, &test);
    let mut errors = Vec::new();
    for method in ["base-tool", "poe"] {
        let model = dir.path().join(format!("{method}.ron"));
        succeeds(&["fit", "--robot", &robot, "--data", &text(&train), "--method", method, "--out", &text(&model)]);
        errors.push(held_out_mm(&model, &test));
    }
    let (base_tool, poe) = (errors[0], errors[1]);
    // ±1 mm / 1 mrad per frame leaves millimetres after base-tool; POE leaves the compliance, < 1 mm.
    assert!(base_tool > 1.0, "base-tool {base_tool} mm");
    assert!(poe < 0.5 * base_tool && poe < 1.0, "POE {poe} mm, base-tool {base_tool} mm");
}

#[test]
fn without_compliance_poe_leaves_only_the_tracker_noise() {
    let dir = tempfile::tempdir().unwrap();
    let [effects, all, train, test] =
        ["effects.ron", "all.csv", "train.csv", "test.csv"].map(|name| dir.path().join(name));
    std::fs::write(&effects, "// tracker noise alone\n(tracker_noise: ())\n").unwrap();
    let robot = fixture("irb4400.ron");
    let out = succeeds(&[
        "simulate",
        "--robot",
        &robot,
        "--out",
        &text(&all),
        "--rows",
        "100",
        "--effects",
        &text(&effects),
        "--payloads",
        "0,10",
    ]);
    assert!(out.contains("effects: tracker_noise"), "{out}");
    let payloads: Vec<String> = std::fs::read_to_string(&all)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(9).unwrap().to_owned())
        .collect();
    assert!(payloads.iter().all(|p| p == "0.0" || p == "10.0"), "{payloads:?}");
    split_csv(&all, 80, &train, &test);
    let model = dir.path().join("poe.ron");
    succeeds(&["fit", "--robot", &robot, "--data", &text(&train), "--method", "poe", "--out", &text(&model)]);
    // The AT901-like noise is about 0.03 mm at these distances: a rigid robot is fitted to it.
    let error = held_out_mm(&model, &test);
    assert!(error < 0.1, "{error} mm");
}

/// Exit status non-zero and exactly one line on stderr, containing `needle`.
fn refused(args: &[&str], needle: &str) {
    let out = calib(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    assert!(stderr.contains(needle), "{args:?}: {stderr}");
}

#[test]
fn bad_arguments_and_files_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = text(&dir.path().join("out.csv"));
    let robot = fixture("irb4400.ron");
    refused(&["simulate", "--robot", &robot, "--out", &out, "--rows", "many"], "many");
    refused(&["simulate", "--robot", &robot, "--out", &out, "--rows", "0"], "--rows");
    refused(&["simulate", "--robot", &robot, "--out", &out, "--payloads", "1,-2"], "payloads");
    refused(&["simulate", "--robot", "no/such/robot.ron", "--out", &out], "no/such/robot.ron");
    let effects = dir.path().join("effects.ron");
    std::fs::write(&effects, "(\n  compliance: (),\n  tracker_nosie: (),\n)\n").unwrap();
    refused(&["simulate", "--robot", &robot, "--out", &out, "--effects", &text(&effects)], "tracker_nosie");
    assert!(!Path::new(&out).exists(), "nothing is written when the input is refused");
}

/// The rows of a CSV as maps from header to cell.
fn rows(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let content = std::fs::read_to_string(path).unwrap();
    let mut lines = content.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(str::to_owned).collect();
    lines.map(|l| header.iter().cloned().zip(l.split(',').map(str::to_owned)).collect()).collect()
}

#[test]
fn a_seven_axis_payload_run_campaign_writes_fixed_joints_a_tool_per_run_and_torques() {
    let dir = tempfile::tempdir().unwrap();
    let all = dir.path().join("all.csv");
    let out = succeeds(&[
        "simulate",
        "--robot",
        &fixture("iiwa7.ron"),
        "--out",
        &text(&all),
        "--rows",
        "120",
        "--seed",
        "4",
        "--full-pose",
        "--moving-joints",
        "1,2",
        "--fixed-jitter-mrad",
        "2",
        "--payloads",
        "0,1.25,2.5,5",
        "--tool-per-payload",
        "--torques",
    ]);
    assert!(out.contains("moving joints 1,2") && out.contains("one tool per run") && out.contains("torques"), "{out}");
    let rows = rows(&all);
    assert_eq!(rows.len(), 120);
    let number = |row: &std::collections::HashMap<String, String>, column: &str| -> f64 {
        row.get(column).unwrap_or_else(|| panic!("{column} missing")).parse().unwrap()
    };
    for row in &rows {
        for j in 3..=7 {
            assert!(number(row, &format!("q{j}_rad")).abs() <= 2e-3, "joint {j} is held at 0");
        }
        for j in 1..=7 {
            number(row, &format!("tau{j}_nm"));
        }
    }
    // Four consecutive runs of 30, one payload and one tool each, in the order given.
    let runs: Vec<(String, f64)> = rows.iter().map(|r| (r["tool"].clone(), number(r, "payload_kg"))).collect();
    for (k, kg) in [0.0, 1.25, 2.5, 5.0].iter().enumerate() {
        let run = &runs[30 * k..30 * (k + 1)];
        assert!(run.iter().all(|(tool, m)| *tool == format!("tool{}", k + 1) && m == kg), "run {k}: {run:?}");
    }
    // Joint 2 carries the arm's weight, joint 1 (vertical) none beyond the sensor noise.
    let mean_abs = |j: usize| rows.iter().map(|r| number(r, &format!("tau{j}_nm")).abs()).sum::<f64>() / 120.0;
    assert!(mean_abs(2) > 20.0 && mean_abs(1) < 1.0, "τ2 {} τ1 {}", mean_abs(2), mean_abs(1));
    // The file reads back and fits, each run's tool its own.
    let model = dir.path().join("poe.ron");
    succeeds(&[
        "fit",
        "--robot",
        &fixture("iiwa7.ron"),
        "--data",
        &text(&all),
        "--method",
        "poe",
        "--out",
        &text(&model),
    ]);
    let fitted = std::fs::read_to_string(&model).unwrap();
    assert!(["tool1", "tool2", "tool3", "tool4"].iter().all(|t| fitted.contains(t)), "the model keeps a tool per run");
}

#[test]
fn campaign_shape_arguments_that_do_not_fit_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = text(&dir.path().join("out.csv"));
    let robot = fixture("iiwa7.ron");
    let base = ["simulate", "--robot", robot.as_str(), "--out", out.as_str()];
    let with = |extra: &[&'static str]| -> Vec<&str> { base.iter().copied().chain(extra.iter().copied()).collect() };
    refused(&with(&["--moving-joints", "0,2"]), "numbered from 1");
    refused(&with(&["--moving-joints", "2,9"]), "joint 9");
    refused(&with(&["--fixed-jitter-mrad", "2"]), "--moving-joints");
    refused(&with(&["--moving-joints", "1,2", "--fixed-jitter-mrad=-1"]), "--fixed-jitter-mrad");
    refused(&with(&["--torque-sigma-nm", "1"]), "--torques");
    let bare = fixture("ur10.ron");
    refused(&["simulate", "--robot", &bare, "--out", &out, "--torques"], "dynamics");
    assert!(!Path::new(&out).exists(), "nothing is written when the input is refused");
}

/// A prismatic joint (a lifting column) is written as `q1_m` and what `simulate` writes
/// `fit` reads back (it refused its own file when the column was written as `q1_rad`).
#[test]
fn a_lifting_column_is_written_in_metres_and_fits_back() {
    let dir = tempfile::tempdir().unwrap();
    let robot = fixture("column_ur10.ron");
    let (data, model) = (dir.path().join("column.csv"), dir.path().join("column.ron"));
    let effects = dir.path().join("effects.ron");
    std::fs::write(&effects, "(tracker_noise: Some(()))").unwrap();
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&data), "--rows", "120", "--effects", &text(&effects)]);
    let header = std::fs::read_to_string(&data).unwrap().lines().next().unwrap().to_owned();
    assert!(header.starts_with("q1_m,q2_rad,"), "{header}");
    let out = succeeds(&["fit", "--robot", &robot, "--data", &text(&data), "--method", "poe", "--out", &text(&model)]);
    assert!(out.contains("training error after: mean 0.0"), "{out}");
}
