//! Gross outliers end to end: one row a metre off among 300 good ones is named by its
//! line in `calib fit` and `calib diagnose`, and does not spoil the model.

use std::path::{Path, PathBuf};

mod common;
use common::{calib, fixture, text};

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// 600 simulated rows of one true robot: the first 300 to fit, the rest to test, as two files.
fn simulated(dir: &Path) -> (Vec<String>, PathBuf) {
    let path = dir.join("all.csv");
    succeeds(&["simulate", "--robot", &fixture("irb4400.ron"), "--out", &text(&path), "--rows", "600", "--seed", "31"]);
    let lines: Vec<String> = std::fs::read_to_string(&path).unwrap().lines().map(str::to_owned).collect();
    let test = dir.join("test.csv");
    std::fs::write(&test, [&lines[..1], &lines[301..]].concat().join("\n")).unwrap();
    (lines[..301].to_vec(), test)
}

/// The training rows with the rows on `moved` lines (1-based, the header is line 1) moved 1 m
/// along x.
fn training(dir: &Path, lines: &[String], moved: &[usize], name: &str) -> PathBuf {
    let x = lines[0].split(',').position(|c| c == "x_mm").expect("an x_mm column");
    let rows: Vec<String> = lines
        .iter()
        .enumerate()
        .map(|(i, line)| {
            if !moved.contains(&(i + 1)) {
                return line.clone();
            }
            let mut cells: Vec<String> = line.split(',').map(str::to_owned).collect();
            cells[x] = (cells[x].parse::<f64>().unwrap() + 1000.0).to_string();
            cells.join(",")
        })
        .collect();
    let path = dir.join(name);
    std::fs::write(&path, rows.join("\n")).unwrap();
    path
}

/// `calib fit --method poe` then `calib eval` on the test rows: the fit's stdout and the mean
/// held-out position error, mm.
fn fit_and_eval(data: &Path, model: &Path, test: &Path, extra: &[&str]) -> (String, f64) {
    let robot = fixture("irb4400.ron");
    let (data, model_text) = (text(data), text(model));
    let mut args = vec!["fit", "--robot", &robot, "--data", &data, "--method", "poe", "--out", &model_text];
    args.extend(extra);
    let stdout = succeeds(&args);
    let eval = succeeds(&["eval", "--model", &model_text, "--data", &text(test), "--json"]);
    let json: serde_json::Value = serde_json::from_str(&eval).expect("one JSON object");
    (stdout, json["mean_position_error_mm"].as_f64().unwrap())
}

#[test]
fn fit_names_a_row_a_metre_off_by_its_line_and_leaves_it_out() {
    let dir = tempfile::tempdir().unwrap();
    let (lines, test) = simulated(dir.path());
    let clean = training(dir.path(), &lines, &[], "clean.csv");
    let dirty = training(dir.path(), &lines, &[137], "dirty.csv");
    let model = dir.path().join("m.ron");
    let (clean_out, reference) = fit_and_eval(&clean, &model, &test, &[]);
    assert!(!clean_out.contains("gross outlier"), "{clean_out}");
    let (out, error) = fit_and_eval(&dirty, &model, &test, &[]);
    assert!(
        out.contains("warning: 1 row(s) of the data are gross outliers, beyond 10 robust sigmas")
            && out.contains(": line 137 (")
            && out.contains("left out of the fit"),
        "{out}"
    );
    assert!(error <= 1.2 * reference, "held-out {error} mm against {reference} mm without the bad row");
    // The JSON names it too, as a field and as a warning.
    let robot = fixture("irb4400.ron");
    let json = succeeds(&[
        "fit",
        "--robot",
        &robot,
        "--data",
        &text(&dirty),
        "--method",
        "poe",
        "--out",
        &text(&model),
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_str(&json).expect("one JSON object");
    assert_eq!(report["outliers"][0]["line"], 137);
    assert!((report["outliers"][0]["position_mm"].as_f64().unwrap() - 1000.0).abs() < 1.0, "{}", report["outliers"]);
    assert_eq!(report["identification"]["robust"]["outliers"].as_array().unwrap().len(), 1);
    let warning = report["warnings"].as_array().unwrap().iter().find(|w| w["kind"] == "gross_outliers");
    assert_eq!(warning.expect("a gross_outliers warning")["rows"][0]["line"], 137);
    // Plain least squares names the row but keeps it, and the model shows it.
    let options = dir.path().join("squared.ron");
    std::fs::write(&options, "(identification: (robust: (loss: squared)))").unwrap();
    let (out, spoiled) = fit_and_eval(&dirty, &model, &test, &["--options", &text(&options)]);
    assert!(out.contains(": line 137 (") && out.contains("KEPT in the fit (least-squares loss)"), "{out}");
    assert!(spoiled > 3.0 * reference, "least squares: {spoiled} mm against {reference} mm");
}

#[test]
fn diagnose_leaves_a_gross_outlier_out_and_refuses_to_attribute_when_there_are_many() {
    let dir = tempfile::tempdir().unwrap();
    let (lines, _) = simulated(dir.path());
    let robot = fixture("irb4400.ron");
    let one = training(dir.path(), &lines, &[137], "one.csv");
    let out = succeeds(&["diagnose", "--robot", &robot, "--data", &text(&one)]);
    assert!(
        out.contains("gross outliers: 1 row(s) beyond 10 robust sigmas of the geometric fit, left out of the diagnosis: line 137 ("),
        "{out}"
    );
    assert!(out.contains(": 299 poses") && !out.contains("verdict:        unknown: gross outliers"), "{out}");
    let json = succeeds(&["diagnose", "--robot", &robot, "--data", &text(&one), "--json"]);
    let diagnosis: serde_json::Value = serde_json::from_str(&json).expect("one JSON object");
    assert_eq!(diagnosis["gross_outliers"]["rows"][0]["line"], 137);
    assert_eq!(diagnosis["gross_outliers"]["attribution_refused"], false);
    assert_eq!(diagnosis["n"], 299);
    // Ten rows in 300 (above 2 %) are no longer errors of the data to leave out quietly.
    let moved: Vec<usize> = (0..10).map(|i| 20 + 25 * i).collect();
    let many = training(dir.path(), &lines, &moved, "many.csv");
    let out = succeeds(&["diagnose", "--robot", &robot, "--data", &text(&many)]);
    assert!(out.contains("verdict:        unknown: gross outliers at line "), "{out}");
    assert!(out.contains("(10 rows, too many to be errors of the data, and the selected effects do not explain them): no effect is attributed"), "{out}");
    for line in &moved {
        assert!(out.contains(&format!("line {line} (")), "line {line}: {out}");
    }
    let json = succeeds(&["diagnose", "--robot", &robot, "--data", &text(&many), "--json"]);
    let diagnosis: serde_json::Value = serde_json::from_str(&json).expect("one JSON object");
    assert_eq!(diagnosis["verdict"]["effect"], "unknown");
    assert_eq!(diagnosis["gross_outliers"]["attribution_refused"], true);
    assert_eq!(diagnosis["gross_outliers"]["kept"], true);
    assert_eq!(diagnosis["gross_outliers"]["unexplained"], 10);
    assert_eq!(diagnosis["gross_outliers"]["rows"].as_array().unwrap().len(), 10);
}
