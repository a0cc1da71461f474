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

    /// RON text of `file` that does not parse: the parser's message at its line and column.
    pub fn ron(file: impl Into<String>, e: &ron::error::SpannedError) -> Error {
        Error::at_line(
            file,
            e.span.start.line as u64,
            e.span.start.col,
            ErrorKind::RonFormat { message: e.code.to_string() },
        )
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

    /// The pose generator refused its input while drawing candidates (a `loadsim::Error`, say);
    /// the message is the generator's own.
    pub fn generator(source: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::new(ErrorKind::Generator { source: Box::new(source) })
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
    fn the_registration_and_report_kinds_keep_the_messages_of_their_former_enums() {
        // The texts `cell::Error` and `report::Error` wrote before they were folded in here.
        let error = Error::at_line("d.csv", 7, 3, ErrorKind::NewToolWithoutRefit { tool: "probe".into() });
        assert_eq!(
            error.to_string(),
            "d.csv:7:3: tool 'probe' is not in the model; re-fit tools to add it (--refit tools or --refit base,tools)"
        );
        let kind = ErrorKind::TooFewPoses {
            what: "the registration".into(),
            poses: 8,
            needed_poses: 9,
            rows: 24,
            parameters: 9,
        };
        assert_eq!(
            kind.to_string(),
            "too few poses for the registration: 8 poses (24 residual rows) for 9 re-fitted parameters; at least 9 poses are needed"
        );
        let kind = ErrorKind::PosesUndetermined { rank: 5, parameters: 6, condition: 1234.5 };
        assert_eq!(
            kind.to_string(),
            "the poses determine only 5 of the 6 re-fitted parameters (condition number 1.234e3): measure poses with more varied joint angles and flange orientations"
        );
        let kind = ErrorKind::RegistrationNotConverged { iterations: 50, rms_m: 0.000_123_4 };
        assert_eq!(kind.to_string(), "the registration did not converge in 50 iterations (RMS residual 0.1234 mm)");
        let kind = ErrorKind::OptionOutOfRange { field: "ridge", value: -1.0, expected: "a positive finite number" };
        assert_eq!(kind.to_string(), "option ridge = -1: expected a positive finite number");
        assert_eq!(
            ErrorKind::TooFewCandidates { candidates: 5, poses: 6 }.to_string(),
            "6 poses asked for but only 5 candidates given"
        );
        assert_eq!(
            ErrorKind::NoIdentifiableDirection { candidates: 4 }.to_string(),
            "the 4 candidates determine no direction of the identification"
        );
        let error = Error::generator(std::io::Error::other("joint 2 has no range"));
        assert_eq!(error.to_string(), "joint 2 has no range");
        let kind = ErrorKind::Plot { figure: "histogram".into(), message: "no room".into() };
        assert_eq!(kind.to_string(), "the chart \"histogram\" could not be drawn: no room");
        let source = serde_json::from_str::<f64>("x").unwrap_err();
        let expected = format!("the evaluation could not be written as JSON: {source}");
        assert_eq!(ErrorKind::EvaluationJson { source }.to_string(), expected);
    }

    #[test]
    fn the_error_is_one_pointer_wide() {
        assert_eq!(std::mem::size_of::<Error>(), std::mem::size_of::<usize>());
    }
}
