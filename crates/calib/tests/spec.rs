//! `docs/SPEC.md` against the code: the SPEC's tables are read here, the commands run
//! on simulated data, and every column, `--effects` item, model-file field and JSON key must be
//! where the SPEC says, in both directions, so that neither can change without the other.
//!
//! What is compared: the measurement CSV's columns (each read by the reader, none ignored), the
//! columns `simulate`, `predict` and `compensate` write, the `--effects` items (the parser's list),
//! the model file's top-level fields, and the key paths of `fit`, `eval`, `diagnose`, `export`,
//! `register` and `plan --json` (every key printed is in the SPEC; every key the SPEC says is
//! always there is there wherever its parent object is).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

mod common;
use common::{calib, fixture, text};

fn spec_text() -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/SPEC.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A markdown table: the heading it stands under, its header cells and its rows' cells.
struct Table {
    heading: String,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

fn cells(line: &str) -> Vec<String> {
    let inner = line.trim().trim_start_matches('|').trim_end_matches('|');
    inner.split('|').map(|c| c.trim().to_owned()).collect()
}

fn tables(spec: &str) -> Vec<Table> {
    let lines: Vec<&str> = spec.lines().collect();
    let mut out = Vec::new();
    let mut heading = String::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.starts_with('#') {
            heading = line.trim_start_matches('#').trim().to_owned();
        }
        let is_separator = |l: &str| l.trim().starts_with("| ---");
        if line.trim_start().starts_with('|') && lines.get(i + 1).is_some_and(|l| is_separator(l)) {
            let header = cells(line);
            let mut rows = Vec::new();
            i += 2;
            while i < lines.len() && lines[i].trim_start().starts_with('|') {
                rows.push(cells(lines[i]));
                i += 1;
            }
            out.push(Table { heading: heading.clone(), header, rows });
            continue;
        }
        i += 1;
    }
    out
}

/// The text between backticks in a cell, in order.
fn ticked(cell: &str) -> Vec<String> {
    cell.split('`').skip(1).step_by(2).map(str::to_owned).collect()
}

fn table<'a>(tables: &'a [Table], heading: &str, first_header: &str) -> &'a Table {
    tables
        .iter()
        .find(|t| t.heading == heading && t.header.first().is_some_and(|h| h == first_header))
        .unwrap_or_else(|| panic!("docs/SPEC.md has no table '{first_header}' under '{heading}'"))
}

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

// ---------------------------------------------------------------------------------------------
// JSON keys

#[derive(Debug, Clone, Copy, PartialEq)]
enum Presence {
    Always,
    OrNull,
    Optional,
}

#[derive(Debug, Default)]
struct KeySpec {
    /// Key path → whether it must be there.
    keys: BTreeMap<String, Presence>,
    /// Key paths whose value is opaque: nothing below them is compared.
    opaque: BTreeSet<String>,
}

fn presence(cell: &str) -> Presence {
    match cell {
        "always" => Presence::Always,
        "or null" => Presence::OrNull,
        "opt." => Presence::Optional,
        other => panic!("docs/SPEC.md: presence '{other}' is not always, or null, opt."),
    }
}

/// The shapes the SPEC names (`Shape `summary``), by name.
fn shapes(tables: &[Table]) -> BTreeMap<String, &Table> {
    tables
        .iter()
        .filter_map(|t| t.heading.strip_prefix("Shape ").map(|name| (name.trim_matches('`').to_owned(), t)))
        .collect()
}

/// The key paths of one JSON table, its shapes expanded under `prefix`.
fn expand(table: &Table, prefix: &str, shapes: &BTreeMap<String, &Table>, spec: &mut KeySpec) {
    assert_eq!(
        table.header,
        ["key", "shape", "presence", "meaning"],
        "'{}': the columns of a JSON table",
        table.heading
    );
    for row in &table.rows {
        let (keys, shape, presence_cell) = (ticked(&row[0]), row[1].as_str(), row[2].as_str());
        assert!(!keys.is_empty(), "'{}': a row without a key: {row:?}", table.heading);
        for key in keys {
            let path = if prefix.is_empty() { key } else { format!("{prefix}.{key}") };
            spec.keys.insert(path.clone(), presence(presence_cell));
            let depth = shape.matches('[').count();
            let inner = shape.trim_matches(|c| c == '[' || c == ']');
            let below = format!("{path}{}", "[]".repeat(depth));
            if inner == "opaque" {
                spec.opaque.insert(path);
            } else if let Some(named) = shapes.get(inner) {
                expand(named, &below, shapes, spec);
            }
        }
    }
}

