//! The error of the calibration crates: a [`Place`] (where, if anywhere) and an [`ErrorKind`]
//! (what), kept apart as ripgrep's globset keeps a glob apart from its error's kind.

use crate::{ErrorKind, Place};
use std::fmt;

/// What went wrong ([`kind`](Error::kind)) and where ([`place`](Error::place)): its message is the
/// place's `file:line:column: ` (or `file: `) followed by the kind's.
///
/// Boxed, so that a `Result` carrying it stays one pointer wide.
#[derive(Debug)]
pub struct Error(Box<Inner>);

#[derive(Debug)]
struct Inner {
    place: Option<Place>,
    kind: ErrorKind,
}

impl Error {
    /// An error without a place (about an argument, a fit, a simulation).
    pub fn new(kind: ErrorKind) -> Error {
        Error(Box::new(Inner { place: None, kind }))
    }

    /// An error at a place.
    pub fn at(place: Place, kind: ErrorKind) -> Error {
        Error(Box::new(Inner { place: Some(place), kind }))
    }

    /// An error about a whole file (or a path): its message starts with `file: `.
    pub fn in_file(file: impl Into<String>, kind: ErrorKind) -> Error {
        Error::at(Place::in_file(file), kind)
    }

    /// An error at a line and column of a file: its message starts with `file:line:column: `.
    pub fn at_line(file: impl Into<String>, line: u64, column: usize, kind: ErrorKind) -> Error {
        Error::at(Place::new(file, line, column), kind)
    }

    /// A file that could not be read or written.
    pub fn io(path: impl Into<String>, source: std::io::Error) -> Error {
        Error::in_file(path, ErrorKind::Io { source })
    }

    /// The kinematic model or its identification failed (a `poe::Error`, say).
    pub fn kinematics(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(ErrorKind::Kinematics { source: Box::new(source) })
    }

    /// The load and effect models refused their input (a `loadsim::Error`, say).
    pub fn load(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(ErrorKind::Load { source: Box::new(source) })
    }

    /// The Gaussian process failed (a `gp::Error`, say).
    pub fn gp(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(ErrorKind::Gp { source: Box::new(source) })
    }

    /// Where the error is: a file (or a command-line option's argument), and a line and column
    /// where known; `None` for an error about no file.
    pub fn place(&self) -> Option<&Place> {
        self.0.place.as_ref()
    }

    /// What went wrong.
    pub fn kind(&self) -> &ErrorKind {
        &self.0.kind
    }

    /// The kind, the place dropped.
    pub fn into_kind(self) -> ErrorKind {
        self.0.kind
    }

    /// The 1-based line and column of the place, where it has them.
    pub fn position(&self) -> Option<(u64, usize)> {
        self.place().and_then(Place::position)
    }
}

impl From<ErrorKind> for Error {
    fn from(kind: ErrorKind) -> Self {
        Error::new(kind)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(place) = &self.0.place {
            write!(f, "{place}: ")?;
        }
        write!(f, "{}", self.0.kind)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.kind.source()
    }
}

#[cfg(test)]
mod tests {
    use super::Error;
    use crate::{ErrorKind, Place};

    #[test]
    fn a_message_is_the_place_then_the_kind() {
        let kind = || ErrorKind::MissingColumn { name: "y_mm".into() };
        let error = Error::at_line("poses.csv", 1, 5, kind());
        assert_eq!(error.to_string(), "poses.csv:1:5: missing required column 'y_mm'");
        assert_eq!(error.position(), Some((1, 5)));
        assert_eq!(error.place().map(Place::file), Some("poses.csv"));
        let error = Error::in_file("poses.csv", ErrorKind::TooFewRows { rows: 3, needed: 50 });
        assert_eq!(error.to_string(), "poses.csv: 3 measurement rows, at least 50 needed");
        assert_eq!(error.position(), None);
        let error = Error::new(ErrorKind::PartOrder { part: "effect" });
        assert_eq!(error.to_string(), "a model's effect comes before its geometry");
        assert!(error.place().is_none());
    }

    #[test]
    fn a_lower_crates_error_keeps_its_message_and_chain() {
        let error = Error::gp(std::io::Error::other("not positive definite"));
        assert_eq!(error.to_string(), "Gaussian process: not positive definite");
        let source = std::error::Error::source(&error).map(ToString::to_string);
        assert_eq!(source.as_deref(), Some("not positive definite"));
        assert!(matches!(error.kind(), ErrorKind::Gp { .. }));
    }

    #[test]
    fn the_error_is_one_pointer_wide() {
        assert_eq!(std::mem::size_of::<Error>(), std::mem::size_of::<usize>());
    }
}
