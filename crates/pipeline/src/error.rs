//! The errors of the `pipeline` crate. Every error about a user's file names the file, and where
//! it can, the line and the column.

use std::fmt;

/// What can go wrong reading inputs, fitting or evaluating.
#[non_exhaustive]
#[derive(Debug)]
pub enum Error {
    /// A file could not be read or written.
    Io {
        /// The path.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A measurement file has no header or no data row.
    EmptyFile {
        /// The file.
        file: String,
    },
    /// The CSV layer refused a line (e.g. a row with a different number of fields).
    CsvSyntax {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
        /// 1-based column (field index) where known, else 1.
        column: usize,
        /// What the CSV reader said.
        message: String,
    },
    /// A required column is absent.
    MissingColumn {
        /// The file.
        file: String,
        /// The header line (1).
        line: u64,
        /// Where the header ends (its field count + 1): the column that should have been there.
        column: usize,
        /// The missing column's name.
        name: String,
    },
    /// A column name appears twice (or a quantity twice in two units).
    DuplicateColumn {
        /// The file.
        file: String,
        /// The header line (1).
        line: u64,
        /// 1-based column of the second occurrence.
        column: usize,
        /// The column's name.
        name: String,
    },
    /// A cell that must be a number is not one, or is NaN or infinite.
    NotANumber {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
        /// 1-based column.
        column: usize,
        /// The column's name.
        name: String,
        /// The cell's text.
        text: String,
    },
    /// The joint columns do not match the robot's joint count.
    JointCountMismatch {
        /// The file.
        file: String,
        /// The header line (1).
        line: u64,
        /// The column at fault: the first extra joint column, or where the missing one should be.
        column: usize,
        /// Joint columns found.
        found: usize,
        /// The robot's joint count.
        expected: usize,
    },
    /// A quaternion whose norm is off by more than 1e-3.
    QuaternionNorm {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
        /// 1-based column of `qw`.
        column: usize,
        /// The norm found.
        norm: f64,
    },
    /// A tool identifier the model was not fitted with.
    UnknownTool {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
        /// 1-based column of `tool`.
        column: usize,
        /// The identifier.
        tool: String,
        /// The identifiers the model knows.
        known: Vec<String>,
    },
    /// A RON file (robot or model) that does not parse, or holds an invalid value.
    RonFormat {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A model file written by another schema version.
    SchemaVersion {
        /// The file.
        file: String,
        /// The version found.
        found: u32,
        /// The version this build reads.
        supported: u32,
    },
    /// The kinematic model or its identification failed.
    Kinematics {
        /// The underlying error.
        source: poe::Error,
    },
    /// The load and effect models refused their input.
    Load {
        /// The underlying error.
        source: loadsim::Error,
    },
    /// The Gaussian process failed.
    Gp {
        /// The underlying error.
        source: gp::Error,
    },
    /// Too few rows for what was asked.
    TooFewRows {
        /// The file.
        file: String,
        /// Rows available.
        rows: usize,
        /// Rows needed.
        needed: usize,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { path, source } => write!(f, "{path}: {source}"),
            Error::EmptyFile { file } => write!(f, "{file}:1:1: the file has no header or no data row"),
            Error::CsvSyntax { file, line, column, message } => write!(f, "{file}:{line}:{column}: {message}"),
            Error::MissingColumn { file, line, column, name } => {
                write!(f, "{file}:{line}:{column}: missing required column '{name}'")
            }
            Error::DuplicateColumn { file, line, column, name } => {
                write!(f, "{file}:{line}:{column}: column '{name}' appears more than once")
            }
            Error::NotANumber { file, line, column, name, text } => {
                write!(f, "{file}:{line}:{column}: column '{name}': '{text}' is not a finite number")
            }
            Error::JointCountMismatch { file, line, column, found, expected } => {
                write!(f, "{file}:{line}:{column}: {found} joint columns, the robot has {expected} joints")
            }
            Error::QuaternionNorm { file, line, column, norm } => write!(
                f,
                "{file}:{line}:{column}: quaternion (qw, qx, qy, qz) has norm {norm:.6}, expected 1 within 1e-3"
            ),
            Error::UnknownTool { file, line, column, tool, known } => write!(
                f,
                "{file}:{line}:{column}: tool '{tool}' is not in the model (it knows {})",
                if known.is_empty() { "none".to_owned() } else { known.join(", ") }
            ),
            Error::RonFormat { file, line, column, message } => write!(f, "{file}:{line}:{column}: {message}"),
            Error::SchemaVersion { file, found, supported } => {
                write!(f, "{file}:1:1: model file has schema version {found}, this calib reads version {supported}")
            }
            Error::Kinematics { source } => write!(f, "{source}"),
            Error::Load { source } => write!(f, "load model: {source}"),
            Error::Gp { source } => write!(f, "Gaussian process: {source}"),
            Error::TooFewRows { file, rows, needed } => {
                write!(f, "{file}: {rows} measurement rows, at least {needed} needed")
            }
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            Error::Kinematics { source } => Some(source),
            Error::Load { source } => Some(source),
            Error::Gp { source } => Some(source),
            _ => None,
        }
    }
}

impl From<poe::Error> for Error {
    fn from(source: poe::Error) -> Self {
        Error::Kinematics { source }
    }
}

impl From<loadsim::Error> for Error {
    fn from(source: loadsim::Error) -> Self {
        Error::Load { source }
    }
}

impl From<gp::Error> for Error {
    fn from(source: gp::Error) -> Self {
        Error::Gp { source }
    }
}
