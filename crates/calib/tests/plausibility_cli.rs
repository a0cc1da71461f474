//! `calib fit` refuses data that fit as well as the right data but describe another robot:
//! metres or inches under `_mm` columns, two position columns swapped, degrees under
//! `_rad` columns; `--force` fits them with a warning; simulated data of every fixture pass.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{calib, fixture, text};

/// Simulated data of `robot` at `out`.
fn simulate(robot: &str, out: &Path, extra: &[&str]) {
    let mut args = vec!["simulate", "--robot", robot, "--out", out.to_str().unwrap(), "--seed", "7"];
    args.extend_from_slice(extra);
    let run = calib(&args);
    assert!(run.status.success(), "{args:?}: {}", String::from_utf8_lossy(&run.stderr));
}

/// The CSV at `from` with every row's cells rewritten by `edit(header, cells)`, written at `to`.
fn rewrite(from: &Path, to: &Path, edit: impl Fn(&[&str], &mut Vec<String>)) {
    let content = std::fs::read_to_string(from).unwrap();
    let mut lines = content.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut out = vec![header.join(",")];
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(str::to_owned).collect();
        edit(&header, &mut cells);
        out.push(cells.join(","));
    }
    std::fs::write(to, out.join("\n") + "\n").unwrap();
}

fn column(header: &[&str], name: &str) -> usize {
    header.iter().position(|c| *c == name).unwrap_or_else(|| panic!("{name} not in {header:?}"))
}

/// Multiplies the named columns by `factor`.
fn scaled(names: &'static [&'static str], factor: f64) -> impl Fn(&[&str], &mut Vec<String>) {
    move |header, cells| {
        for name in names {
            let k = column(header, name);
            cells[k] = (cells[k].parse::<f64>().unwrap() * factor).to_string();
        }
    }
}