fn key_spec(command: &str) -> KeySpec {
    let spec = spec_text();
    let tables = tables(&spec);
    let shapes = shapes(&tables);
    let heading = format!("`calib {command} --json`");
    let table = tables.iter().find(|t| t.heading == heading).unwrap_or_else(|| panic!("docs/SPEC.md has no {heading}"));
    let mut keys = KeySpec::default();
    expand(table, "", &shapes, &mut keys);
    keys
}

/// Every key path of `value` (`a.b`, `a[].b`) and every path at which an object stands.
fn walk(value: &serde_json::Value, prefix: &str, paths: &mut BTreeSet<String>, objects: &mut BTreeSet<String>) {
    match value {
        serde_json::Value::Object(map) => {
            objects.insert(prefix.to_owned());
            for (key, inner) in map {
                let path = if prefix.is_empty() { key.clone() } else { format!("{prefix}.{key}") };
                paths.insert(path.clone());
                walk(inner, &path, paths, objects);
            }
        }
        serde_json::Value::Array(items) => {
            for item in items {
                walk(item, &format!("{prefix}[]"), paths, objects);
            }
        }
        _ => {}
    }
}

/// The keys `json` (one `calib COMMAND --json` output) prints against the SPEC's table of the
/// command: the keys found beside any the SPEC lacks, and the keys the SPEC says are always
/// there that are missing. Returns the paths seen, for the caller to check what it planted.
fn check_json(command: &str, json: &str) -> BTreeSet<String> {
    let spec = key_spec(command);
    let value: serde_json::Value = serde_json::from_str(json).unwrap_or_else(|e| panic!("{command}: {e}: {json}"));
    let (mut paths, mut objects) = (BTreeSet::new(), BTreeSet::new());
    walk(&value, "", &mut paths, &mut objects);
    let under_opaque = |path: &str| {
        spec.opaque.iter().any(|o| path.strip_prefix(o.as_str()).is_some_and(|rest| rest.starts_with(['.', '['])))
    };
    let unknown: Vec<&String> = paths.iter().filter(|p| !spec.keys.contains_key(*p) && !under_opaque(p)).collect();
    assert!(unknown.is_empty(), "calib {command} --json prints keys docs/SPEC.md does not list: {unknown:?}");
    let missing: Vec<&String> = spec
        .keys
        .iter()
        .filter(|(path, presence)| {
            let parent = path.rsplit_once('.').map_or("", |(parent, _)| parent);
            **presence != Presence::Optional && objects.contains(parent) && !paths.contains(*path)
        })
        .map(|(path, _)| path)
        .collect();
    assert!(missing.is_empty(), "calib {command} --json lacks keys docs/SPEC.md says are always there: {missing:?}");
    paths
}

/// The campaign every JSON check runs on: an IRB 4400 (full pose) simulated once, its first rows
/// to fit (one of them a metre off, a gross outlier), the rest to test, some of those placed
/// where the warnings of `eval` apply.
struct Campaign {
    _dir: tempfile::TempDir,
    train: PathBuf,
    test: PathBuf,
    few: PathBuf,
    model: PathBuf,
}

fn rewrite(lines: &[String], path: &Path) -> PathBuf {
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
    path.to_path_buf()
}

