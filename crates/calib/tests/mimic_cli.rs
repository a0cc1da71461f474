//! A URDF with mimic joints on the command line: `simulate` → `fit` → `eval` round
//! trips on `column_arm.urdf` (a lifting column of three stages driven by one motor, folded into
//! one joint), `fit` says what the folding made unobservable, and `export --like` keeps the
//! mimic joints.

mod common;

use common::{calib, fixture, text};
use std::path::Path;

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Splits `all` after `first` data rows into `train` and `test`, with the prismatic column's
/// header in metres (`q1_m`; a `q1_rad` header is renamed), since `fit` refuses `_rad` for a
/// prismatic joint.
fn split(all: &Path, first: usize, train: &Path, test: &Path) {
    let content = std::fs::read_to_string(all).unwrap();
    let mut lines = content.lines();
    let header = lines.next().unwrap().replacen("q1_rad,", "q1_m,", 1);
    assert!(header.starts_with("q1_m,"), "{header}");
    let rows: Vec<&str> = lines.collect();
    let write = |path: &Path, rows: &[&str]| std::fs::write(path, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
    write(train, &rows[..first]);
    write(test, &rows[first..]);
}

#[test]
fn the_column_arm_round_trips_through_simulate_fit_eval_and_export() {
    let dir = tempfile::tempdir().unwrap();
    let [effects, all, train, test, model, urdf] =
        ["effects.ron", "all.csv", "train.csv", "test.csv", "poe.ron", "out.urdf"].map(|n| dir.path().join(n));
    // Tracker noise alone (the URDF's masses bend nothing without a deflection).
    std::fs::write(&effects, "(tracker_noise: ())\n").unwrap();
    let robot = fixture("column_arm.urdf");
    let [effects, all, train, test, model, urdf] = [effects, all, train, test, model, urdf].map(|p| text(&p));
    let again = text(&dir.path().join("again.ron"));
    let out = succeeds(&[
        "simulate",
        "--robot",
        &robot,
        "--out",
        &all,
        "--rows",
        "300",
        "--seed",
        "3",
        "--payloads",
        "0",
        "--effects",
        &effects,
    ]);
    assert!(out.contains("simulated 300 poses of column_arm"), "{out}");
    // One column per motor: seven joints, not the URDF's nine movable ones.
    let header = std::fs::read_to_string(&all).unwrap().lines().next().unwrap().to_owned();
    assert!(header.contains("q7_") && !header.contains("q8_"), "{header}");
    split(Path::new(&all), 200, Path::new(&train), Path::new(&test));
    let fitted = succeeds(&["fit", "--robot", &robot, "--data", &train, "--method", "poe", "--out", &model]);
    assert!(
        fitted.contains(
            "joint 1 is URDF joint 'lift' with its mimic joint(s) 'lift_stage_2' (multiplier 1), 'lift_stage_3'"
        ) && fitted.contains("how it splits between the stages"),
        "{fitted}"
    );
    let json = succeeds(&["eval", "--model", &model, "--data", &test, "--json"]);
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    let held_out = value["mean_position_error_mm"].as_f64().unwrap();
    // The tracker noise is about 0.03 mm; the nominal geometry is off by millimetres.
    assert!(held_out < 0.1, "{held_out} mm");
    succeeds(&["export", "--model", &model, "--urdf", &urdf, "--like", &robot]);
    let written = std::fs::read_to_string(&urdf).unwrap();
    assert_eq!(written.matches("<mimic joint=\"lift\" multiplier=\"1\" offset=\"0\"/>").count(), 2);
    // The written URDF is a robot description again, with the column folded the same way.
    let again = [
        "fit",
        "--robot",
        &urdf,
        "--base-link",
        "track",
        "--tip-link",
        "prism",
        "--data",
        &train,
        "--method",
        "base-tool",
        "--out",
        &again,
    ];
    let refitted = succeeds(&again);
    assert!(refitted.contains("'lift_stage_3' (multiplier 1)"), "{refitted}");
}

#[test]
fn simulate_bends_the_column_with_the_urdfs_masses_and_refuses_compliance_without_stiffness() {
    let dir = tempfile::tempdir().unwrap();
    let robot = fixture("column_arm.urdf");
    let simulate = |effects: &str, name: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, effects).unwrap();
        let out = text(&dir.path().join(format!("{name}.csv")));
        calib(&["simulate", "--robot", &robot, "--out", &out, "--rows", "20", "--seed", "5", "--effects", &text(&path)])
    };
    let bent = simulate("(deflection: (links: [(joint_index: 0, flexibility_per_nm2: (1e-6, 1e-6))]))\n", "bent.ron");
    assert!(bent.status.success(), "{}", String::from_utf8_lossy(&bent.stderr));
    let still = simulate("()\n", "still.ron");
    assert!(still.status.success(), "{}", String::from_utf8_lossy(&still.stderr));
    // The same poses, the column bent under the arm's weight from the URDF's <inertial> masses.
    let rows = |name: &str| -> Vec<Vec<f64>> {
        let content = std::fs::read_to_string(dir.path().join(name)).unwrap();
        let mut lines = content.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let xyz: Vec<usize> =
            ["x_mm", "y_mm", "z_mm"].iter().map(|c| header.iter().position(|h| h == c).unwrap()).collect();
        lines
            .map(|l| l.split(',').collect::<Vec<_>>())
            .map(|f| xyz.iter().map(|&i| f[i].parse().unwrap()).collect())
            .collect()
    };
    let moved: Vec<f64> = rows("bent.ron.csv")
        .iter()
        .zip(rows("still.ron.csv"))
        .map(|(a, b)| a.iter().zip(&b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt())
        .collect();
    let largest = moved.iter().copied().fold(0.0, f64::max);
    assert!(largest > 0.05 && largest < 5.0, "the bending moves the prism by at most {largest} mm");
    let compliance = simulate("(\n  compliance: ())\n", "compliance.ron");
    let message = String::from_utf8_lossy(&compliance.stderr);
    assert!(!compliance.status.success(), "compliance simulated on a robot without stiffness");
    assert!(
        message.contains("compliance.ron:2:3: compliance: joint compliance needs the joint stiffness"),
        "{message}"
    );
}

