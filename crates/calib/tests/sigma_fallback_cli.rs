//! `calib eval` and `calib predict` on rows that excite combinations of the effects' parameters no
//! training row did: the model falls back to the geometry fitted alone there, and says so in the
//! JSON (`sigma_fallback`, with the file line of the first such row) and as a warning; on the
//! training rows themselves there is none. The library's fallback is tested in pipeline's
//! `effects.rs`; this holds what a user reads.

mod common;

use common::{eval_json, fixture, succeeds_with_stderr as run, text};

#[test]
fn eval_and_predict_report_the_sigma_fallback_off_the_training_band_and_not_on_it() {
    let dir = tempfile::tempdir().unwrap();
    let [all, train, off, model] = ["all.csv", "train.csv", "off.csv", "model.ron"].map(|name| dir.path().join(name));
    let robot = fixture("irb4400.ron");
    run(&["simulate", "--robot", &robot, "--out", &text(&all), "--rows", "1500", "--seed", "61"]);

    // Trained where the elbow follows the shoulder (|q2 + q3| < 0.15 rad), joint compliance is
    // determined only along that band; rows off it (|q2 + q3| > 0.6) excite what no training row
    // did (as pipeline's effects.rs, on the command line).
    let content = std::fs::read_to_string(&all).unwrap();
    let mut lines = content.lines();
    let header = lines.next().unwrap();
    let names: Vec<&str> = header.split(',').collect();
    let column = |name: &str| names.iter().position(|n| *n == name).unwrap();
    let (q2, q3) = (column("q2_rad"), column("q3_rad"));
    let band = |line: &str| {
        let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap_or(f64::NAN)).collect();
        (fields[q2] + fields[q3]).abs()
    };
    let rows: Vec<&str> = lines.collect();
    let on: Vec<&str> = rows.iter().copied().filter(|l| band(l) < 0.15).collect();
    let far: Vec<&str> = rows.iter().copied().filter(|l| band(l) > 0.6).take(30).collect();
    assert!(on.len() > 100 && far.len() == 30, "{} / {} rows", on.len(), far.len());
    std::fs::write(&train, format!("{header}\n{}\n", on.join("\n"))).unwrap();
    std::fs::write(&off, format!("{header}\n{}\n", far.join("\n"))).unwrap();
    run(&[
        "fit",
        "--robot",
        &robot,
        "--data",
        &text(&train),
        "--method",
        "poe",
        "--effects",
        "joint_compliance",
        "--out",
        &text(&model),
    ]);

    let on_training = eval_json(&model, &train);
    assert!(on_training.get("sigma_fallback").is_none_or(|v| v.is_null()), "training rows fall back: {on_training}");

    let json = eval_json(&model, &off);
    let fallen = &json["sigma_fallback"];
    assert_eq!(fallen["of_rows"], 30, "{json}");
    let rows = fallen["rows"].as_u64().expect("rows off the band fall back");
    assert!(rows >= 10 && fallen["fully"].as_u64().unwrap() <= rows, "{fallen}");
    let first = fallen["first_line"].as_u64().unwrap();
    assert!((2..=31).contains(&first), "a data line of the file: {fallen}");
    let [limit, training, largest] =
        ["limit_mm", "training_max_mm", "largest_sigma_mm"].map(|key| fallen[key].as_f64().unwrap());
    assert!(training < limit && limit < largest, "{fallen}");

    let expected = format!(
        "warning: {rows} of 30 rows (the first at line {first}) excite combinations of the effects' parameters that \
         no training row did: the model's σ there reaches {largest:.3} mm, above the {limit:.3} mm it falls back \
         from ({training:.3} mm at most on the training rows), so there it uses the geometry fitted alone"
    );
    let (stdout, _) = run(&["eval", "--model", &text(&model), "--data", &text(&off)]);
    assert!(stdout.contains(&expected), "eval:\n{stdout}\nexpected:\n{expected}");
    let (_, stderr) = run(&["predict", "--model", &text(&model), "--data", &text(&off)]);
    assert!(stderr.contains(&expected), "predict:\n{stderr}\nexpected:\n{expected}");
    let (_, stderr) = run(&["predict", "--model", &text(&model), "--data", &text(&train)]);
    assert!(!stderr.contains("excite combinations"), "predict on the training rows:\n{stderr}");
}
