//! The errors of the `poe` crate.

use std::fmt;

/// What can go wrong when building or identifying a kinematic model.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A joint vector's length does not match the model.
    JointCountMismatch {
        /// Length given.
        given: usize,
        /// The model's joint count.
        expected: usize,
    },
    /// A joint axis direction is not a unit vector.
    AxisNotUnit {
        /// 0-based joint index.
        joint: usize,
        /// The norm found.
        norm: f64,
    },
    /// A tool index refers to no tool of the model.
    UnknownTool {
        /// The index given.
        tool: usize,
        /// The number of tools in the model.
        tool_count: usize,
    },
    /// A parameter mask has the wrong length.
    MaskLength {
        /// Length given.
        given: usize,
        /// Number of parameters.
        expected: usize,
    },
    /// Fewer observations than needed to determine the free parameters.
    TooFewObservations {
        /// Rows given.
        rows: usize,
        /// Rows needed at least.
        needed: usize,
    },
    /// The observations mix full-pose and position-only rows, which the registration cannot use.
    MixedObservations,
    /// The iterations diverged or produced a non-finite value.
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// Root-mean-square residual at the last iteration.
        residual: f64,
    },
    /// The closed-form registration found the data degenerate (e.g. all poses alike).
    DegenerateRegistration {
        /// Rank of the linear system found.
        rank: usize,
        /// Rank needed.
        needed: usize,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::JointCountMismatch { given, expected } => {
                write!(f, "{given} joint values given, the robot has {expected} joints")
            }
            Error::AxisNotUnit { joint, norm } => {
                write!(f, "axis of joint {} has norm {norm}, expected 1", joint + 1)
            }
            Error::UnknownTool { tool, tool_count } => {
                write!(f, "tool index {tool} out of range: the model has {tool_count} tools")
            }
            Error::MaskLength { given, expected } => {
                write!(f, "parameter mask has {given} entries, the model has {expected} parameters")
            }
            Error::TooFewObservations { rows, needed } => {
                write!(f, "{rows} measurement rows, at least {needed} needed")
            }
            Error::MixedObservations => {
                write!(f, "full-pose and position-only rows cannot be mixed")
            }
            Error::NotConverged { iterations, residual } => {
                write!(f, "identification did not converge after {iterations} iterations (rms residual {residual:e})")
            }
            Error::DegenerateRegistration { rank, needed } => {
                write!(f, "the poses are too alike to register the tracker: rank {rank} of {needed}")
            }
        }
    }
}

impl std::error::Error for Error {}