#[test]
fn the_shipped_column_arm_fits_from_its_urdf_as_shipped_and_exports_back_in_its_shape() {
    let dir = tempfile::tempdir().unwrap();
    let [effects, all, train, test, model, urdf, again] =
        ["effects.ron", "all.csv", "train.csv", "test.csv", "poe.ron", "out.urdf", "again.ron"]
            .map(|n| text(&dir.path().join(n)));
    std::fs::write(&effects, "(tracker_noise: ())\n").unwrap();
    let robot = fixture("column_arm_shipped.urdf");
    let simulate =
        ["simulate", "--robot", &robot, "--out", &all, "--rows", "160", "--seed", "4", "--effects", &effects];
    succeeds(&simulate);
    split(Path::new(&all), 120, Path::new(&train), Path::new(&test));
    // The motor beside the chain is the data's joint 1.
    let fit = ["fit", "--robot", &robot, "--tip-link", "prism", "--data", &train, "--method", "poe", "--out", &model];
    let fitted = succeeds(&fit);
    let folded = "joint 1 is URDF joint 'column_drive' with its mimic joint(s) 'column_stage_1' (multiplier 0.5), \
                  'column_stage_2' (multiplier 0.5)";
    assert!(fitted.contains(folded), "{fitted}");
    let json = succeeds(&["eval", "--model", &model, "--data", &test, "--json"]);
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    let held_out = value["mean_position_error_mm"].as_f64().unwrap();
    assert!(held_out < 0.1, "{held_out} mm");
    succeeds(&["export", "--model", &model, "--urdf", &urdf, "--like", &robot]);
    let written = std::fs::read_to_string(&urdf).unwrap();
    assert_eq!(written.matches("<mimic joint=\"column_drive\" multiplier=\"0.5\"").count(), 2);
    assert!(written.contains("<child link=\"column_drive_nut\"/>"), "{written}");
    let refit = [
        "fit",
        "--robot",
        &urdf,
        "--base-link",
        "track",
        "--tip-link",
        "prism",
        "--data",
        &train,
        "--method",
        "base-tool",
        "--out",
        &again,
    ];
    assert!(succeeds(&refit).contains(folded));
}
