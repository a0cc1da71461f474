//! What the binary's end-to-end tests share: running `calib`, and the fixtures' paths.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `calib` binary with `args`.
pub fn calib(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_calib")).args(args).output().expect("the calib binary runs")
}

/// The path of `fixtures/robots/<name>`, as text for an argument.
pub fn fixture(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name).display().to_string()
}

/// A path as text for an argument.
pub fn text(path: &Path) -> String {
    path.display().to_string()
}

/// Runs a command that must succeed and returns its stdout and stderr.
#[allow(dead_code)] // not every test file that shares this module uses it
pub fn succeeds_with_stderr(args: &[&str]) -> (String, String) {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// `calib eval --json` of `model` on `data`, which must succeed, parsed.
#[allow(dead_code)] // not every test file that shares this module uses it
pub fn eval_json(model: &Path, data: &Path) -> serde_json::Value {
    let (stdout, _) = succeeds_with_stderr(&["eval", "--model", &text(model), "--data", &text(data), "--json"]);
    serde_json::from_str(&stdout).expect("eval prints JSON")
}

/// Runs a command that must fail and returns its stderr, checked to be exactly one line.
#[allow(dead_code)] // not every test file that shares this module uses it
pub fn fails(args: &[&str]) -> String {
    let out = calib(args);
    assert!(!out.status.success(), "{args:?} should fail: {}", String::from_utf8_lossy(&out.stdout));
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: not one line:\n{stderr}");
    stderr.trim_end().to_owned()
}
