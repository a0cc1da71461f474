//! The sparse fit's refusals: the exact GP's, passed on whole, and its own.

/// Why a sparse fit was refused.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// Refused by the exact GP's checks, factorisations or subset fit (its message unchanged).
    Gp(gp::Error),
    /// More inducing points were asked for than there are training points.
    TooManyInducingPoints {
        /// Inducing points requested.
        requested: usize,
        /// Training points available.
        available: usize,
    },
}

impl From<gp::Error> for Error {
    fn from(error: gp::Error) -> Self {
        Self::Gp(error)
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Gp(error) => error.fmt(f),
            Self::TooManyInducingPoints { requested, available } => {
                write!(f, "{requested} inducing points requested but only {available} training points")
            }
        }
    }
}

impl std::error::Error for Error {}