fn campaign() -> Campaign {
    let dir = tempfile::tempdir().unwrap();
    let all = dir.path().join("all.csv");
    let robot = fixture("irb4400.ron");
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&all), "--rows", "160", "--seed", "48", "--full-pose"]);
    let lines: Vec<String> = std::fs::read_to_string(&all).unwrap().lines().map(str::to_owned).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let column = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let set = |line: &str, name: &str, value: &dyn Fn(f64) -> f64| {
        let mut cells: Vec<String> = line.split(',').map(str::to_owned).collect();
        let i = column(name);
        cells[i] = format!("{}", value(cells[i].parse().unwrap()));
        cells.join(",")
    };
    // Alternate rows, so that the test rows lie within the training rows' inputs (time too).
    let rows = |parity: usize| lines[1..].iter().skip(parity).step_by(2).cloned();
    let mut train: Vec<String> = std::iter::once(lines[0].clone()).chain(rows(0)).collect();
    train[40] = set(&train[40], "x_mm", &|x| x + 1000.0);
    let mut test: Vec<String> = std::iter::once(lines[0].clone()).chain(rows(1)).collect();
    // A tracker glitch, a joint beyond its limit (and the fitted range), a wrist a turn away.
    test[5] = set(&test[5], "y_mm", &|y| y + 50.0);
    test[6] = set(&test[6], "q1_rad", &|_| 3.0);
    test[7] = set(&test[7], "q6_rad", &|q| if q > 0.0 { q - std::f64::consts::TAU } else { q + std::f64::consts::TAU });
    let few = test[..21].to_vec();
    let campaign = Campaign {
        train: rewrite(&train, &dir.path().join("train.csv")),
        test: rewrite(&test, &dir.path().join("test.csv")),
        few: rewrite(&few, &dir.path().join("few.csv")),
        model: dir.path().join("model.ron"),
        _dir: dir,
    };
    let fit = succeeds(&[
        "fit",
        "--robot",
        &robot,
        "--data",
        &text(&campaign.train),
        "--method",
        "poe-gp",
        "--effects",
        "joint_compliance,gear_periodic:1:1",
        "--out",
        &text(&campaign.model),
        "--json",
    ]);
    let paths = check_json("fit", &fit);
    for planted in ["outliers[].line", "warnings[].rows[].line", "residual_gp.leave_one_out.n", "effects[].label"] {
        assert!(paths.contains(planted), "fit --json: {planted} not printed");
    }
    campaign
}

#[test]
fn every_json_key_is_the_specs() {
    let campaign = campaign();
    let robot = fixture("irb4400.ron");
    let model = text(&campaign.model);
    let eval = succeeds(&["eval", "--model", &model, "--data", &text(&campaign.test), "--json"]);
    let paths = check_json("eval", &eval);
    for planted in [
        "suspect_rows.rows[].line",
        "out_of_range[].first_line",
        "beyond_joint_limits[].first_line",
        "wrapped[].first_line",
        "coverage.inside.n",
        "range_split.outside.n",
    ] {
        assert!(paths.contains(planted), "eval --json: {planted} not printed: {eval}");
    }
    let dir = tempfile::tempdir().unwrap();
    let registered = dir.path().join("registered.ron");
    let register = succeeds(&[
        "register",
        "--model",
        &model,
        "--data",
        &text(&campaign.few),
        "--out",
        &text(&registered),
        "--json",
    ]);
    check_json("register", &register);
    let urdf = dir.path().join("out.urdf");
    let export =
        succeeds(&["export", "--model", &model, "--urdf", &text(&urdf), "--data", &text(&campaign.train), "--json"]);
    let paths = check_json("export", &export);
    assert!(paths.contains("training_error.without_each[].error.n"), "{export}");
    let planned = dir.path().join("plan.csv");
    let plan = succeeds(&[
        "plan",
        "--robot",
        &robot,
        "--model",
        &model,
        "--poses",
        "8",
        "--generate",
        "120",
        "--out",
        &text(&planned),
        "--json",
    ]);
    let paths = check_json("plan", &plan);
    assert!(paths.contains("unmodelled_from.heldout_mm") && paths.contains("unmodelled_mrad_from.from"), "{plan}");
    let diagnose = succeeds(&["diagnose", "--robot", &robot, "--data", &text(&campaign.train), "--json"]);
    let paths = check_json("diagnose", &diagnose);
    assert!(paths.contains("gross_outliers.rows[].line"), "{diagnose}");
    // The model file's top-level fields (RON, one per line at the first indent).
    let file = std::fs::read_to_string(&campaign.model).unwrap();
    let fields: BTreeSet<String> = file
        .lines()
        .filter_map(|l| l.strip_prefix("    ").filter(|r| !r.starts_with(' ')))
        .filter_map(|l| l.split_once(':').map(|(name, _)| name.to_owned()))
        .collect();
    let spec = spec_text();
    let tables = tables(&spec);
    let model_table = table(&tables, "Model file (RON) (v3)", "field");
    let listed: BTreeMap<String, Presence> =
        model_table.rows.iter().map(|r| (ticked(&r[0])[0].clone(), presence(&r[1]))).collect();
    let unknown: Vec<&String> = fields.iter().filter(|f| !listed.contains_key(*f)).collect();
    assert!(unknown.is_empty(), "the model file has fields docs/SPEC.md does not list: {unknown:?}");
    let missing: Vec<&String> =
        listed.iter().filter(|(f, p)| **p == Presence::Always && !fields.contains(*f)).map(|(f, _)| f).collect();
    assert!(missing.is_empty(), "the model file lacks fields docs/SPEC.md says are always there: {missing:?}");
    for field in ["effects", "residual_gp", "training_range", "heldout", "robot_description"] {
        assert!(fields.contains(field), "{field} not written");
    }
}

