//! `cargo xtask deps`: the workspace's crate graph with the lines of each crate, and the structure
//! it keeps true: no crate above a line budget, no circle between crates, and no module of a crate
//! (or of xtask) that imports a module importing it back; in xtask, no check that imports an
//! experiment or the reverse. And the crates CI builds alone share the tests' build
//! (`deps_features`), so that CI compiles the workspace once.
//!
//! A module's imports are its `crate::…` and `super::…` paths outside `#[cfg(test)]` blocks and
//! comments, resolved to the longest module prefix; a name the crate root re-exports
//! (`pub use module::{Name}`) resolves to the module that defines it, so a circle through the
//! root's re-exports is found too.

use anyhow::{Context, Result, bail};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Print the crate graph with lines per crate; fail on a module or crate circle or an oversized crate.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The most lines of Rust a crate's `src/` may hold. 5,000: a crate a newcomer can read
    /// whole, and the size above which one crate had come to hold several concerns.
    #[arg(long, default_value_t = 5000)]
    max_lines: usize,
}

/// One crate of the workspace (or xtask).
struct Crate {
    name: String,
    src: PathBuf,
    /// Workspace crates it depends on (normal dependencies).
    depends_on: BTreeSet<String>,
    lines: usize,
}

pub fn run(args: &Args) -> Result<()> {
    let root = crate::workspace_root();
    let crates = workspace_crates(&root)?;
    let names: BTreeSet<String> = crates.iter().map(|c| c.name.clone()).collect();
    let mut failures = Vec::new();

    println!("| crate | lines | depends on (workspace) |");
    println!("| --- | ---: | --- |");
    for c in &crates {
        let deps: Vec<&str> = c.depends_on.iter().filter(|d| names.contains(*d)).map(String::as_str).collect();
        println!("| `{}` | {} | {} |", c.name, c.lines, deps.join(", "));
        if c.name != "xtask" && c.lines > args.max_lines {
            failures.push(format!("crate {} has {} lines (at most {})", c.name, c.lines, args.max_lines));
        }
    }

    let graph: BTreeMap<String, BTreeSet<String>> = crates
        .iter()
        .map(|c| (c.name.clone(), c.depends_on.iter().filter(|d| names.contains(*d)).cloned().collect()))
        .collect();
    for circle in circles(&graph) {
        failures.push(format!("crates import each other: {}", circle.join(" <-> ")));
    }
    for c in &crates {
        let modules = read_modules(&c.src)?;
        let graph = module_graph(&modules);
        for circle in circles(&graph) {
            failures.push(format!("{}: modules import each other: {}", c.name, circle.join(" <-> ")));
        }
        if c.name == "xtask" {
            for (from, to) in across(&graph, SEPARATE_HALVES) {
                failures.push(format!("xtask: {from} imports {to} (checks and experiments share only the crate root)"));
            }
        }
    }
    failures.extend(super::deps_features::drift(&root)?);
    if failures.is_empty() {
        println!("\nno crate above {} lines; no circle between crates or between the modules of one", args.max_lines);
        println!(
            "xtask, calib-python and calib resolve every dependency with the features of `cargo test --workspace`"
        );
        return Ok(());
    }
    for failure in &failures {
        eprintln!("{failure}");
    }
    bail!("{} problem(s) in the crate structure", failures.len())
}

/// Every member under `crates/`, and xtask, with its workspace dependencies and lines.
fn workspace_crates(root: &Path) -> Result<Vec<Crate>> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .context("reading crates/")?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("Cargo.toml").is_file())
        .collect();
    dirs.sort();
    dirs.push(root.join("xtask"));
    dirs.iter()
        .map(|dir| {
            let manifest = std::fs::read_to_string(dir.join("Cargo.toml"))
                .with_context(|| format!("reading {}", dir.join("Cargo.toml").display()))?;
            let name = package_name(&manifest)
                .map(str::to_owned)
                .with_context(|| format!("{}: no package name", dir.display()))?;
            // The `[dependencies]` section only: dev-dependencies may point anywhere.
            let section = manifest.split("\n[").find(|s| s.starts_with("dependencies]")).unwrap_or("");
            let depends_on = dependencies(section).into_iter().map(str::to_owned).collect();
            let src = dir.join("src");
            let lines = rust_files(&src)?
                .iter()
                .map(|f| std::fs::read_to_string(f).map(|t| t.lines().count()))
                .sum::<std::io::Result<usize>>()?;
            Ok(Crate { name, src, depends_on, lines })
        })
        .collect()
}

