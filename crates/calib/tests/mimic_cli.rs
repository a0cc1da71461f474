//! A URDF with mimic joints on the command line (issue 30): `simulate` → `fit` → `eval` round
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
/// header in metres: `simulate` wrote `q1_rad` for it at the time of writing (another change
/// renames it to `q1_m`), which `fit` refuses for a prismatic joint.
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
    // Tracker noise alone: the URDF carries masses, but the description read from it no load model.
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
