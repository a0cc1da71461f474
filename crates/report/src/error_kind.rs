//! The refusals of the calibration report: the kinds of [`errors::Error`] this crate raises, with
//! their messages.

use std::fmt;

/// What writing the calibration report fails on.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A chart of the calibration report could not be drawn.
    Plot {
        /// The chart.
        figure: String,
        /// What `plotters` said.
        message: String,
    },
    /// The evaluation embedded in the calibration report could not be written as JSON.
    EvaluationJson {
        /// The underlying error.
        source: serde_json::Error,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::Plot { figure, message } => write!(f, "the chart {figure:?} could not be drawn: {message}"),
            ErrorKind::EvaluationJson { source } => {
                write!(f, "the evaluation could not be written as JSON: {source}")
            }
        }
    }
}

impl std::error::Error for ErrorKind {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ErrorKind::EvaluationJson { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl errors::Kind for ErrorKind {}

#[cfg(test)]
mod tests {
    use super::ErrorKind;

    #[test]
    fn the_report_kinds_keep_the_messages_of_their_former_enum() {
        let kind = ErrorKind::Plot { figure: "histogram".into(), message: "no room".into() };
        assert_eq!(kind.to_string(), "the chart \"histogram\" could not be drawn: no room");
        let source = serde_json::from_str::<f64>("x").unwrap_err();
        let expected = format!("the evaluation could not be written as JSON: {source}");
        assert_eq!(ErrorKind::EvaluationJson { source }.to_string(), expected);
    }
}