fn rust_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).with_context(|| format!("reading {}", d.display()))? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

/// Each module's path (`identify::solver`; the crate root is `""`) and its code without tests
/// and comments.
fn read_modules(src: &Path) -> Result<BTreeMap<String, String>> {
    rust_files(src)?
        .into_iter()
        .map(|file| {
            let relative = file.strip_prefix(src)?.with_extension("");
            let mut parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
            if parts.last().is_some_and(|p| p == "mod" || p == "lib" || p == "main") {
                parts.pop();
            }
            let text = std::fs::read_to_string(&file)?;
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            Ok((parts.join("::"), without_comments(code)))
        })
        .collect()
}

/// Whether `c` is a word character (the `\w` of a path segment).
fn is_word(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The longest path `word(::word)*` at the start of `text` (empty if `text` starts with no word).
fn path_at(text: &str) -> &str {
    let mut end = 0;
    loop {
        let segment = text[end..].find(|c: char| !is_word(c)).unwrap_or(text.len() - end);
        if segment == 0 {
            // `a::` followed by no word: the path ends before the `::`.
            return &text[..end.saturating_sub(2)];
        }
        end += segment;
        if !text[end..].starts_with("::") {
            return &text[..end];
        }
        end += 2;
    }
}

/// Every path `word(::word)*` in `text`, left to right, none overlapping.
fn paths(text: &str) -> Vec<&str> {
    let mut found = Vec::new();
    let mut at = 0;
    while let Some(i) = text[at..].find(is_word) {
        let path = path_at(&text[at + i..]);
        found.push(path);
        at += i + path.len();
    }
    found
}

/// The path after each `prefix` (`crate::`) in `code` that starts with a word.
fn paths_after<'a>(code: &'a str, prefix: &str) -> Vec<&'a str> {
    code.match_indices(prefix).map(|(i, _)| path_at(&code[i + prefix.len()..])).filter(|p| !p.is_empty()).collect()
}

/// The inside of each `{…}` after `prefix` (`use crate::{`) that closes with `};` before any other `;`.
fn groups_after<'a>(code: &'a str, prefix: &str) -> Vec<&'a str> {
    code.match_indices(prefix)
        .filter_map(|(i, _)| {
            let inside = &code[i + prefix.len()..];
            let end = inside.find(';')?;
            inside[..end].strip_suffix('}')
        })
        .collect()
}

/// The root's `pub use module::{A, B};` and `pub use module::A;` (also `pub(crate)`): each module
/// with the text after its `::`.
fn re_exports(code: &str) -> Vec<(&str, &str)> {
    let mut found: Vec<(usize, &str, &str)> = Vec::new();
    for prefix in ["pub use ", "pub(crate) use "] {
        for (i, _) in code.match_indices(prefix) {
            let rest = &code[i + prefix.len()..];
            let module_end = rest.find(|c: char| !is_word(c)).unwrap_or(rest.len());
            let (module, rest) = rest.split_at(module_end);
            let Some(rest) = rest.strip_prefix("::").filter(|_| !module.is_empty()) else { continue };
            let Some(end) = rest.find(';') else { continue };
            let item = &rest[..end];
            let single = !item.is_empty() && item.chars().all(is_word);
            if single || (item.starts_with('{') && item.ends_with('}')) {
                found.push((i, module, item));
            }
        }
    }
    // In the order they are written: a name exported twice resolves to the later module.
    found.sort_by_key(|(i, _, _)| *i);
    found.into_iter().map(|(_, module, item)| (module, item)).collect()
}

/// `code` without its `//` comments (to the end of each line).
fn without_comments(code: &str) -> String {
    code.split('\n').map(|line| line.find("//").map_or(line, |i| &line[..i])).collect::<Vec<_>>().join("\n")
}