fn fit(robot: &str, data: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["fit", "--robot", robot, "--data", data.to_str().unwrap(), "--method", "poe"];
    args.extend_from_slice(&["--out", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    calib(&args)
}

/// Simulated IRB 4400 data, rewritten by `edit`: the refusal's stderr, and the forced fit's stdout.
fn refused_then_forced(dir: &Path, name: &str, edit: impl Fn(&[&str], &mut Vec<String>)) -> (String, PathBuf, String) {
    let (right, wrong, model) = (dir.join("right.csv"), dir.join(format!("{name}.csv")), dir.join("model.ron"));
    let robot = fixture("irb4400.ron");
    simulate(&robot, &right, &["--rows", "120"]);
    rewrite(&right, &wrong, edit);
    let refused = fit(&robot, &wrong, &model, &[]);
    let stderr = String::from_utf8_lossy(&refused.stderr).into_owned();
    eprintln!("{name}: {stderr}");
    assert!(!refused.status.success(), "{name} was fitted: {}", String::from_utf8_lossy(&refused.stdout));
    assert!(!model.exists(), "a refused fit wrote a model");
    assert_eq!(stderr.trim().lines().count(), 1, "one line on stderr: {stderr}");
    let forced = fit(&robot, &wrong, &model, &["--force"]);
    assert!(forced.status.success(), "--force refused {name}: {}", String::from_utf8_lossy(&forced.stderr));
    assert!(model.exists(), "--force wrote no model");
    (stderr, wrong, String::from_utf8_lossy(&forced.stdout).into_owned())
}

fn assert_forced_warning(stdout: &str, refusal: &str) {
    let warning = stdout.lines().find(|l| l.contains("warning: fitted despite the plausibility check (--force)"));
    let warning = warning.unwrap_or_else(|| panic!("no --force warning in {stdout}"));
    assert!(warning.contains(refusal), "{warning}");
}

#[test]
fn metres_under_mm_columns_are_refused_naming_both_spreads_and_forced_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let (stderr, file, stdout) = refused_then_forced(dir.path(), "metres", scaled(&["x_mm", "y_mm", "z_mm"], 1e-3));
    assert!(stderr.contains(&format!("{}: positions look like metres under _mm columns", text(&file))), "{stderr}");
    assert!(stderr.contains("measured spread") && stderr.contains("the robot's"), "{stderr}");
    assert_forced_warning(&stdout, "positions look like metres under _mm columns");
}

#[test]
fn inches_under_mm_columns_are_refused_as_inches() {
    let dir = tempfile::tempdir().unwrap();
    let (stderr, _, stdout) = refused_then_forced(dir.path(), "inches", scaled(&["x_mm", "y_mm", "z_mm"], 1.0 / 25.4));
    assert!(stderr.contains("positions look like inches under _mm columns"), "{stderr}");
    assert_forced_warning(&stdout, "inches under _mm");
}

#[test]
fn a_scale_off_by_half_is_refused_naming_the_ratio() {
    let dir = tempfile::tempdir().unwrap();
    let (stderr, _, _) = refused_then_forced(dir.path(), "half", scaled(&["x_mm", "y_mm", "z_mm"], 0.5));
    assert!(stderr.contains("the positions do not have the robot's size"), "{stderr}");
    // The ratio is named, and it is the half measured (the fitted tool, pulled inwards to shrink
    // the robot's spread, makes it a little more than 0.5), outside the band.
    let ratio: f64 = stderr.split("ratio ").nth(1).and_then(|r| r.split(',').next()).unwrap().parse().unwrap();
    assert!((0.5..0.8).contains(&ratio) && stderr.contains("outside 0.8 to 1.25"), "{stderr}");
}

#[test]
fn swapped_x_and_y_columns_are_refused_as_a_left_handed_frame() {
    let swap = |header: &[&str], cells: &mut Vec<String>| cells.swap(column(header, "x_mm"), column(header, "y_mm"));
    let dir = tempfile::tempdir().unwrap();
    let (stderr, _, stdout) = refused_then_forced(dir.path(), "swapped", swap);
    assert!(stderr.contains("the measured frame looks left-handed: two position columns swapped?"), "{stderr}");
    assert_forced_warning(&stdout, "left-handed");
}

#[test]
fn degrees_under_rad_columns_are_refused_at_the_first_value_beyond_the_limits() {
    let joints = &["q1_rad", "q2_rad", "q3_rad", "q4_rad", "q5_rad", "q6_rad"];
    let dir = tempfile::tempdir().unwrap();
    let (stderr, file, stdout) =
        refused_then_forced(dir.path(), "degrees", scaled(joints, 180.0 / std::f64::consts::PI));
    assert!(stderr.contains("degrees under `_rad`?"), "{stderr}");
    // file:line:column of the value: a data line and one of the six joint columns.
    let place = stderr.trim().strip_prefix(&format!("error: {}:", text(&file))).unwrap_or_else(|| panic!("{stderr}"));
    let mut parts = place.splitn(3, ':');
    let line: usize = parts.next().unwrap().parse().unwrap();
    let column: usize = parts.next().unwrap().parse().unwrap();
    assert!(line >= 2 && (1..=6).contains(&column), "{stderr}");
    assert!(parts.next().unwrap().contains(&format!("joint {column} is at")), "{stderr}");
    assert_forced_warning(&stdout, "degrees under `_rad`?");
}

/// The plausibility report of `calib fit --json` on simulated data of `robot`.
fn passes(robot: &str, simulate_args: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let (data, model) = (dir.path().join("data.csv"), dir.path().join("model.ron"));
    simulate(robot, &data, simulate_args);
    let run = fit(robot, &data, &model, &["--json"]);
    assert!(run.status.success(), "{robot} {simulate_args:?}: {}", String::from_utf8_lossy(&run.stderr));
    let report: serde_json::Value = serde_json::from_slice(&run.stdout).expect("fit prints JSON");
    let check = report["plausibility"].clone();
    eprintln!("{robot} {simulate_args:?}: {check}");
    let ratio = check["scale_ratio"].as_f64().expect("a scale ratio");
    assert!((0.8..=1.25).contains(&ratio), "{robot}: ratio {ratio}");
    assert!(check["reflection_rms_mm"].as_f64() > check["rotation_rms_mm"].as_f64(), "{check}");
    check
}

#[test]
fn simulated_data_of_every_fixture_robot_passes_the_checks() {
    // Compliance, the default effect, where the description has the dynamics it needs; tracker
    // noise alone on every description (the UR10 has no dynamics).
    for robot in ["irb4400.ron", "iiwa7.ron"] {
        passes(&fixture(robot), &["--rows", "100", "--full-pose"]);
    }
    let dir = tempfile::tempdir().unwrap();
    let noise = dir.path().join("noise.ron");
    std::fs::write(&noise, "(tracker_noise: ())\n").unwrap();
    let noise = text(&noise);
    for robot in ["irb4400.ron", "ur10.ron", "iiwa7.ron", "irb4400_dh.ron", "ur10_dh.ron", "iiwa7_dh.ron"] {
        passes(&fixture(robot), &["--rows", "100", "--full-pose", "--effects", &noise]);
    }
    for robot in ["irb4400.urdf", "ur10.urdf", "iiwa7.urdf"] {
        passes(&fixture(robot), &["--rows", "100", "--effects", &noise]);
    }
}

#[test]
fn the_seven_axis_campaign_shape_with_a_tool_per_payload_passes_the_checks() {
    let shape = [
        "--rows",
        "160",
        "--full-pose",
        "--moving-joints",
        "1,2",
        "--fixed-jitter-mrad",
        "2",
        "--payloads",
        "0,1.25,2.5,5",
        "--tool-per-payload",
    ];
    passes(&fixture("iiwa7.ron"), &shape);
}

/// A planar three-link arm: every axis along z, so its tool moves in the plane z = 0.2 m.
const PLANAR: &str = r#"Robot(
    name: "planar three-link",
    joints: [
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.0), limits_deg: (-150.0, 150.0)),
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.4, 0.0, 0.0), limits_deg: (-150.0, 150.0)),
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.8, 0.0, 0.0), limits_deg: (-150.0, 150.0)),
    ],
    flange: (position: (1.1, 0.0, 0.2), x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0)),
)"#;

