//! `calib report` and `calib diagnose --report` end to end: the page embeds exactly what
//! `calib eval --json` prints, refuses to overwrite an input, and the diagnosis folder gets its
//! plots and page from the same writer.

mod common;

use common::{calib, fails, fixture, succeeds_with_stderr, text};
use std::path::{Path, PathBuf};

fn simulated(dir: &Path, rows: usize, seed: u64) -> PathBuf {
    let path = dir.join(format!("sim{seed}.csv"));
    let args = ["--out", &text(&path), "--rows", &rows.to_string(), "--seed", &seed.to_string()];
    let robot = fixture("irb4400.ron");
    succeeds_with_stderr(&[&["simulate", "--robot", robot.as_str()], &args[..]].concat());
    path
}

#[test]
fn the_report_embeds_eval_json_as_eval_prints_it() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 120, 5);
    let model = dir.path().join("model.ron");
    let robot = fixture("irb4400.ron");
    let fit = ["fit", "--robot", &robot, "--data", &text(&data), "--method", "poe", "--out", &text(&model)];
    succeeds_with_stderr(&fit);
    let (eval, _) = succeeds_with_stderr(&["eval", "--model", &text(&model), "--data", &text(&data), "--json"]);
    let out = dir.path().join("report.html");
    let report = ["report", "--model", &text(&model), "--robot", &robot, "--data", &text(&data), "--out", &text(&out)];
    succeeds_with_stderr(&report);
    let html = std::fs::read_to_string(&out).unwrap();
    let embedded = html.split("id=\"eval-json\">").nth(1).unwrap().split("</script>").next().unwrap();
    assert_eq!(embedded.replace("<\\/", "</"), eval.trim_end());
    let json: serde_json::Value = serde_json::from_str(&eval).unwrap();
    let mean = json["mean_position_error_mm"].as_f64().unwrap();
    assert!(html.contains(&format!("data-key=\"after.mean_position_error_mm\" data-value=\"{mean}\"")));
}

#[test]
fn the_report_refuses_to_write_over_its_data() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 60, 6);
    let robot = fixture("irb4400.ron");
    let before = std::fs::read(&data).unwrap();
    let err =
        fails(&["report", "--model", "none.ron", "--robot", &robot, "--data", &text(&data), "--out", &text(&data)]);
    assert!(err.contains("--out"), "{err}");
    assert_eq!(std::fs::read(&data).unwrap(), before);
}

#[test]
fn the_diagnosis_folder_has_its_plots_its_markdown_and_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 150, 7);
    let folder = dir.path().join("diag");
    let out =
        calib(&["diagnose", "--robot", &fixture("irb4400.ron"), "--data", &text(&data), "--report", &text(&folder)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let markdown = std::fs::read_to_string(folder.join("diagnosis.md")).unwrap();
    let page = std::fs::read_to_string(folder.join("diagnosis.html")).unwrap();
    for j in 1..=6 {
        let name = format!("joint{j}.svg");
        let svg = std::fs::read_to_string(folder.join(&name)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("Held-out error against joint"), "{name}");
        assert!(
            markdown.contains(&format!("![{name}]({name})"))
                && page.contains(&format!("<figcaption>{name}</figcaption>"))
        );
    }
    assert!(page.contains("<section id=\"diagnosis\">"));
}