#[test]
fn a_json_key_renamed_in_the_code_only_fails_the_check() {
    // The check itself: a key the SPEC does not list, and a key it says is always there missing.
    let json = r#"{"method":"poe","robot":"r","data":"d","full_pose":false,"n":1,"mean_position_error_mm":1,
        "rms_position_error_mm":1,"max_position_error_mm":1,"median_position_err_mm":1,
        "format":{"dialect":{"delimiter":"comma","decimal":"point"},"euler_angles":false,"mapped_columns":[]},"warnings":[]}"#;
    let failure = std::panic::catch_unwind(|| check_json("eval", json)).expect_err("a renamed key must fail");
    let message = failure.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(message.contains("median_position_err_mm"), "{message}");
    let json =
        json.replace("median_position_err_mm", "median_position_error_mm").replace(r#""euler_angles":false,"#, "");
    let failure = std::panic::catch_unwind(|| check_json("eval", &json)).expect_err("a missing key must fail");
    let message = failure.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(message.contains("format.euler_angles"), "{message}");
}

// ---------------------------------------------------------------------------------------------
// CSV columns

/// The column names of a table cell: `q1_rad` … `qN_rad` with `1`…`N` (or `K`) for the joints.
fn column_names(cell: &str, joints: &[(usize, &str)]) -> Vec<Vec<String>> {
    // Groups: the names before "(or", and each alternative after it.
    cell.split("(or ")
        .map(|part| {
            let mut names = Vec::new();
            for name in ticked(part) {
                if name.contains('N') && (name.starts_with('q') || name.starts_with("tau")) {
                    // One name per joint of the unit's kind (`qN_rad`: the revolute joints).
                    let unit = name.rsplit('_').next().unwrap();
                    for &(k, kind) in joints {
                        let fits = match unit {
                            "rad" | "deg" => kind == "revolute",
                            "m" | "mm" => kind == "prismatic",
                            _ => true,
                        };
                        if fits {
                            names.push(name.replace('N', &k.to_string()).replace("q1_", &format!("q{k}_")));
                        }
                    }
                } else if name.contains('K') {
                    for &(k, kind) in joints {
                        if kind == "prismatic" {
                            names.push(name.replace('K', &k.to_string()));
                        }
                    }
                } else {
                    names.push(name);
                }
            }
            names.sort();
            names.dedup();
            names
        })
        .filter(|g| !g.is_empty())
        .collect()
}

