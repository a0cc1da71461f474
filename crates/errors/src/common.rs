//! The kinds of fault more than one crate raises: a file that cannot be read, RON text that does
//! not parse or holds a value no robot cell has, and the errors of the crates below the readers
//! (`poe`, `loadsim`, `gp`), carried boxed with their message and `source()` chain.

use std::fmt;

/// What goes wrong in more than one crate: the kind of an [`Error`](crate::Error) made by its own
/// constructors ([`Error::io`](crate::Error::io), [`Error::ron`](crate::Error::ron),
/// [`Error::kinematics`](crate::Error::kinematics) …) and by the checks of the robot and model files.
#[non_exhaustive]
#[derive(Debug)]
pub enum CommonKind {
    /// A file could not be read or written.
    Io {
        /// The operating system's error.
        source: std::io::Error,
    },
    /// Bytes that are not UTF-8 text.
    ///
    /// At the first such byte: its field, in a CSV file; its character, in a RON file.
    InvalidUtf8,
    /// A value in a RON file (robot or model) that must be a finite number and is not.
    NotFinite {
        /// The field, e.g. `flange.position` or `links[2].com_m`.
        field: String,
        /// The value found.
        value: f64,
    },
    /// A model file whose parts do not fit together: a count that differs from what another
    /// part needs (an edited or corrupt file).
    ModelCount {
        /// The field, e.g. `compensation.gp`.
        field: String,
        /// What is counted, e.g. `inputs`.
        what: &'static str,
        /// The count found.
        found: usize,
        /// The count the rest of the model needs.
        expected: usize,
    },
    /// A model file with an index out of its range.
    ModelIndex {
        /// The field, e.g. `joint_compliance.terms[3].joint`.
        field: String,
        /// The index found.
        index: usize,
        /// The index must be below this.
        limit: usize,
    },
    /// A robot or model file with a finite value far outside any robot cell (an edited or corrupt
    /// file): left in, its products overflow and the model predicts NaN poses.
    ModelValue {
        /// The field, e.g. `kinematics.joints[1]`.
        field: String,
        /// The value found.
        value: f64,
        /// Its magnitude must not exceed this.
        limit: f64,
    },
    /// A RON file (robot or model) that does not parse, or holds an invalid value.
    RonFormat {
        /// What is wrong.
        message: String,
    },
    /// The kinematic model or its identification failed.
    Kinematics {
        /// The underlying error (a `poe::Error`, `loadsim::Error` or `gp::Error`, boxed: this crate
        /// knows none of them), its message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// The load and effect models refused their input.
    Load {
        /// The underlying error (a `poe::Error`, `loadsim::Error` or `gp::Error`, boxed: this crate
        /// knows none of them), its message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// The Gaussian process failed.
    Gp {
        /// The underlying error (a `poe::Error`, `loadsim::Error` or `gp::Error`, boxed: this crate
        /// knows none of them), its message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// The pose generator refused its input while drawing planning candidates (`calib plan
    /// --generate`); the message is the generator's own.
    Generator {
        /// The underlying error (a `loadsim::Error`, boxed: this crate knows none of them), its
        /// message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
}

impl fmt::Display for CommonKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CommonKind::Io { source } => write!(f, "{source}"),
            CommonKind::InvalidUtf8 => write!(f, "the text is not UTF-8"),
            CommonKind::NotFinite { field, value } => {
                write!(f, "{field} is {value}, a finite number is needed")
            }
            CommonKind::ModelCount { field, what, found, expected } => {
                write!(f, "{field} has {found} {what}, the rest of the model needs {expected}")
            }
            CommonKind::ModelIndex { field, index, limit } => {
                write!(f, "{field} is {index}, it must be below {limit}")
            }
            CommonKind::ModelValue { field, value, limit } => write!(
                f,
                "{field} is {value:e}, beyond ±{limit:e}: larger than any robot cell (an edited or corrupt file)"
            ),
            CommonKind::RonFormat { message } => write!(f, "{message}"),
            CommonKind::Kinematics { source } => write!(f, "{source}"),
            CommonKind::Load { source } => write!(f, "load model: {source}"),
            CommonKind::Gp { source } => write!(f, "Gaussian process: {source}"),
            CommonKind::Generator { source } => write!(f, "{source}"),
        }
    }
}

impl std::error::Error for CommonKind {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CommonKind::Io { source, .. } => Some(source),
            CommonKind::Kinematics { source, .. } => Some(source.as_ref()),
            CommonKind::Load { source, .. } => Some(source.as_ref()),
            CommonKind::Gp { source, .. } => Some(source.as_ref()),
            CommonKind::Generator { source, .. } => Some(source.as_ref()),
            _ => None,
        }
    }
}
