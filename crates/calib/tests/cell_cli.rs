//! `calib register` and `calib plan` end to end (crate `cell`).

use std::path::{Path, PathBuf};

mod common;
use common::{fails, fixture, succeeds_with_stderr, text};

/// A simulated full-pose IRB 4400 data set of `rows` rows and a `poe` model fitted on its first
/// 150 rows: (data, model).
fn setup(dir: &Path, rows: usize) -> (PathBuf, PathBuf) {
    let data = dir.join("sim.csv");
    let train = dir.join("train.csv");
    let model = dir.join("poe.ron");
    let rows = rows.to_string();
    succeeds_with_stderr(&[
        "simulate",
        "--robot",
        &fixture("irb4400.ron"),
        "--out",
        &text(&data),
        "--rows",
        &rows,
        "--seed",
        "4",
        "--full-pose",
    ]);
    let content = std::fs::read_to_string(&data).unwrap();
    let lines: Vec<&str> = content.lines().collect();
    std::fs::write(&train, lines[..151].join("\n") + "\n").unwrap();
    succeeds_with_stderr(&[
        "fit",
        "--robot",
        &fixture("irb4400.ron"),
        "--data",
        &text(&train),
        "--method",
        "poe",
        "--out",
        &text(&model),
    ]);
    (data, model)
}

/// Hamilton product `a ⊗ b` of quaternions `(w, x, y, z)`.
fn product(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Rows `range` of a full-pose CSV seen from a tracker moved by a quarter turn about z and
/// `(2.5, −1.0, 0.3)` m: `p' = R p + t`, `q' = q_R ⊗ q`.
fn moved(data: &Path, out: &Path, range: std::ops::Range<usize>) {
    let content = std::fs::read_to_string(data).unwrap();
    let mut lines = content.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (x, y, z, qw) = (at("x_mm"), at("y_mm"), at("z_mm"), at("qw"));
    let half = std::f64::consts::FRAC_PI_4;
    let turn = [half.cos(), 0.0, 0.0, half.sin()];
    let mut text = header.join(",") + "\n";
    for line in lines.skip(range.start).take(range.len()) {
        let mut cells: Vec<String> = line.split(',').map(str::to_owned).collect();
        let v = |i: usize| cells[i].parse::<f64>().unwrap();
        let (px, py, pz) = (v(x), v(y), v(z));
        let q = product(turn, [v(qw), v(qw + 1), v(qw + 2), v(qw + 3)]);
        cells[x] = (-py + 2500.0).to_string();
        cells[y] = (px - 1000.0).to_string();
        cells[z] = (pz + 300.0).to_string();
        for k in 0..4 {
            cells[qw + k] = q[k].to_string();
        }
        text += &(cells.join(",") + "\n");
    }
    std::fs::write(out, text).unwrap();
}

fn json_number(json: &str, key: &str) -> f64 {
    let start = json.find(&format!("\"{key}\":")).unwrap_or_else(|| panic!("{key} in {json}")) + key.len() + 3;
    let end = json[start..].find([',', '}']).unwrap() + start;
    json[start..end].parse().unwrap()
}

#[test]
fn register_carries_a_model_to_a_moved_tracker() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = setup(dir.path(), 400);
    let few = dir.path().join("few.csv");
    let rest = dir.path().join("rest.csv");
    let original_rest = dir.path().join("original_rest.csv");
    moved(&data, &few, 150..175);
    moved(&data, &rest, 200..400);
    let content = std::fs::read_to_string(&data).unwrap();
    let lines: Vec<&str> = content.lines().collect();
    std::fs::write(&original_rest, [&lines[..1], &lines[201..401]].concat().join("\n") + "\n").unwrap();
    let out = dir.path().join("moved.ron");
    let (stdout, _) = succeeds_with_stderr(&[
        "register",
        "--model",
        &text(&model),
        "--data",
        &text(&few),
        "--out",
        &text(&out),
        "--heldout-mm",
        "1.0",
        "--json",
    ]);
    assert!(stdout.contains("\"verdict\":\"consistent\""), "{stdout}");
    assert!((json_number(&stdout, "angle_deg") - 90.0).abs() < 0.05, "{stdout}");
    let eval = |model: &Path, data: &Path| {
        succeeds_with_stderr(&["eval", "--model", &text(model), "--data", &text(data), "--json"])
    };
    let (before_json, _) = eval(&model, &original_rest);
    let (after_json, _) = eval(&out, &rest);
    let (before, after) =
        (json_number(&before_json, "mean_position_error_mm"), json_number(&after_json, "mean_position_error_mm"));
    assert!(after < 1.2 * before, "registered {after} mm against the original's {before} mm");
    // Neither is said to be from another placement.
    for json in [&before_json, &after_json] {
        assert!(!json.contains("other_placement"), "{json}");
    }
    // The model as it was cannot be used on the moved data, and eval says why: one
    // rigid motion leaves what the model leaves on the unmoved rows, and `calib register` is named.
    let (moved_json, stderr) = eval(&model, &rest);
    assert!(json_number(&moved_json, "mean_position_error_mm") > 1000.0);
    let remaining =
        json_number(&moved_json[moved_json.find("\"other_placement\"").unwrap()..], "mean_position_error_mm");
    assert!(remaining < 1.2 * before, "{remaining} mm after the rigid motion, {before} mm unmoved: {moved_json}");
    assert!(stderr.contains("another tracker placement") && stderr.contains("calib register --model"), "{stderr}");
}

