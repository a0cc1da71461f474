//! The crate's error.

/// Why a report could not be made.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// The pipeline refused the model or the data (the evaluation, the tools, an output file).
    Pipeline(pipeline::Error),
    /// A chart could not be drawn.
    Plot {
        /// The chart.
        figure: String,
        /// What `plotters` said.
        message: String,
    },
    /// The embedded `eval --json` could not be serialised.
    Json {
        /// What `serde_json` said.
        message: String,
    },
    /// A folder could not be made.
    Io {
        /// The folder.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Pipeline(e) => write!(f, "{e}"),
            Error::Plot { figure, message } => write!(f, "the chart {figure:?} could not be drawn: {message}"),
            Error::Json { message } => write!(f, "the evaluation could not be written as JSON: {message}"),
            Error::Io { path, source } => write!(f, "{path}: {source}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Pipeline(e) => Some(e),
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl From<pipeline::Error> for Error {
    fn from(e: pipeline::Error) -> Self {
        Error::Pipeline(e)
    }
}
