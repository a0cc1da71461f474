//! Part of `cargo xtask deps`: the crates CI builds alone resolve every dependency with the
//! features `cargo test --workspace` resolves it with, so that they reuse the tests' build.
//!
//! `cargo test --workspace` resolves features over every member's normal and dev-dependencies;
//! `cargo xtask …` (`cargo run -p xtask`), maturin's build of the Python extension
//! (`cargo rustc -p calib-python`) and `cargo build -p calib` (in `cargo xtask hostile`) over that
//! one crate's graph. A dependency resolved with other
//! features gets another build hash, so it and every crate above it are compiled again: faer and
//! the whole workspace, three more times in CI. `crates/workspace-hack` lists the tests' features for
//! them; this finds what it misses, from `cargo tree` (resolution only, nothing is built).

use anyhow::{Context, Result, ensure};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

/// The crates that CI builds on their own after the tests: `cargo xtask`, the Python step, and
/// `cargo build -p calib`, which `cargo xtask hostile` runs to find the binary.
const BUILT_ALONE: [&str; 3] = ["xtask", "calib-python", "calib"];

/// One line per dependency `cargo build -p` of each of [`BUILT_ALONE`] would resolve with other
/// features than `cargo test --workspace` does (empty when they share its build).
pub(crate) fn drift(root: &Path) -> Result<Vec<String>> {
    let tests = parse_tree(&cargo_tree(root, &["--workspace", "-e", "normal,build,dev"])?);
    let mut problems = Vec::new();
    for package in BUILT_ALONE {
        let alone = parse_tree(&cargo_tree(root, &["-p", package, "-e", "normal,build"])?);
        problems.extend(differences(package, &alone, &tests));
    }
    Ok(problems)
}

/// Each package `package` resolves with features the tests do not resolve it with.
fn differences(package: &str, alone: &Resolution, tests: &Resolution) -> Vec<String> {
    let mut problems = Vec::new();
    for (id, features) in alone {
        let theirs = tests.get(id);
        for ours in features.iter().filter(|f| !theirs.is_some_and(|set| set.contains(*f))) {
            let theirs = theirs.map_or_else(
                || "(not in its graph)".to_owned(),
                |set| set.iter().map(|f| format!("[{f}]")).collect::<Vec<_>>().join(" or "),
            );
            problems.push(format!(
                "{package} resolves {id} with features [{ours}] but `cargo test --workspace` with {theirs}: \
                 add them to crates/workspace-hack/Cargo.toml ([build-dependencies] for a proc macro's \
                 dependency), or CI compiles it and every crate above it again"
            ));
        }
    }
    problems
}

/// Each package (`name vX.Y.Z`) with the feature lists it is built with (two where it is built for
/// build scripts or proc macros with other features than for the code that links it).
type Resolution = BTreeMap<String, BTreeSet<String>>;

/// `cargo tree --prefix none --format {p}|{f}` of one selection of packages.
fn cargo_tree(root: &Path, selection: &[&str]) -> Result<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let out = Command::new(&cargo)
        .current_dir(root)
        .args(["tree", "--prefix", "none", "--format", "{p}|{f}"])
        .args(selection)
        .output()
        .with_context(|| format!("running {cargo} tree"))?;
    ensure!(out.status.success(), "cargo tree {selection:?} failed: {}", String::from_utf8_lossy(&out.stderr).trim());
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    ensure!(text.contains('|'), "cargo tree {selection:?} listed no package");
    Ok(text)
}

fn parse_tree(text: &str) -> Resolution {
    let mut packages = Resolution::new();
    for line in text.lines() {
        let Some((package, features)) = line.split_once('|') else { continue };
        // `name vX.Y.Z (path)`, `… (proc-macro)`: the name and version identify it.
        let id = package.split(' ').take(2).collect::<Vec<_>>().join(" ");
        let features = features.trim_end_matches(" (*)").trim();
        packages.entry(id).or_default().insert(features.to_owned());
    }
    packages
}

#[cfg(test)]
mod tests {
    use super::*;

    const TESTS: &str = "either v1.19.0|std,use_std\n\
                         syn v3.0.10|clone-impls,extra-traits\n\
                         serde_derive v1.0.229 (proc-macro)|default (*)\n\
                         robot v0.1.0 (/work/crates/robot)|\n";

    #[test]
    fn a_build_alone_with_the_tests_features_shares_their_build() {
        let alone = "either v1.19.0|std,use_std (*)\nrobot v0.1.0 (/elsewhere/crates/robot)|\n\
                     serde_derive v1.0.229 (proc-macro)|default\n";
        assert_eq!(differences("xtask", &parse_tree(alone), &parse_tree(TESTS)), Vec::<String>::new());
    }

    #[test]
    fn a_feature_missing_alone_names_the_package_and_both_feature_lists() {
        let alone = "either v1.19.0|\nsyn v3.0.10|clone-impls\n";
        let problems = differences("calib-python", &parse_tree(alone), &parse_tree(TESTS));
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(
            problems[0].starts_with("calib-python resolves either v1.19.0 with features [] but"),
            "{}",
            problems[0]
        );
        assert!(problems[0].contains("with [std,use_std]: add them"), "{}", problems[0]);
        assert!(problems[1].contains("syn v3.0.10 with features [clone-impls]"), "{}", problems[1]);
    }

    #[test]
    fn a_package_the_tests_never_build_is_drift_too() {
        let problems = differences("xtask", &parse_tree("zerocopy v0.8.63|simd\n"), &parse_tree(TESTS));
        assert_eq!(problems.len(), 1);
        assert!(problems[0].contains("(not in its graph)"), "{}", problems[0]);
    }
}
