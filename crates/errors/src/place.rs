//! Where an error is: the file (or the command-line option whose argument is at fault), and the
//! line and column where they are known.

use std::fmt;

/// Where an [`Error`](crate::Error) is. Shown as `file:line:column`, or `file` alone for an error
/// about a whole file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Place {
    file: String,
    position: Option<(u64, usize)>,
}

impl Place {
    /// A 1-based line and column of a file. An argument of a command-line option (`--columns`,
    /// `--effects`) is a file of one line, named by the option.
    pub fn new(file: impl Into<String>, line: u64, column: usize) -> Place {
        Place { file: file.into(), position: Some((line, column)) }
    }

    /// A whole file (or a path), no line or column.
    pub fn in_file(file: impl Into<String>) -> Place {
        Place { file: file.into(), position: None }
    }

    /// The file, path or option.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The 1-based line, where known.
    pub fn line(&self) -> Option<u64> {
        self.position.map(|(line, _)| line)
    }

    /// The 1-based column, where known.
    pub fn column(&self) -> Option<usize> {
        self.position.map(|(_, column)| column)
    }

    /// The 1-based line and column, where known.
    pub fn position(&self) -> Option<(u64, usize)> {
        self.position
    }
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.position {
            Some((line, column)) => write!(f, "{}:{line}:{column}", self.file),
            None => f.write_str(&self.file),
        }
    }
}
