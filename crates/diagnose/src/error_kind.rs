//! The refusals of the diagnosis: the kinds of [`errors::Error`] this crate raises, with their messages.

use std::fmt;

/// What the diagnosis refuses or fails on.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A report could not be written as JSON.
    Json {
        /// What was being written.
        what: &'static str,
        /// The underlying error.
        source: serde_json::Error,
    },
    /// The diagnosis's regularised normal equations were not positive definite: the data hold a
    /// non-finite number or are degenerate beyond what the prior can hold.
    DiagnoseSolve {
        /// Folds whose rows were left out of the fit (empty: every row).
        left_out: Vec<usize>,
        /// Number of columns of the system.
        columns: usize,
        /// The pivot at which the factorisation failed.
        pivot: usize,
    },
    /// Too few rows for what was asked.
    TooFewRows {
        /// Rows available.
        rows: usize,
        /// Rows needed.
        needed: usize,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::Json { what, source } => write!(f, "{what} as JSON: {source}"),
            ErrorKind::DiagnoseSolve { left_out, columns, pivot } => write!(
                f,
                "diagnose: the regularised fit without folds {left_out:?} ({columns} columns) is not positive definite at pivot {pivot}"
            ),
            ErrorKind::TooFewRows { rows, needed } => {
                write!(f, "{rows} measurement rows, at least {needed} needed")
            }
        }
    }
}

impl std::error::Error for ErrorKind {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ErrorKind::Json { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl errors::Kind for ErrorKind {}