/// Measurements of the planar arm at 80 poses (position only), each position's height above the
/// plane given by `height(row, x, y)` in metres.
fn planar_data(path: &Path, height: impl Fn(usize, f64, f64) -> f64) {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = String::from("q1_rad,q2_rad,q3_rad,x_mm,y_mm,z_mm\n");
    for row in 0..80 {
        let q: Vec<f64> = (0..3).map(|_| (uniform() - 0.5) * 2.0 * 2.5).collect();
        let (a1, a2, a3) = (q[0], q[0] + q[1], q[0] + q[1] + q[2]);
        let x = 0.4 * a1.cos() + 0.4 * a2.cos() + 0.3 * a3.cos();
        let y = 0.4 * a1.sin() + 0.4 * a2.sin() + 0.3 * a3.sin();
        let z = 0.2 + height(row, x, y);
        out += &format!("{},{},{},{},{},{}\n", q[0], q[1], q[2], x * 1e3, y * 1e3, z * 1e3);
    }
    std::fs::write(path, out).unwrap();
}

#[test]
fn a_planar_chain_with_positions_that_leave_its_plane_is_refused_and_planar_data_pass() {
    let dir = tempfile::tempdir().unwrap();
    let robot = dir.path().join("planar.ron");
    std::fs::write(&robot, PLANAR).unwrap();
    let robot = text(&robot);
    let (flat, spatial, model) =
        (dir.path().join("flat.csv"), dir.path().join("spatial.csv"), dir.path().join("m.ron"));
    // Its own plane, tilted by half a milliradian, with 20 µm of noise: not refused as 3-D data.
    // (The fit stops later, at the tracker registration: a planar chain leaves its placement
    // along the axes unobserved, "the poses are too alike to register the tracker".)
    planar_data(&flat, |row, x, y| 5e-4 * (x + 0.3 * y) + 2e-5 * ((row * 7919 % 13) as f64 / 6.0 - 1.0));
    let run = fit(&robot, &flat, &model, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!stderr.contains("leave a plane"), "{stderr}");
    // The same poses with heights up to 0.3 m: another robot's data.
    planar_data(&spatial, |row, _, _| 0.3 * ((row * 7919 % 101) as f64 / 50.0 - 1.0));
    let refused = fit(&robot, &spatial, &model, &[]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success() && !model.exists(), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains(&format!("{}: the positions leave a plane", text(&spatial))), "{stderr}");
    assert!(
        stderr.contains("planar three-link's chain is planar: all 3 joints turn about axes parallel to (0, 0, 1)"),
        "{stderr}"
    );
}