#[test]
fn register_refuses_too_few_poses_with_the_counts() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = setup(dir.path(), 160);
    let few = dir.path().join("few.csv");
    moved(&data, &few, 150..152);
    let out = dir.path().join("moved.ron");
    let message = fails(&["register", "--model", &text(&model), "--data", &text(&few), "--out", &text(&out)]);
    assert!(message.contains("2 poses (12 residual rows) for 6 re-fitted parameters"), "{message}");
    assert!(message.contains("at least 3 poses"), "{message}");
    assert!(!out.exists());
}

#[test]
fn register_refuses_a_new_tool_unless_tools_are_refitted() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = setup(dir.path(), 170);
    let few = dir.path().join("few.csv");
    moved(&data, &few, 150..170);
    let content = std::fs::read_to_string(&few).unwrap();
    let tooled: Vec<String> =
        content.lines().enumerate().map(|(i, l)| format!("{l},{}", if i == 0 { "tool" } else { "probe2" })).collect();
    std::fs::write(&few, tooled.join("\n") + "\n").unwrap();
    let out = dir.path().join("moved.ron");
    let message = fails(&["register", "--model", &text(&model), "--data", &text(&few), "--out", &text(&out)]);
    assert!(message.contains("tool 'probe2' is not in the model"), "{message}");
    assert!(message.contains(":2:"), "{message}");
    let (stdout, _) = succeeds_with_stderr(&[
        "register",
        "--model",
        &text(&model),
        "--data",
        &text(&few),
        "--out",
        &text(&out),
        "--refit",
        "base,tools",
    ]);
    assert!(stdout.contains("tool 'probe2' (new)"), "{stdout}");
    assert!(std::fs::read_to_string(&out).unwrap().contains("\"probe2\""));
}

#[test]
fn register_never_overwrites_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = setup(dir.path(), 180);
    let before = std::fs::read(&model).unwrap();
    let few = dir.path().join("few.csv");
    moved(&data, &few, 150..180);
    let message = fails(&["register", "--model", &text(&model), "--data", &text(&few), "--out", &text(&model)]);
    assert!(message.contains("--out"), "{message}");
    assert_eq!(std::fs::read(&model).unwrap(), before);
}

#[test]
fn plan_writes_chosen_candidate_rows_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let candidates = dir.path().join("candidates.csv");
    succeeds_with_stderr(&[
        "simulate",
        "--robot",
        &fixture("irb4400.ron"),
        "--out",
        &text(&candidates),
        "--rows",
        "300",
        "--seed",
        "5",
    ]);
    let chosen = dir.path().join("chosen.csv");
    let (stdout, _) = succeeds_with_stderr(&[
        "plan",
        "--robot",
        &fixture("irb4400.ron"),
        "--candidates",
        &text(&candidates),
        "--poses",
        "20",
        "--out",
        &text(&chosen),
        "--json",
    ]);
    assert_eq!(json_number(&stdout, "poses"), 20.0);
    assert!(stdout.contains("\"checkpoints\""), "{stdout}");
    let input = std::fs::read_to_string(&candidates).unwrap();
    let output = std::fs::read_to_string(&chosen).unwrap();
    let (input_lines, output_lines): (Vec<&str>, Vec<&str>) = (input.lines().collect(), output.lines().collect());
    assert_eq!(output_lines[0], input_lines[0]);
    assert_eq!(output_lines.len(), 21);
    for line in &output_lines[1..] {
        assert!(input_lines[1..].contains(line), "{line} is not a candidate row as written");
    }
}

