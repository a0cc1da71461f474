//! The refusals of pose planning: the kinds of [`errors::Error`] this crate raises, with their messages.

use std::fmt;

/// What pose planning refuses.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// Fewer planning candidates than poses asked for.
    TooFewCandidates {
        /// Candidates available.
        candidates: usize,
        /// Poses asked for.
        poses: usize,
    },
    /// Planning candidates that determine no direction of the identification.
    NoIdentifiableDirection {
        /// Candidates.
        candidates: usize,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::TooFewCandidates { candidates, poses } => {
                write!(f, "{poses} poses asked for but only {candidates} candidates given")
            }
            ErrorKind::NoIdentifiableDirection { candidates } => {
                write!(f, "the {candidates} candidates determine no direction of the identification")
            }
        }
    }
}

impl std::error::Error for ErrorKind {}

impl errors::Kind for ErrorKind {}

#[cfg(test)]
mod tests {
    use super::ErrorKind;

    #[test]
    fn the_planning_kinds_keep_their_messages() {
        assert_eq!(
            ErrorKind::TooFewCandidates { candidates: 5, poses: 6 }.to_string(),
            "6 poses asked for but only 5 candidates given"
        );
        assert_eq!(
            ErrorKind::NoIdentifiableDirection { candidates: 4 }.to_string(),
            "the 4 candidates determine no direction of the identification"
        );
    }
}