#[test]
fn every_measurement_column_of_the_spec_is_read() {
    use measurements::{ReadOptions, parse_measurements};
    use poe::JointKind;
    let spec = spec_text();
    let tables = tables(&spec);
    let columns = table(&tables, "Measurement CSV", "column");
    // A revolute and a prismatic joint: every unit has a joint to name.
    let joints = [(1, "revolute"), (2, "prismatic")];
    let base = ["q1_rad", "q2_m", "x_mm", "y_mm", "z_mm"];
    let value = |name: &str| match name {
        "qw" => "1",
        "qx" | "qy" | "qz" => "0",
        "tool" => "probe",
        _ => "0.5",
    };
    let mut seen = 0;
    for row in &columns.rows {
        for group in column_names(&row[0], &joints) {
            // The group replaces the base columns of the same quantity (`x_m` for `x_mm`).
            let prefix = |n: &str| n.split('_').next().unwrap_or(n).to_owned();
            let mut header: Vec<String> =
                base.iter().filter(|b| !group.iter().any(|g| prefix(g) == prefix(b))).map(|b| b.to_string()).collect();
            header.extend(group.iter().cloned());
            let row_text: Vec<&str> = header.iter().map(|h| value(h)).collect();
            let csv = format!("{}\n{}\n", header.join(","), row_text.join(","));
            let options = ReadOptions::for_joints(vec![JointKind::Revolute, JointKind::Prismatic]);
            let set = parse_measurements(csv.as_bytes(), "spec.csv", &options)
                .unwrap_or_else(|e| panic!("docs/SPEC.md's columns {group:?} are refused: {e}\n{csv}"));
            assert!(set.ignored_columns.is_empty(), "docs/SPEC.md's {group:?}: ignored {:?}", set.ignored_columns);
            seen += group.len();
        }
    }
    assert!(seen >= 25, "only {seen} columns read from the SPEC's table");
}

/// The names of a table of output columns, `[…]` ones included, for the joints given.
fn written_columns(table: &Table, joints: &[(usize, &str)]) -> Vec<String> {
    let mut names = Vec::new();
    for row in &table.rows {
        let cell = &row[0];
        if !cell.contains('`') || cell.starts_with("(every other") {
            continue;
        }
        // `q1_rad` … `qN_rad` (`qK_m` for a prismatic joint K): the joint columns in order.
        if cell.contains("qN_rad") {
            let prefix = if cell.contains("nominal_") { "nominal_" } else { "" };
            for &(k, kind) in joints {
                names.push(format!("{prefix}q{k}_{}", if kind == "prismatic" { "m" } else { "rad" }));
            }
        } else if cell.contains("tauN_nm") {
            names.extend(joints.iter().map(|(k, _)| format!("tau{k}_nm")));
        } else {
            names.extend(ticked(cell));
        }
    }
    names
}

#[test]
fn the_columns_calib_writes_are_the_specs() {
    let spec = spec_text();
    let tables = tables(&spec);
    let heading = "CSV files calib writes (v3)";
    let joints: Vec<(usize, &str)> = (1..=6).map(|k| (k, "revolute")).collect();
    let dir = tempfile::tempdir().unwrap();
    let robot = fixture("irb4400.ron");
    let data = dir.path().join("sim.csv");
    succeeds(&[
        "simulate",
        "--robot",
        &robot,
        "--out",
        &text(&data),
        "--rows",
        "60",
        "--seed",
        "2",
        "--full-pose",
        "--tool-per-payload",
        "--payloads",
        "1,5",
        "--torques",
    ]);
    let written = std::fs::read_to_string(&data).unwrap();
    let header: Vec<&str> = written.lines().next().unwrap().split(',').collect();
    assert_eq!(header, written_columns(table(&tables, heading, "`calib simulate` column"), &joints), "simulate");
    // One tool, for the targets of `compensate` to name none.
    succeeds(&["simulate", "--robot", &robot, "--out", &text(&data), "--rows", "60", "--seed", "2", "--full-pose"]);
    let written = std::fs::read_to_string(&data).unwrap();
    let model = dir.path().join("m.ron");
    succeeds(&["fit", "--robot", &robot, "--data", &text(&data), "--method", "poe-gp", "--out", &text(&model)]);
    let predicted = succeeds(&["predict", "--model", &text(&model), "--data", &text(&data)]);
    let header: Vec<&str> = predicted.lines().next().unwrap().split(',').collect();
    assert_eq!(header, written_columns(table(&tables, heading, "`calib predict` column"), &joints), "predict");
    // Joint targets: the input's joint columns become nominal_…, the other input columns stay.
    let lines: Vec<String> = written.lines().map(|l| l.split(',').take(6).collect::<Vec<_>>().join(",")).collect();
    let targets = rewrite(&lines[..4], &dir.path().join("targets.csv"));
    let compensated = succeeds(&["compensate", "--model", &text(&model), "--targets", &text(&targets)]);
    let header: Vec<&str> = compensated.lines().next().unwrap().split(',').collect();
    assert_eq!(header, written_columns(table(&tables, heading, "`calib compensate` column"), &joints), "compensate");
}

