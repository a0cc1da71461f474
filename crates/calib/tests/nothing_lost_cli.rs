//! Nothing lost: no command writes over one of its own inputs (under any spelling: `./`, a hard
//! link, a symbolic link), an output that is a symbolic link keeps being one and its target gets
//! the content, what is not a regular file is never replaced, a killed command leaves the old
//! file, and an absurd `simulate --rows` is refused rather than a panic or an abort.

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn calib_in(dir: Option<&Path>, args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_calib"));
    if let Some(dir) = dir {
        command.current_dir(dir);
    }
    command.args(args).output().expect("the calib binary runs")
}

fn calib(args: &[&str]) -> Output {
    calib_in(None, args)
}

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name)
}

fn text(path: &Path) -> String {
    path.display().to_string()
}

fn succeeds(args: &[&str]) -> String {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A command that must be refused: exit status 1 (an error, not a panic's 101 nor a signal), one
/// line on stderr, which is returned.
fn refused(out: &Output, what: &str) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).trim_end().to_owned();
    assert_eq!(out.status.code(), Some(1), "{what} should be refused with exit 1; stderr:\n{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{what}: not one line:\n{stderr}");
    stderr
}

/// The folder's file names, sorted: no temporary file may be left behind by a refusal.
fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// A copy of the IRB 4400 robot file, simulated data of it and a `base-tool` model fitted on it
/// (fast), all in `dir`: inputs that a test may lose without harm to the fixtures.
fn cell(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let robot = dir.join("robot.ron");
    std::fs::copy(fixture("irb4400.ron"), &robot).unwrap();
    let data = dir.join("run.csv");
    succeeds(&["simulate", "--robot", &text(&robot), "--out", &text(&data), "--rows", "60", "--seed", "3"]);
    let model = dir.join("model.ron");
    succeeds(&[
        "fit",
        "--robot",
        &text(&robot),
        "--data",
        &text(&data),
        "--method",
        "base-tool",
        "--out",
        &text(&model),
    ]);
    (robot, data, model)
}

fn fit_to(robot: &Path, data: &Path, out: &str) -> Output {
    calib(&["fit", "--robot", &text(robot), "--data", &text(data), "--method", "base-tool", "--out", out])
}

#[test]
fn fit_refuses_to_write_its_model_over_the_data_or_the_robot() {
    let dir = tempfile::tempdir().unwrap();
    let (robot, data, _) = cell(dir.path());
    let (robot_bytes, data_bytes) = (std::fs::read(&robot).unwrap(), std::fs::read(&data).unwrap());
    let before = names(dir.path());

    let message = refused(&fit_to(&robot, &data, &text(&data)), "fit --out = --data");
    assert_eq!(
        message,
        format!(
            "error: --out {} is the same file as --data {}: refusing to overwrite an input",
            text(&data),
            text(&data)
        )
    );
    let message = refused(&fit_to(&robot, &data, &text(&robot)), "fit --out = --robot");
    assert_eq!(
        message,
        format!(
            "error: --out {} is the same file as --robot {}: refusing to overwrite an input",
            text(&robot),
            text(&robot)
        )
    );
    assert_eq!(std::fs::read(&data).unwrap(), data_bytes);
    assert_eq!(std::fs::read(&robot).unwrap(), robot_bytes);
    assert_eq!(names(dir.path()), before, "nothing written, no temporary file left");
}

#[test]
fn fit_refuses_an_input_under_another_spelling_a_hard_link_or_a_symbolic_link() {
    let dir = tempfile::tempdir().unwrap();
    let (robot, data, _) = cell(dir.path());
    let data_bytes = std::fs::read(&data).unwrap();

    // `./run.csv` against `run.csv`, run from the folder.
    let out = calib_in(
        Some(dir.path()),
        &["fit", "--robot", "robot.ron", "--data", "run.csv", "--method", "base-tool", "--out", "./run.csv"],
    );
    let message = refused(&out, "fit --out ./run.csv --data run.csv");
    assert_eq!(message, "error: --out ./run.csv is the same file as --data run.csv: refusing to overwrite an input");

    let hard = dir.path().join("hard.csv");
    std::fs::hard_link(&data, &hard).unwrap();
    let message = refused(&fit_to(&robot, &data, &text(&hard)), "fit --out a hard link of --data");
    assert!(
        message.contains(&format!("--out {} is the same file as --data {}", text(&hard), text(&data))),
        "{message}"
    );

    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&data, &link).unwrap();
    let message = refused(&fit_to(&robot, &data, &text(&link)), "fit --out a symbolic link to --data");
    assert!(
        message.contains(&format!("--out {} is the same file as --data {}", text(&link), text(&data))),
        "{message}"
    );
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());

    // And the other way round: the data given through the link, the model written to the file.
    let out = calib(&[
        "fit",
        "--robot",
        &text(&robot),
        "--data",
        &text(&link),
        "--method",
        "base-tool",
        "--out",
        &text(&data),
    ]);
    let message = refused(&out, "fit --data a symbolic link to --out");
    assert!(message.contains(&format!("is the same file as --data {}", text(&link))), "{message}");
    assert_eq!(std::fs::read(&data).unwrap(), data_bytes);
}