/// The value of the first line `name = "…"` of a manifest.
fn package_name(manifest: &str) -> Option<&str> {
    manifest.lines().find_map(|line| {
        let rest = line.strip_prefix("name")?.trim_start().strip_prefix('=')?.trim_start().strip_prefix('"')?;
        let name = &rest[..rest.find('"')?];
        (!name.is_empty()).then_some(name)
    })
}

/// The dependencies a `[dependencies]` section names: each line's leading `name` followed by
/// `.workspace = true` or `=`.
fn dependencies(section: &str) -> Vec<&str> {
    section
        .lines()
        .filter_map(|line| {
            let end = line.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-')).unwrap_or(line.len());
            let (name, rest) = line.split_at(end);
            let workspace = rest
                .strip_prefix(".workspace")
                .and_then(|r| r.trim_start().strip_prefix('='))
                .is_some_and(|r| r.trim_start().starts_with("true"));
            (!name.is_empty() && (workspace || rest.trim_start().starts_with('='))).then_some(name)
        })
        .collect()
}

/// xtask's two halves: a check must not change because an experiment did, nor an experiment
/// because a check did; what both need sits at the crate root.
const SEPARATE_HALVES: [&str; 2] = ["checks", "experiments"];

/// Each import from a module under one of `halves` to a module under another, as (from, to).
fn across(graph: &BTreeMap<String, BTreeSet<String>>, halves: [&str; 2]) -> Vec<(String, String)> {
    let half = |module: &str| halves.iter().position(|h| module == *h || module.starts_with(&format!("{h}::")));
    graph
        .iter()
        .flat_map(|(from, targets)| targets.iter().map(move |to| (from, to)))
        .filter(|(from, to)| matches!((half(from), half(to)), (Some(a), Some(b)) if a != b))
        .map(|(from, to)| (from.clone(), to.clone()))
        .collect()
}

/// Which module imports which.
fn module_graph(modules: &BTreeMap<String, String>) -> BTreeMap<String, BTreeSet<String>> {
    // Names the crate root re-exports, and the module each comes from.
    let mut exported: BTreeMap<String, String> = BTreeMap::new();
    if let Some(root) = modules.get("") {
        for (module, items) in re_exports(root) {
            if modules.contains_key(module) {
                for name in items.split(|c: char| !is_word(c)).filter(|w| !w.is_empty()) {
                    exported.insert(name.to_owned(), module.to_owned());
                }
            }
        }
    }
    let mut graph = BTreeMap::new();
    for (module, code) in modules {
        let parent = module.rsplit_once("::").map_or("", |(p, _)| p);
        let from_super = |p: &str| if parent.is_empty() { p.to_owned() } else { format!("{parent}::{p}") };
        let mut paths: Vec<String> = paths_after(code, "crate::").into_iter().map(str::to_owned).collect();
        for group in groups_after(code, "use crate::{") {
            paths.extend(self::paths(group).into_iter().map(str::to_owned));
        }
        if !module.is_empty() {
            paths.extend(paths_after(code, "super::").into_iter().map(from_super));
            for group in groups_after(code, "use super::{") {
                paths.extend(self::paths(group).into_iter().map(from_super));
            }
        }
        let mut targets = BTreeSet::new();
        for p in paths {
            let segments: Vec<&str> = p.split("::").collect();
            let found = (1..=segments.len())
                .rev()
                .map(|k| segments[..k].join("::"))
                .find(|candidate| modules.contains_key(candidate))
                .or_else(|| exported.get(segments[0]).cloned());
            if let Some(target) = found
                && !target.is_empty()
                && target != *module
                && !module.starts_with(&format!("{target}::"))
            {
                targets.insert(target);
            }
        }
        graph.insert(module.clone(), targets);
    }
    graph
}

/// The strongly connected components of more than one node (Tarjan), each sorted.
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        next: usize,
        found: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        s.index.insert(v, s.next);
        s.low.insert(v, s.next);
        s.next += 1;
        s.stack.push(v);
        s.on_stack.insert(v);
        let graph = s.graph;
        for w in graph.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !s.index.contains_key(w) {
                visit(s, w);
                let low = s.low[v].min(s.low[w]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.low[v].min(s.index[w]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.to_owned());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.found.push(component);
            }
        }
    }
    let mut state = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        found: Vec::new(),
    };
    for v in graph.keys() {
        if !state.index.contains_key(v.as_str()) {
            visit(&mut state, v);
        }
    }
    state.found
}