// ---------------------------------------------------------------------------------------------
// `--effects` items

#[test]
fn the_effects_items_are_the_parsers() {
    let spec = spec_text();
    let tables = tables(&spec);
    let items = table(&tables, "`--effects` items", "item");
    let listed: BTreeSet<String> = items.rows.iter().map(|r| ticked(&r[0])[0].clone()).collect();
    let parsed: BTreeSet<String> = effects::effect_items().split(", ").map(str::to_owned).collect();
    assert_eq!(listed, parsed, "docs/SPEC.md's --effects items against the parser's");
    // Each item, its arguments filled in, is taken by the parser.
    for item in &listed {
        let filled = item.replace("JOINT", "1").replace("PITCH_MM", "10").replace("HARMONICS", "2");
        filled.parse::<effects::EffectSelection>().unwrap_or_else(|e| panic!("{filled}: {e}"));
    }
}

// ---------------------------------------------------------------------------------------------
// `fit --json` warning kinds

/// One warning of each kind the fit gives (`pipeline::FitWarning`), `forced` carrying a
/// plausibility check's refusal.
fn every_fit_warning() -> Vec<pipeline::FitWarning> {
    use pipeline::FitWarning;
    let outlier = measurements::OutlierLine {
        line: 7,
        position_mm: 1000.0,
        position_sigmas: 400.0,
        rotation_mrad: None,
        rotation_sigmas: None,
    };
    let warnings = vec![
        FitWarning::Forced { refusal: "a refusal".to_owned() },
        FitWarning::LowRedundancy { residual_rows: 30, identifiable: 24, redundancy: 1.25, min_redundancy: 3.0 },
        FitWarning::GpSearchNotConverged { outputs: vec![0], iterations: 200 },
        FitWarning::GrossOutliers { rows: vec![outlier], threshold_sigmas: 10.0, left_out: true },
        FitWarning::ConstantEffect { effect: "backlash:1".to_owned() },
        FitWarning::StatedUncertaintyFarAbove { rows: vec![(7, 12.0)], far_above_median: 10.0 },
        FitWarning::WrongMinimum { rms_mm: 9.0, rigid_rms_mm: 3.0 },
    ];
    // No wildcard: a kind added to the code does not compile here until it is added above, and
    // then it must be in docs/SPEC.md's list for the test below to pass.
    for warning in &warnings {
        match warning {
            FitWarning::Forced { .. }
            | FitWarning::LowRedundancy { .. }
            | FitWarning::GpSearchNotConverged { .. }
            | FitWarning::GrossOutliers { .. }
            | FitWarning::ConstantEffect { .. }
            | FitWarning::StatedUncertaintyFarAbove { .. }
            | FitWarning::WrongMinimum { .. } => {}
        }
    }
    warnings
}

#[test]
fn the_fit_warning_kinds_are_the_specs() {
    let spec = spec_text();
    let tables = tables(&spec);
    let table = table(&tables, "`calib fit --json`", "key");
    let row = |key: &str| {
        table.rows.iter().find(|r| r[0] == format!("`{key}`")).unwrap_or_else(|| panic!("docs/SPEC.md lacks {key}"))
    };
    let listed: BTreeSet<String> = ticked(&row("warnings[].kind")[3]).into_iter().collect();
    let mut kinds = BTreeSet::new();
    for warning in every_fit_warning() {
        let value = serde_json::to_value(&warning).unwrap();
        let kind = value["kind"].as_str().unwrap_or_else(|| panic!("no kind: {value}")).to_owned();
        // Each field the kind prints is a `warnings[].…` row of the SPEC that names the kind.
        for field in value.as_object().unwrap().keys().filter(|k| *k != "kind") {
            let cells = row(&format!("warnings[].{field}"));
            assert!(ticked(&cells[3]).contains(&kind), "docs/SPEC.md's warnings[].{field} does not name {kind}");
        }
        kinds.insert(kind);
    }
    assert_eq!(listed, kinds, "docs/SPEC.md's fit warning kinds against pipeline::FitWarning's");
}
