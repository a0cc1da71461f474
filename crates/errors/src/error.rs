//! The error of the calibration crates: a [`Place`] (where, if anywhere) and a [`Kind`] (what),
//! kept apart as ripgrep's globset keeps a glob apart from its error's kind. The kind is the
//! raising crate's own enum, so that a new refusal is written (and rebuilds) where it is raised.

use crate::{CommonKind, Place};
use std::fmt;

/// What went wrong, without where: each crate's `ErrorKind` enum (and this crate's [`CommonKind`]
/// and [`OptionOutOfRange`](crate::OptionOutOfRange)). Its `Display` is the message after the
/// place, its `source()` the error it wraps, if any.
pub trait Kind: std::error::Error + Send + Sync + 'static {}

// Here rather than beside `CommonKind`, so that the modules do not import each other.
impl Kind for CommonKind {}

/// What went wrong ([`kind`](Error::kind)) and where ([`place`](Error::place)): its message is the
/// place's `file:line:column: ` (or `file: `) followed by the kind's.
///
/// Boxed, so that a `Result` carrying it stays one pointer wide.
#[derive(Debug)]
pub struct Error(Box<Inner>);

#[derive(Debug)]
struct Inner {
    place: Option<Place>,
    kind: Box<dyn Kind>,
}

impl Error {
    /// An error without a place (about an argument, a fit, a simulation).
    pub fn new(kind: impl Kind) -> Error {
        Error(Box::new(Inner { place: None, kind: Box::new(kind) }))
    }

    /// An error at a place.
    pub fn at(place: Place, kind: impl Kind) -> Error {
        Error(Box::new(Inner { place: Some(place), kind: Box::new(kind) }))
    }

    /// An error about a whole file (or a path): its message starts with `file: `.
    pub fn in_file(file: impl Into<String>, kind: impl Kind) -> Error {
        Error::at(Place::in_file(file), kind)
    }

    /// An error at a line and column of a file: its message starts with `file:line:column: `.
    pub fn at_line(file: impl Into<String>, line: u64, column: usize, kind: impl Kind) -> Error {
        Error::at(Place::new(file, line, column), kind)
    }

    /// RON text of `file` that does not parse: the parser's message at its line and column.
    pub fn ron(file: impl Into<String>, e: &ron::error::SpannedError) -> Error {
        Error::at_line(
            file,
            e.span.start.line as u64,
            e.span.start.col,
            CommonKind::RonFormat { message: e.code.to_string() },
        )
    }

    /// A file that could not be read or written.
    pub fn io(path: impl Into<String>, source: std::io::Error) -> Error {
        Error::in_file(path, CommonKind::Io { source })
    }

    /// The kinematic model or its identification failed (a `poe::Error`, say).
    pub fn kinematics(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(CommonKind::Kinematics { source: Box::new(source) })
    }

    /// The load and effect models refused their input (a `loadsim::Error`, say).
    pub fn load(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(CommonKind::Load { source: Box::new(source) })
    }

    /// The pose generator refused its input while drawing candidates (a `loadsim::Error`, say);
    /// the message is the generator's own.
    pub fn generator(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(CommonKind::Generator { source: Box::new(source) })
    }

    /// The Gaussian process failed (a `gp::Error`, say).
    pub fn gp(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(CommonKind::Gp { source: Box::new(source) })
    }

    /// Where the error is: a file (or a command-line option's argument), and a line and column
    /// where known; `None` for an error about no file.
    pub fn place(&self) -> Option<&Place> {
        self.0.place.as_ref()
    }

    /// What went wrong, as the kind `K` (a crate's `ErrorKind`, [`CommonKind`]), or `None`
    /// where the kind is another crate's: `error.kind::<measurements::ErrorKind>()`.
    pub fn kind<K: Kind>(&self) -> Option<&K> {
        let kind: &(dyn std::error::Error + 'static) = &*self.0.kind;
        kind.downcast_ref::<K>()
    }

    /// What went wrong, whatever crate's kind it is: its `Display` is the message without the place.
    pub fn dyn_kind(&self) -> &dyn Kind {
        &*self.0.kind
    }

    /// The 1-based line and column of the place, where it has them.
    pub fn position(&self) -> Option<(u64, usize)> {
        self.place().and_then(Place::position)
    }
}

impl<K: Kind> From<K> for Error {
    fn from(kind: K) -> Self {
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
    use super::{Error, Kind};
    use crate::{CommonKind, OptionOutOfRange, Place};
    use std::fmt;

    /// A crate's own kind, as the crates above this one define theirs.
    #[derive(Debug)]
    enum ReadKind {
        MissingColumn { name: String },
    }

    impl fmt::Display for ReadKind {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            match self {
                ReadKind::MissingColumn { name } => write!(f, "missing required column '{name}'"),
            }
        }
    }

    impl std::error::Error for ReadKind {}
    impl Kind for ReadKind {}

    #[test]
    fn a_message_is_the_place_then_the_kind() {
        let kind = || ReadKind::MissingColumn { name: "y_mm".into() };
        let error = Error::at_line("poses.csv", 1, 5, kind());
        assert_eq!(error.to_string(), "poses.csv:1:5: missing required column 'y_mm'");
        assert_eq!(error.position(), Some((1, 5)));
        assert_eq!(error.place().map(Place::file), Some("poses.csv"));
        let error = Error::in_file("poses.csv", CommonKind::NotFinite { field: "x".into(), value: f64::NAN });
        assert_eq!(error.to_string(), "poses.csv: x is NaN, a finite number is needed");
        assert_eq!(error.position(), None);
        let error = Error::new(OptionOutOfRange::new("ridge", -1.0, "a positive finite number"));
        assert_eq!(error.to_string(), "option ridge = -1: expected a positive finite number");
        assert!(error.place().is_none());
    }

    #[test]
    fn a_kind_is_found_by_its_type_and_only_by_it() {
        let error = Error::at_line("poses.csv", 1, 5, ReadKind::MissingColumn { name: "y_mm".into() });
        assert!(matches!(error.kind::<ReadKind>(), Some(ReadKind::MissingColumn { name }) if name == "y_mm"));
        assert!(error.kind::<CommonKind>().is_none());
        let error: Error = CommonKind::RonFormat { message: "expected ')'".into() }.into();
        assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::RonFormat { .. })));
        assert!(error.kind::<ReadKind>().is_none());
    }

    #[test]
    fn a_lower_crates_error_keeps_its_message_and_chain() {
        let error = Error::gp(std::io::Error::other("not positive definite"));
        assert_eq!(error.to_string(), "Gaussian process: not positive definite");
        let source = std::error::Error::source(&error).map(ToString::to_string);
        assert_eq!(source.as_deref(), Some("not positive definite"));
        assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::Gp { .. })));
        let error = Error::generator(std::io::Error::other("joint 2 has no range"));
        assert_eq!(error.to_string(), "joint 2 has no range");
        let error = Error::load(std::io::Error::other("no mass"));
        assert_eq!(error.to_string(), "load model: no mass");
    }

    #[test]
    fn the_error_is_one_pointer_wide() {
        assert_eq!(std::mem::size_of::<Error>(), std::mem::size_of::<usize>());
    }
}