/// With `--model`, the plan's unmodelled error is the model's held-out error (mean 3-D × √(π/8)
/// per axis) unless the options set it, and the report says where each came from.
#[test]
fn plan_takes_the_unmodelled_error_from_the_models_heldout_error() {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = setup(dir.path(), 250);
    let content = std::fs::read_to_string(&model).unwrap();
    let at = content.find("mean_position_error_mm: ").expect("a poe fit keeps its held-out estimate") + 24;
    let heldout: f64 = content[at..at + content[at..].find(',').unwrap()].parse().unwrap();
    let sigma = heldout * (std::f64::consts::PI / 8.0).sqrt();
    let plan = |options: Option<&str>| {
        let chosen = dir.path().join("chosen.csv");
        let mut args: Vec<String> = ["plan", "--robot", &fixture("irb4400.ron"), "--model", &text(&model)]
            .into_iter()
            .map(String::from)
            .collect();
        args.extend(["--candidates", &text(&data), "--poses", "12", "--out", &text(&chosen)].map(String::from));
        if let Some(options) = options {
            let file = dir.path().join("options.ron");
            std::fs::write(&file, options).unwrap();
            args.extend(["--options".to_owned(), text(&file)]);
        }
        let json =
            succeeds_with_stderr(&[args.iter().map(String::as_str).collect::<Vec<_>>(), vec!["--json"]].concat()).0;
        std::fs::remove_file(&chosen).unwrap();
        let lines = succeeds_with_stderr(&args.iter().map(String::as_str).collect::<Vec<_>>()).0;
        std::fs::remove_file(&chosen).unwrap();
        (json, lines)
    };
    let (json, lines) = plan(None);
    assert!((json_number(&json, "unmodelled_mm") - sigma).abs() < 1e-12, "{json}");
    assert!((json_number(&json, "unmodelled_mrad") - sigma).abs() < 1e-12, "{json}");
    assert!(json.contains("\"unmodelled_from\":{\"from\":\"model\""), "{json}");
    assert!(json.contains("\"heldout_source\":\"degrees_of_freedom\""), "{json}");
    assert!(
        lines.contains(&format!("unmodelled error {sigma:.3} mm per axis (from the poe model's held-out error")),
        "{lines}"
    );
    // Set in the options: kept, and said so; the orientation's still from the model.
    let (json, lines) = plan(Some("(unmodelled_mm: 0.3)"));
    assert_eq!(json_number(&json, "unmodelled_mm"), 0.3);
    assert!((json_number(&json, "unmodelled_mrad") - sigma).abs() < 1e-12, "{json}");
    assert!(json.contains("\"unmodelled_from\":{\"from\":\"options\"}"), "{json}");
    assert!(json.contains("\"unmodelled_mrad_from\":{\"from\":\"model\""), "{json}");
    assert!(lines.contains("unmodelled error 0.300 mm per axis (set in the options)"), "{lines}");
}

#[test]
fn plan_refuses_more_poses_than_candidates_with_the_counts() {
    let dir = tempfile::tempdir().unwrap();
    let candidates = dir.path().join("candidates.csv");
    std::fs::write(
        &candidates,
        "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad\n0.1,0.2,0.3,0.4,0.5,0.6\n0.2,0.1,0.0,0.4,0.5,0.6\n",
    )
    .unwrap();
    let chosen = dir.path().join("chosen.csv");
    let message = fails(&[
        "plan",
        "--robot",
        &fixture("irb4400.ron"),
        "--candidates",
        &text(&candidates),
        "--poses",
        "3",
        "--out",
        &text(&chosen),
    ]);
    assert!(message.contains("3 poses asked for but only 2 candidates"), "{message}");
    assert!(!chosen.exists());
}

#[test]
fn plan_without_candidates_draws_them_within_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let chosen = dir.path().join("chosen.csv");
    let (stdout, _) = succeeds_with_stderr(&[
        "plan",
        "--robot",
        &fixture("ur10.ron"),
        "--poses",
        "12",
        "--generate",
        "400",
        "--out",
        &text(&chosen),
    ]);
    assert!(stdout.contains("drew 400 candidates"), "{stdout}");
    let output = std::fs::read_to_string(&chosen).unwrap();
    assert!(output.starts_with("q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad\n"));
    assert_eq!(output.lines().count(), 13);
}

