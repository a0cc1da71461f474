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
    /// Fewer residual rows than free parameters: the data cannot determine them.
    TooFewObservations {
        /// Measurements given.
        observations: usize,
        /// Residual rows they give (3 per position, 6 per pose).
        rows: usize,
        /// Parameters the identification would have to determine.
        parameters: usize,
    },
    /// Fewer measurements than the closed-form registration has unknowns.
    TooFewForRegistration {
        /// Measurements given.
        observations: usize,
        /// Unknowns of the linear registration (13, and 9 more per extra tool).
        needed: usize,
    },
    /// An option is out of its range.
    InvalidOption {
        /// The field of the options struct.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A linear solve failed (a factorisation that did not converge or a matrix that is not
    /// positive definite even with the damping).
    LinearSolveFailed {
        /// The iteration at which it failed.
        iteration: usize,
        /// Which decomposition.
        decomposition: &'static str,
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
            Error::TooFewObservations { observations, rows, parameters } => write!(
                f,
                "{observations} measurements give {rows} residual rows, fewer than the {parameters} free parameters \
                 they must determine: measure more poses or fit fewer parameters"
            ),
            Error::TooFewForRegistration { observations, needed } => {
                write!(f, "{observations} measurements, the registration of the tracker needs at least {needed}")
            }
            Error::InvalidOption { name, value, expected } => {
                write!(f, "option {name} = {value}: expected {expected}")
            }
            Error::LinearSolveFailed { iteration, decomposition } => {
                write!(f, "the {decomposition} of iteration {iteration} failed")
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
