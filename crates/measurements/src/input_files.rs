//! The files a command reads, so that none of its outputs is written over one of them: a model
//! written over its own measurements, a URDF over the model it came from.
//!
//! Two paths are the same file when their canonical paths are equal (`./run.csv`, `a/../run.csv`,
//! a symbolic link) or, on Unix, when they have the same device and inode (a hard link).

use crate::ErrorKind;
use crate::output_file::output_target;
use errors::Error;
use std::path::{Path, PathBuf};

/// One input: the option that named it, the path as given, and what identifies the file.
#[derive(Debug, Clone)]
struct InputFile {
    option: &'static str,
    path: PathBuf,
    canonical: Option<PathBuf>,
    identity: Option<(u64, u64)>,
}

/// The input files of a command, each with the option that named it.
#[derive(Debug, Clone, Default)]
pub struct InputFiles {
    files: Vec<InputFile>,
}

/// The device and inode of the file at `path` (symbolic links followed), where the platform has
/// them and the file exists.
fn identity(path: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// The canonical path of `path`; for a file that does not exist yet, its folder's canonical path
/// joined with its name.
fn canonical(path: &Path) -> Option<PathBuf> {
    if let Ok(path) = std::fs::canonicalize(path) {
        return Some(path);
    }
    let name = path.file_name()?;
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    std::fs::canonicalize(folder).ok().map(|folder| folder.join(name))
}

impl InputFiles {
    /// No inputs.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the file `path`, named by `option` (e.g. `--data`). A file that does not exist is
    /// kept too (its reader refuses it later); it only matches an output of the same path.
    pub fn with(mut self, option: &'static str, path: &Path) -> Self {
        self.files.push(InputFile {
            option,
            path: path.to_path_buf(),
            canonical: canonical(path),
            identity: identity(path),
        });
        self
    }

    /// Adds `path` if there is one.
    pub fn with_optional(self, option: &'static str, path: Option<&Path>) -> Self {
        match path {
            Some(path) => self.with(option, path),
            None => self,
        }
    }

    /// Checks that writing `output` (named by `option`) would neither overwrite one of the inputs
    /// ([`ErrorKind::OutputIsInput`]) nor replace something that is not a regular file
    /// ([`crate::output_target`]'s refusals). Symbolic links at `output` are followed, as the
    /// writer follows them.
    pub fn check_output(&self, option: &'static str, output: &Path) -> Result<(), Error> {
        let target = output_target(output)?;
        let (canonical, identity) = (canonical(&target), identity(&target));
        let same = |input: &InputFile| {
            (identity.is_some() && identity == input.identity)
                || (canonical.is_some() && canonical == input.canonical)
                || input.path == output
        };
        match self.files.iter().find(|input| same(input)) {
            Some(input) => Err(Error::new(ErrorKind::OutputIsInput {
                output_option: option,
                output: output.display().to_string(),
                input_option: input.option,
                input: input.path.display().to_string(),
            })),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(inputs: &InputFiles, output: &Path) -> String {
        match inputs.check_output("--out", output) {
            Err(e) if matches!(e.kind::<ErrorKind>(), Some(ErrorKind::OutputIsInput { .. })) => e.to_string(),
            other => panic!("{} should be refused as an input, got {other:?}", output.display()),
        }
    }

    #[test]
    fn an_output_is_refused_under_every_spelling_of_an_input() {
        let dir = tempfile::tempdir().unwrap();
        let data = dir.path().join("run.csv");
        std::fs::write(&data, "x\n").unwrap();
        let inputs = InputFiles::new().with("--robot", &dir.path().join("robot.ron")).with("--data", &data);
        let message = refused(&inputs, &data);
        assert_eq!(
            message,
            format!(
                "--out {} is the same file as --data {}: refusing to overwrite an input",
                data.display(),
                data.display()
            )
        );
        refused(&inputs, &dir.path().join(".").join("run.csv"));
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        refused(&inputs, &dir.path().join("sub/../run.csv"));
        #[cfg(unix)]
        {
            let hard = dir.path().join("hard.csv");
            std::fs::hard_link(&data, &hard).unwrap();
            refused(&inputs, &hard);
            let link = dir.path().join("link.csv");
            std::os::unix::fs::symlink(&data, &link).unwrap();
            refused(&inputs, &link);
        }
        assert!(inputs.check_output("--out", &dir.path().join("model.ron")).is_ok());
    }

    #[test]
    fn an_input_that_does_not_exist_matches_only_its_own_path() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.csv");
        let inputs = InputFiles::new().with("--data", &missing);
        refused(&inputs, &missing);
        assert!(inputs.check_output("--out", &dir.path().join("other.csv")).is_ok());
    }
}
