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

#[test]
fn the_model_keeps_its_robot_and_the_fit_s_warnings_so_the_report_needs_neither_robot_nor_fit_output() {
    let dir = tempfile::tempdir().unwrap();
    // 15 position-only rows for a full POE fit: few rows per parameter, which the fit warns of.
    let (train, test) = (simulated(dir.path(), 15, 8), simulated(dir.path(), 60, 9));
    let model = dir.path().join("model.ron");
    let robot = fixture("irb4400.ron");
    let fit = ["fit", "--robot", &robot, "--data", &text(&train), "--method", "poe", "--out", &text(&model)];
    let (printed, _) = succeeds_with_stderr(&fit);
    let warning = printed.lines().find(|l| l.contains("warning:")).unwrap_or_else(|| panic!("no warning: {printed}"));
    let kept = std::fs::read_to_string(&model).unwrap();
    assert!(kept.contains("fit_warnings: Some([") && kept.contains("robot_description: Some("), "{kept}");
    let out = dir.path().join("report.html");
    let report = ["report", "--model", &text(&model), "--data", &text(&test), "--out", &text(&out)];
    succeeds_with_stderr(&report);
    let html = std::fs::read_to_string(&out).unwrap();
    let section = html.split("<h3>From the fit</h3>").nth(1).unwrap().split("<h3>").next().unwrap();
    let said = warning.split("warning:").nth(1).unwrap().trim();
    let first_words: String = said.chars().take(40).collect();
    assert!(section.contains(&first_words), "{first_words:?} not in {section}");
    assert!(html.contains(&format!("{} (as the model keeps it)", text(&model))), "the robot's source");

    // A model written before both were kept: the report asks for --robot, and then says that the
    // fit's warnings are not in the file.
    let older = dir.path().join("older.ron");
    let cut = kept.find("    fit_warnings:").unwrap();
    std::fs::write(&older, format!("{})\n", &kept[..cut])).unwrap();
    let report = ["report", "--model", &text(&older), "--data", &text(&test), "--out", &text(&out)];
    let refused = fails(&report);
    assert!(
        refused.contains("older.ron: the model does not keep its robot description")
            && refused.contains("give --robot"),
        "{refused}"
    );
    let with_robot = [&report[..], &["--robot", &robot]].concat();
    succeeds_with_stderr(&with_robot);
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.contains("This model file was written before the fit's own warnings"), "no note on the older file");
}
