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