#[cfg(test)]
mod tests {
    use super::*;

    fn modules(items: &[(&str, &str)]) -> BTreeMap<String, String> {
        items.iter().map(|(m, code)| ((*m).to_owned(), (*code).to_owned())).collect()
    }

    #[test]
    fn a_circle_through_the_roots_re_exports_is_found() {
        let m = modules(&[
            ("", "mod a; mod b; pub use a::Alpha; pub use b::{Beta};"),
            ("a", "use crate::Beta; pub struct Alpha;"),
            ("b", "use crate::a::Alpha; pub struct Beta;"),
        ]);
        assert_eq!(circles(&module_graph(&m)), vec![vec!["a".to_owned(), "b".to_owned()]]);
    }

    #[test]
    fn a_chain_and_a_child_using_its_parent_are_not_circles() {
        let m = modules(&[
            ("", "mod a; mod b; pub use a::Alpha;"),
            ("a", "pub struct Alpha;"),
            ("b", "use crate::Alpha; mod c;"),
            ("b::c", "use super::Something;"),
        ]);
        assert!(circles(&module_graph(&m)).is_empty());
    }

    #[test]
    fn super_paths_resolve_against_the_parent() {
        let m = modules(&[
            ("", "mod p;"),
            ("p", "mod x; mod y;"),
            ("p::x", "use super::y::Y;"),
            ("p::y", "use super::x::X;"),
        ]);
        assert_eq!(circles(&module_graph(&m)), vec![vec!["p::x".to_owned(), "p::y".to_owned()]]);
    }

    #[test]
    fn a_check_importing_an_experiment_is_found_and_the_shared_root_modules_are_not() {
        let m = modules(&[
            ("", "mod checks; mod experiments; mod simulation;"),
            ("simulation", "pub fn cell() {}"),
            ("checks", "pub mod a;"),
            ("checks::a", "use crate::simulation::cell; use crate::experiments::b::run;"),
            ("experiments", "pub mod b;"),
            ("experiments::b", "use crate::simulation::cell; pub fn run() {}"),
        ]);
        let graph = module_graph(&m);
        assert!(circles(&graph).is_empty());
        assert_eq!(across(&graph, SEPARATE_HALVES), [("checks::a".to_owned(), "experiments::b".to_owned())]);
    }
}

#[cfg(test)]
mod scanner_tests {
    use super::*;

    #[test]
    fn paths_end_before_a_trailing_separator_and_groups_close_at_the_first_semicolon() {
        assert_eq!(path_at("a::b::{c, d}"), "a::b");
        assert_eq!(path_at("a::b;"), "a::b");
        assert_eq!(path_at("{a}"), "");
        assert_eq!(paths("x::y, z::{w}"), ["x::y", "z", "w"]);
        assert_eq!(paths_after("use crate::m::f; crate::{", "crate::"), ["m::f"]);
        assert_eq!(groups_after("use crate::{a, b::c}; use crate::{d; }", "use crate::{"), ["a, b::c"]);
        assert_eq!(
            re_exports("pub use m::{A, B};\npub(crate) use n::C;\npub use o::{D; pub use p::*;"),
            [("m", "{A, B}"), ("n", "C")]
        );
        assert_eq!(without_comments("a // b\nc\n// d"), "a \nc\n");
    }

    #[test]
    fn manifests_give_their_name_and_workspace_dependencies() {
        let manifest = "[package]\nname = \"poe\"\n[dependencies]\nlie.workspace = true\nfaer = { workspace = true }\n# x = 1\nrayon.workspace = false\n";
        assert_eq!(package_name(manifest), Some("poe"));
        assert_eq!(package_name("[package]\nname = \"\"\n"), None);
        let section = manifest.split("\n[").find(|s| s.starts_with("dependencies]")).unwrap();
        assert_eq!(dependencies(section), ["lie", "faer"]);
    }
}
