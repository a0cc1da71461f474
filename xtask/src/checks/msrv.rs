//! `cargo xtask msrv`: the oldest Rust that builds the workspace as `Cargo.lock` pins it — the
//! newest `rust-version` among the locked dependencies built on this platform (and 1.85 for the
//! 2024 edition) — against what `Cargo.toml` and the README state. A test holds them equal, so a
//! dependency update that needs a newer compiler cannot leave the stated version behind.

use anyhow::{Context, Result, bail};
use serde::Deserialize;
use std::path::Path;
use std::process::Command;

/// Print the Rust version `Cargo.lock` needs and check `Cargo.toml` and the README state it.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// The 2024 edition's first compiler.
const EDITION_2024: (u64, u64) = (1, 85);

#[derive(Debug, Deserialize)]
struct Metadata {
    packages: Vec<Package>,
    resolve: Resolve,
}

#[derive(Debug, Deserialize)]
struct Package {
    id: String,
    name: String,
    version: String,
    rust_version: Option<String>,
    /// `None` for the workspace's own packages.
    source: Option<String>,
}

#[derive(Debug, Deserialize)]
struct Resolve {
    nodes: Vec<Node>,
}

#[derive(Debug, Deserialize)]
struct Node {
    id: String,
}

/// `1.89` or `1.89.0` as (major, minor).
fn parse_version(text: &str) -> Option<(u64, u64)> {
    let mut parts = text.split('.');
    Some((parts.next()?.parse().ok()?, parts.next()?.parse().ok()?))
}

/// What the lock needs and what the workspace states.
#[derive(Debug)]
struct Versions {
    /// The newest `rust-version` of a locked dependency built here (at least the edition's).
    needed: (u64, u64),
    /// The dependencies that ask for it, `name version`.
    needed_by: Vec<String>,
    /// The workspace packages' `rust-version`, each.
    stated: Vec<(String, Option<(u64, u64)>)>,
}

fn host() -> Result<String> {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let output = Command::new(rustc).arg("-vV").output().context("running rustc -vV")?;
    let text = String::from_utf8_lossy(&output.stdout);
    let host = text.lines().find_map(|l| l.strip_prefix("host: ")).context("rustc -vV names no host")?;
    Ok(host.trim().to_owned())
}

fn versions(workspace: &Path) -> Result<Versions> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = Command::new(cargo)
        .current_dir(workspace)
        .args(["metadata", "--format-version", "1", "--locked", "--filter-platform", &host()?])
        .output()
        .context("running cargo metadata")?;
    if !output.status.success() {
        bail!("cargo metadata failed: {}", String::from_utf8_lossy(&output.stderr));
    }
    let metadata: Metadata = serde_json::from_slice(&output.stdout).context("reading cargo metadata")?;
    let built: std::collections::HashSet<&str> = metadata.resolve.nodes.iter().map(|n| n.id.as_str()).collect();
    let mut needed = EDITION_2024;
    let mut needed_by = vec!["the 2024 edition".to_owned()];
    let mut stated = Vec::new();
    for package in metadata.packages.iter().filter(|p| built.contains(p.id.as_str())) {
        let version = package.rust_version.as_deref().and_then(parse_version);
        if package.source.is_none() {
            stated.push((package.name.clone(), version));
            continue;
        }
        let Some(version) = version else { continue };
        if version > needed {
            needed = version;
            needed_by.clear();
        }
        if version == needed {
            needed_by.push(format!("{} {}", package.name, package.version));
        }
    }
    Ok(Versions { needed, needed_by, stated })
}

fn workspace() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// The README's toolchain line.
fn readme_line(workspace: &Path) -> Result<String> {
    let path = workspace.join("README.md");
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let line = text.lines().find(|l| l.contains("You need a Rust toolchain")).context("no toolchain line in README")?;
    Ok(line.to_owned())
}

/// Every way the stated versions differ from the needed one, in words.
fn disagreements(versions: &Versions, readme: &str) -> Vec<String> {
    let (major, minor) = versions.needed;
    let mut found = Vec::new();
    for (name, stated) in &versions.stated {
        if *stated != Some(versions.needed) {
            found.push(format!("{name} states rust-version {stated:?}, Cargo.lock needs {major}.{minor}"));
        }
    }
    if !readme.contains(&format!("≥ {major}.{minor}")) {
        found.push(format!("the README's toolchain line does not say ≥ {major}.{minor}: {readme}"));
    }
    found
}

pub fn run(_: &Args) -> Result<()> {
    let versions = versions(workspace())?;
    let (major, minor) = versions.needed;
    println!("Cargo.lock needs Rust {major}.{minor}, for {}", versions.needed_by.join(", "));
    let problems = disagreements(&versions, &readme_line(workspace())?);
    if !problems.is_empty() {
        bail!("{}", problems.join("; "));
    }
    println!("Cargo.toml and the README state it");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stated_rust_version_is_the_one_the_locked_dependencies_need() {
        let versions = versions(workspace()).unwrap();
        assert!(versions.stated.len() >= 7, "{versions:?}");
        let problems = disagreements(&versions, &readme_line(workspace()).unwrap());
        assert!(problems.is_empty(), "{problems:?}");
    }

    #[test]
    fn a_dependency_newer_than_the_stated_version_is_a_disagreement() {
        let versions = Versions {
            needed: (1, 89),
            needed_by: vec!["nalgebra 0.35.0".into()],
            stated: vec![("calib".into(), Some((1, 85))), ("lie".into(), Some((1, 89)))],
        };
        let problems = disagreements(&versions, "You need a Rust toolchain (`rustup`, stable ≥ 1.85).");
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(problems[0].starts_with("calib states rust-version Some((1, 85))"), "{problems:?}");
    }
}