#[test]
fn export_refuses_to_write_its_urdf_over_the_model() {
    let dir = tempfile::tempdir().unwrap();
    let (_, _, model) = cell(dir.path());
    let model_bytes = std::fs::read(&model).unwrap();
    let out = calib(&["export", "--model", &text(&model), "--urdf", &text(&model)]);
    let message = refused(&out, "export --urdf = --model");
    assert_eq!(
        message,
        format!(
            "error: --urdf {} is the same file as --model {}: refusing to overwrite an input",
            text(&model),
            text(&model)
        )
    );
    assert_eq!(std::fs::read(&model).unwrap(), model_bytes);
}

#[test]
fn simulate_refuses_to_write_over_its_robot_file() {
    let dir = tempfile::tempdir().unwrap();
    let robot = dir.path().join("robot.ron");
    std::fs::copy(fixture("irb4400.ron"), &robot).unwrap();
    let bytes = std::fs::read(&robot).unwrap();
    let message = refused(&calib(&["simulate", "--robot", &text(&robot), "--out", &text(&robot)]), "simulate");
    let expected = format!("is the same file as --robot {}: refusing to overwrite an input", text(&robot));
    assert!(message.ends_with(&expected), "{message}");
    assert_eq!(std::fs::read(&robot).unwrap(), bytes);
}

#[test]
fn an_output_that_is_a_symbolic_link_stays_one_and_its_target_gets_the_content() {
    let dir = tempfile::tempdir().unwrap();
    let robot = fixture("irb4400.ron");
    let real = dir.path().join("real.csv");
    std::fs::write(&real, "old\n").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink("real.csv", &link).unwrap();
    succeeds(&["simulate", "--robot", &text(&robot), "--out", &text(&link), "--rows", "5", "--seed", "1"]);
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link is still a link");
    let written = std::fs::read_to_string(&real).unwrap();
    assert!(written.starts_with("q1_rad,"), "the link's target holds the measurements: {written}");
    assert_eq!(written.lines().count(), 6);
    // The same bytes as a plain output of the same seed.
    let plain = dir.path().join("plain.csv");
    succeeds(&["simulate", "--robot", &text(&robot), "--out", &text(&plain), "--rows", "60", "--seed", "1"]);
    let plain_5 = dir.path().join("plain5.csv");
    succeeds(&["simulate", "--robot", &text(&robot), "--out", &text(&plain_5), "--rows", "5", "--seed", "1"]);
    assert_eq!(std::fs::read(&plain_5).unwrap(), written.into_bytes());
    assert_eq!(names(dir.path()), ["link.csv", "plain.csv", "plain5.csv", "real.csv"], "no temporary file left");

    // fit writes through a temporary file and a rename: the link must survive that too.
    let real_model = dir.path().join("real.ron");
    std::fs::write(&real_model, "old\n").unwrap();
    let model_link = dir.path().join("model.ron");
    std::os::unix::fs::symlink(&real_model, &model_link).unwrap();
    let out = fit_to(&robot, &plain, &text(&model_link));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::symlink_metadata(&model_link).unwrap().file_type().is_symlink(), "the model link is kept");
    assert!(std::fs::read_to_string(&real_model).unwrap().contains("schema_version"), "its target holds the model");
}

