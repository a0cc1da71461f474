//! `calib eval` on rows where the GP's training rows say nothing: the fade is reported in the JSON
//! (`gp_fade`, with the file line of the first such row) and as a warning in the text, and on the
//! training rows themselves there is none. The library's fade is tested in pipeline's
//! `gp_methods.rs`; this holds what a user reads.

mod common;

use common::{eval_json, fixture, succeeds_with_stderr as run, text};

#[test]
fn eval_reports_the_gp_fade_where_the_training_rows_say_nothing_and_not_on_them() {
    let dir = tempfile::tempdir().unwrap();
    let [train, far, model] = ["train.csv", "far.csv", "model.ron"].map(|name| dir.path().join(name));
    let robot = fixture("irb4400.ron");
    run(&["simulate", "--robot", &robot, "--out", &text(&train), "--rows", "120", "--seed", "4"]);
    run(&["fit", "--robot", &robot, "--data", &text(&train), "--method", "poe-gp", "--out", &text(&model)]);

    // The first 10 rows with every joint moved a whole radian beyond the largest value the
    // training rows have: nothing the GP has seen. The positions are left as they are (eval
    // compares them; the fade does not read them).
    let content = std::fs::read_to_string(&train).unwrap();
    let mut lines = content.lines();
    let header = lines.next().unwrap();
    let names: Vec<&str> = header.split(',').collect();
    let joints: Vec<usize> =
        (0..names.len()).filter(|&c| names[c].starts_with('q') && names[c].ends_with("_rad")).collect();
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(str::to_owned).collect()).collect();
    let top: Vec<f64> = joints
        .iter()
        .map(|&c| rows.iter().map(|r| r[c].parse::<f64>().unwrap()).fold(f64::NEG_INFINITY, f64::max))
        .collect();
    let moved: Vec<String> = rows[..10]
        .iter()
        .map(|r| {
            let mut r = r.clone();
            for (k, &c) in joints.iter().enumerate() {
                let q: f64 = r[c].parse().unwrap();
                r[c] = format!("{}", top[k] + 1.0 + 0.1 * q.sin());
            }
            r.join(",")
        })
        .collect();
    std::fs::write(&far, format!("{header}\n{}\n", moved.join("\n"))).unwrap();

    let on_training = eval_json(&model, &train);
    assert!(on_training.get("gp_fade").is_none_or(|v| v.is_null()), "training rows fade: {on_training}");

    let json = eval_json(&model, &far);
    let fade = &json["gp_fade"];
    assert_eq!(fade["of_rows"], 10, "{json}");
    assert_eq!(fade["rows"], 10, "every moved row fades: {fade}");
    assert_eq!(fade["first_line"], 2, "the first data row is file line 2: {fade}");
    let (share, above) = (fade["largest_share"].as_f64().unwrap(), fade["fade_above"].as_f64().unwrap());
    assert!(share > above && share <= 1.0, "{fade}");

    let (stdout, _) = run(&["eval", "--model", &text(&model), "--data", &text(&far)]);
    assert!(
        stdout.contains("warning: 10 of 10 rows (the first at line 2) lie where the GP's training rows say little"),
        "{stdout}"
    );
}