/// `eval` and `predict` take a revolute angle a turn away from the fitted range back into it, as
/// `register` does, and say so: the IRB 4400's joint 6 spans ±400°; a `poe-gp` model fitted on
/// rows with |q6| < 3 rad, evaluated on rows inside its range whose negative q6 is shifted by +2π, gives the errors
/// and the poses of the unshifted rows (the GP, fitted on q6 as an input, would otherwise be
/// asked 2π away from its data), and the JSON names the joint.
#[test]
fn eval_and_predict_wrap_angles_a_turn_away_into_the_fitted_range() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("sim.csv");
    let robot = fixture("irb4400.ron");
    succeeds_with_stderr(&["simulate", "--robot", &robot, "--out", &text(&data), "--rows", "600", "--seed", "6"]);
    let content = std::fs::read_to_string(&data).unwrap();
    let mut lines = content.lines();
    let header = lines.next().unwrap();
    let q6 = header.split(',').position(|h| h == "q6_rad").unwrap();
    let value = |line: &str| line.split(',').nth(q6).unwrap().parse::<f64>().unwrap();
    let inside: Vec<&str> = lines.filter(|l| value(l).abs() < 3.0).collect();
    let (train, rest) = inside.split_at(120);
    // Test rows within the angles the model was fitted on, so that each shifted row wraps back.
    let (low, high) = train.iter().map(|l| value(l)).fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let test: Vec<&str> = rest.iter().copied().filter(|l| (low..=high).contains(&value(l))).collect();
    let shifted: Vec<String> = test
        .iter()
        .map(|l| {
            let mut cells: Vec<String> = l.split(',').map(str::to_owned).collect();
            let q = value(l);
            if q < 0.0 {
                cells[q6] = (q + std::f64::consts::TAU).to_string();
            }
            cells.join(",")
        })
        .collect();
    let write = |name: &str, rows: &[String]| {
        let path = dir.path().join(name);
        std::fs::write(&path, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
        path
    };
    let own = |rows: &[&str]| rows.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let (train, test, shifted) =
        (write("train.csv", &own(train)), write("test.csv", &own(&test)), write("shifted.csv", &shifted));
    let moved = shifted_rows(&std::fs::read_to_string(&shifted).unwrap(), q6);
    assert!(moved > 20, "{moved} rows shifted");
    let model = dir.path().join("gp.ron");
    let args = ["fit", "--robot", &robot, "--data", &text(&train), "--method", "poe-gp", "--gp", "exact"];
    succeeds_with_stderr(&[&args[..], &["--out", &text(&model)]].concat());
    let eval = |data: &Path| succeeds_with_stderr(&["eval", "--model", &text(&model), "--data", &text(data), "--json"]);
    let ((plain, _), (wrapped, note)) = (eval(&test), eval(&shifted));
    let (a, b) = (json_number(&plain, "mean_position_error_mm"), json_number(&wrapped, "mean_position_error_mm"));
    assert!((a - b).abs() < 1e-9, "unshifted {a} mm, shifted {b} mm");
    // Joint 4 (±200°) may wrap a row in both; joint 6 only the shifted rows, every one of them.
    let joint6 = "{\"joint\":6,\"rows_wrapped\":";
    assert!(!plain.contains(joint6), "{plain}");
    let at = wrapped.find(joint6).unwrap_or_else(|| panic!("{wrapped}")) + joint6.len();
    let count: usize = wrapped[at..].split(',').next().unwrap().parse().unwrap();
    assert_eq!(count, moved);
    assert!(note.contains("joint 6:") && note.contains("modulo 2π"), "{note}");
    let predict = |data: &Path| succeeds_with_stderr(&["predict", "--model", &text(&model), "--data", &text(data)]);
    let ((plain, _), (wrapped, note)) = (predict(&test), predict(&shifted));
    assert!(note.contains("joint 6:"), "{note}");
    let numbers = |csv: &str| -> Vec<f64> {
        csv.lines()
            .skip(1)
            .flat_map(|l| l.split(',').skip(1).map(|c| c.parse::<f64>().unwrap_or(0.0)).collect::<Vec<_>>())
            .collect()
    };
    let (p, w) = (numbers(&plain), numbers(&wrapped));
    assert_eq!(p.len(), w.len());
    assert!(p.iter().zip(&w).all(|(x, y)| (x - y).abs() < 2e-6), "the poses of shifted rows differ");
}

/// Rows of a CSV whose joint column `q6` lies above π (those shifted by a turn).
fn shifted_rows(csv: &str, q6: usize) -> usize {
    csv.lines().skip(1).filter(|l| l.split(',').nth(q6).unwrap().parse::<f64>().unwrap() > std::f64::consts::PI).count()
}
