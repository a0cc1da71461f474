//! The crate's one error type: every refusal carries the numbers that explain it.

use std::fmt;

/// Why a registration or a plan was refused.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// A file or model error from `pipeline` (its message names the file, line and column).
    Pipeline(errors::Error),
    /// A kinematics error from `poe`.
    Kinematics(poe::Error),
    /// The candidate generator's error.
    Generator(loadsim::Error),
    /// Too few poses for what is re-fitted: `rows` residual rows for `parameters` parameters,
    /// `needed` rows wanted (or too few poses of one tool).
    TooFewPoses {
        /// What is short: `the registration` or `tool 'x'`.
        what: String,
        /// Poses given.
        poses: usize,
        /// Poses needed.
        needed_poses: usize,
        /// Residual rows given.
        rows: usize,
        /// Parameters re-fitted.
        parameters: usize,
    },
    /// The data name a tool the model does not know, and tools are not re-fitted.
    NewToolWithoutRefit {
        /// The measurement file.
        file: String,
        /// The first line with it.
        line: u64,
        /// Its column.
        column: usize,
        /// The tool's identifier.
        tool: String,
    },
    /// The poses do not determine what is re-fitted (e.g. all points on a line, or one flange
    /// orientation for a tool offset and a base rotation).
    Undetermined {
        /// Directions the poses determine.
        rank: usize,
        /// Parameters re-fitted.
        parameters: usize,
        /// Largest over smallest singular value of the scaled Jacobian.
        condition: f64,
    },
    /// The least squares did not converge.
    NotConverged {
        /// Iterations run.
        iterations: usize,
        /// RMS residual at the end, m.
        rms_m: f64,
    },
    /// An option is out of its range.
    BadOption {
        /// The option's field name.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// Fewer candidates than poses asked for.
    TooFewCandidates {
        /// Candidates available.
        candidates: usize,
        /// Poses asked for.
        poses: usize,
    },
    /// The candidates determine fewer directions of the identification than it has.
    NoIdentifiableDirection {
        /// Candidates.
        candidates: usize,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Pipeline(e) => write!(f, "{e}"),
            Error::Kinematics(e) => write!(f, "{e}"),
            Error::Generator(e) => write!(f, "{e}"),
            Error::TooFewPoses { what, poses, needed_poses, rows, parameters } => write!(
                f,
                "too few poses for {what}: {poses} poses ({rows} residual rows) for {parameters} re-fitted \
                 parameters; at least {needed_poses} poses are needed"
            ),
            Error::NewToolWithoutRefit { file, line, column, tool } => write!(
                f,
                "{file}:{line}:{column}: tool '{tool}' is not in the model; re-fit tools to add it \
                 (--refit tools or --refit base,tools)"
            ),
            Error::Undetermined { rank, parameters, condition } => write!(
                f,
                "the poses determine only {rank} of the {parameters} re-fitted parameters (condition number \
                 {condition:.3e}): measure poses with more varied joint angles and flange orientations"
            ),
            Error::NotConverged { iterations, rms_m } => write!(
                f,
                "the registration did not converge in {iterations} iterations (RMS residual {:.4} mm)",
                rms_m * 1e3
            ),
            Error::BadOption { field, value, expected } => write!(f, "option {field} = {value}: expected {expected}"),
            Error::TooFewCandidates { candidates, poses } => {
                write!(f, "{poses} poses asked for but only {candidates} candidates given")
            }
            Error::NoIdentifiableDirection { candidates } => {
                write!(f, "the {candidates} candidates determine no direction of the identification")
            }
        }
    }
}

impl std::error::Error for Error {}

impl From<errors::Error> for Error {
    fn from(e: errors::Error) -> Self {
        Error::Pipeline(e)
    }
}

impl From<poe::Error> for Error {
    fn from(e: poe::Error) -> Self {
        Error::Kinematics(e)
    }
}

impl From<loadsim::Error> for Error {
    fn from(e: loadsim::Error) -> Self {
        Error::Generator(e)
    }
}