#[test]
fn a_directory_a_fifo_or_a_device_node_is_never_replaced_by_an_output() {
    let dir = tempfile::tempdir().unwrap();
    let (robot, data, _) = cell(dir.path());
    let folder = dir.path().join("folder");
    std::fs::create_dir(&folder).unwrap();
    let message = refused(&fit_to(&robot, &data, &text(&folder)), "fit --out a directory");
    assert_eq!(
        message,
        format!("error: {}: is a directory, not a regular file: refusing to replace it with an output", text(&folder))
    );
    assert!(folder.is_dir());

    // `/dev/null` through `simulate` only: were the check missing, simulate would write into it, harmless,
    // where a fit's rename would replace the machine's /dev/null (these tests may run as root).
    let out = calib(&["simulate", "--robot", &text(&robot), "--out", "/dev/null", "--rows", "5"]);
    let message = refused(&out, "simulate --out /dev/null");
    assert_eq!(
        message,
        "error: /dev/null: is a character device, not a regular file: refusing to replace it with an output"
    );

    let fifo = dir.path().join("fifo");
    match Command::new("mkfifo").arg(&fifo).status() {
        Ok(status) if status.success() => {
            // fit, not simulate: were the check missing, opening a FIFO for writing with no reader would block.
            let message = refused(&fit_to(&robot, &data, &text(&fifo)), "fit --out a FIFO");
            assert_eq!(
                message,
                format!(
                    "error: {}: is a FIFO (named pipe), not a regular file: refusing to replace it with an output",
                    text(&fifo)
                )
            );
            use std::os::unix::fs::FileTypeExt;
            assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO is still a FIFO");
        }
        _ => eprintln!("note: mkfifo is not available here; the FIFO case is skipped"),
    }
    let mut expected = vec!["fifo", "folder", "model.ron", "robot.ron", "run.csv"];
    if !dir.path().join("fifo").exists() {
        expected.retain(|n| *n != "fifo");
    }
    assert_eq!(names(dir.path()), expected, "no temporary file left");
}

#[test]
fn simulate_refuses_an_absurd_row_count_without_panicking() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("sim.csv");
    for rows in ["18446744073709551615", "1000000000"] {
        let out =
            calib(&["simulate", "--robot", &text(&fixture("irb4400.ron")), "--out", &text(&out_path), "--rows", rows]);
        let message = refused(&out, &format!("simulate --rows {rows}"));
        assert_eq!(
            message,
            format!(
                "error: --rows: {rows} rows asked for: at most 1000000 are simulated (up to 280 MB of CSV and 25 s; is the count mistyped?)"
            )
        );
        assert!(!out_path.exists());
    }
}

/// Kill -9 while `simulate` writes: the output holds the old file, never a part (a temporary file
/// may be left next to it, as nothing can clean up after a kill). The kill must land while rows
/// are being written: `simulate` writes each row as it draws it, so with 100,000 rows (seconds
/// of drawing in debug) it is still running when the first buffer of rows reaches the temporary
/// file, and the exit status must say it was killed.
#[test]
fn a_simulate_killed_while_writing_leaves_the_old_file() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("sim.csv");
    let old = b"the previous measurements\n".to_vec();
    std::fs::write(&out_path, &old).unwrap();
    let rows = 100_000;
    let mut child = Command::new(env!("CARGO_BIN_EXE_calib"))
        .args(["simulate", "--robot", &text(&fixture("irb4400.ron")), "--out", &text(&out_path), "--rows"])
        .arg(rows.to_string())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Kill once rows have reached the disk: a file next to the output that is not empty, or the
    // output itself changed (where the writer wrote in place).
    let started = std::time::Instant::now();
    let writing = || {
        let others = names(dir.path()).into_iter().filter(|n| n != "sim.csv");
        others.into_iter().any(|n| std::fs::metadata(dir.path().join(n)).is_ok_and(|m| m.len() > 0))
            || std::fs::read(&out_path).map(|b| b != old).unwrap_or(true)
    };
    loop {
        if writing() {
            child.kill().unwrap();
            break;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("simulate ended ({status}) before it was seen writing: the kill would not land");
        }
        assert!(started.elapsed().as_secs() < 60, "simulate wrote nothing in 60 s");
        std::thread::sleep(std::time::Duration::from_micros(200));
    }
    let status = child.wait().unwrap();
    assert_eq!(status.signal(), Some(9), "simulate was not killed but ended: {status}");
    let content = std::fs::read(&out_path).unwrap();
    assert!(
        content == old,
        "killed while writing, the output is no longer the old file: {} bytes, {} lines",
        content.len(),
        String::from_utf8_lossy(&content).lines().count()
    );
}

#[test]
fn diagnose_refuses_a_report_folder_whose_files_are_its_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let (robot, data, _) = cell(dir.path());
    // The measurements named as the report's own markdown file.
    let data_as_report = dir.path().join("diagnosis.md");
    std::fs::rename(&data, &data_as_report).unwrap();
    let bytes = std::fs::read(&data_as_report).unwrap();
    let out =
        calib(&["diagnose", "--robot", &text(&robot), "--data", &text(&data_as_report), "--report", &text(dir.path())]);
    let message = refused(&out, "diagnose --report holding --data");
    assert_eq!(
        message,
        format!(
            "error: --report {} is the same file as --data {}: refusing to overwrite an input",
            text(&data_as_report),
            text(&data_as_report)
        )
    );
    assert_eq!(std::fs::read(&data_as_report).unwrap(), bytes);
    assert_eq!(names(dir.path()), ["diagnosis.md", "model.ron", "robot.ron"], "no plot written either");
}
