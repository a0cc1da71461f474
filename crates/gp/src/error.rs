//! The crate's one error type.

use core::fmt;

/// Everything that can go wrong when fitting or querying a Gaussian process.
///
/// Each variant carries the numbers that explain it, so that a caller can report the failure
/// without parsing a message.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// The training set has fewer rows than the method needs.
    TooFewPoints {
        /// Rows given.
        rows: usize,
        /// Rows needed.
        required: usize,
    },
    /// The input matrix has no columns.
    NoInputDimensions,
    /// The output matrix has no columns.
    NoOutputs,
    /// The input and output matrices do not have the same number of rows.
    RowCountMismatch {
        /// Rows of the input matrix.
        input_rows: usize,
        /// Rows of the output matrix.
        output_rows: usize,
    },
    /// A query (or a kernel) expects inputs of another dimension.
    InputDimensionMismatch {
        /// Dimension the model was fitted with.
        expected: usize,
        /// Dimension given.
        found: usize,
    },
    /// An input or output entry is NaN or infinite.
    NonFiniteData {
        /// Row of the offending entry.
        row: usize,
        /// Column of the offending entry.
        column: usize,
        /// `true` for the output matrix, `false` for the input matrix.
        in_outputs: bool,
    },
    /// A log-parameter vector has the wrong length for its kernel.
    ParameterCountMismatch {
        /// Length the kernel needs.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// A hyperparameter is not finite and strictly positive.
    InvalidHyperparameter {
        /// Index in the kernel's log-parameter vector.
        index: usize,
        /// The offending value (natural scale, not log).
        value: f64,
    },
    /// A bound pair is not `0 < lower <= upper < inf`.
    InvalidBounds {
        /// Index in the kernel's log-parameter vector.
        index: usize,
        /// Lower bound given (natural scale).
        lower: f64,
        /// Upper bound given (natural scale).
        upper: f64,
    },
    /// An option of the configuration is outside its range (the shape of `poe`'s refusals too).
    InvalidOption {
        /// Which field, by its path in the config struct (`jitter.growth`).
        field: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A configuration that does not fit the data or the other settings (kernels, groups).
    InvalidConfig {
        /// Which field, by its name in the config struct.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// The Cholesky factorisation failed even after adding the largest jitter allowed.
    CholeskyFailed {
        /// Size of the matrix.
        size: usize,
        /// Index of the first pivot that was not positive, at the last attempt.
        pivot: usize,
        /// Largest jitter added to the diagonal (absolute, in normalised output units).
        jitter_tried: f64,
    },
    /// No restart of the hyperparameter search reached a finite log marginal likelihood.
    OptimisationFailed {
        /// Number of starting points tried.
        starts: usize,
    },
    /// The diagonal of the inverse training covariance that leave-one-out prediction divides by
    /// is not finite and positive at a row (a covariance too ill-conditioned for it).
    LeaveOneOutFailed {
        /// Size of the matrix.
        size: usize,
        /// The row.
        row: usize,
        /// The value found.
        value: f64,
    },
    /// The groups of a leave-group-out prediction are not a partition of the training rows: a
    /// row is beyond them, in two groups, or in none.
    InvalidGroups {
        /// Training rows.
        rows: usize,
        /// The first row out of range, repeated or missing.
        row: usize,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooFewPoints { rows, required } => {
                write!(f, "training set has {rows} rows, at least {required} needed")
            }
            Self::NoInputDimensions => write!(f, "input matrix has no columns"),
            Self::NoOutputs => write!(f, "output matrix has no columns"),
            Self::RowCountMismatch { input_rows, output_rows } => {
                write!(f, "inputs have {input_rows} rows but outputs have {output_rows}")
            }
            Self::InputDimensionMismatch { expected, found } => {
                write!(f, "inputs have {found} columns, the model expects {expected}")
            }
            Self::NonFiniteData { row, column, in_outputs } => {
                let which = if *in_outputs { "output" } else { "input" };
                write!(f, "{which} entry at row {row}, column {column} is not finite")
            }
            Self::ParameterCountMismatch { expected, found } => {
                write!(f, "kernel needs {expected} log-parameters, {found} given")
            }
            Self::InvalidHyperparameter { index, value } => {
                write!(f, "hyperparameter {index} is {value}, it must be finite and > 0")
            }
            Self::InvalidBounds { index, lower, upper } => {
                write!(f, "bounds of hyperparameter {index} are [{lower}, {upper}], need 0 < lower <= upper < inf")
            }
            Self::InvalidOption { field, value, expected: e } => write!(f, "option {field} = {value}: expected {e}"),
            Self::InvalidConfig { field, value } => write!(f, "configuration field `{field}` = {value} is invalid"),
            Self::CholeskyFailed { size, pivot, jitter_tried } => write!(
                f,
                "Cholesky factorisation of a {size}x{size} kernel matrix failed at pivot {pivot} \
                 even with jitter {jitter_tried:e} on the diagonal"
            ),
            Self::OptimisationFailed { starts } => {
                write!(f, "none of {starts} hyperparameter starts reached a finite log marginal likelihood")
            }
            Self::LeaveOneOutFailed { size, row, value } => write!(
                f,
                "leave-one-out prediction failed: the inverse of the {size}x{size} training covariance has \
                 {value:e} on its diagonal at row {row}"
            ),
            Self::InvalidGroups { rows, row } => write!(
                f,
                "leave-group-out groups must hold each of the {rows} training rows once: row {row} is out of range, \
                 repeated or missing"
            ),
        }
    }
}

impl std::error::Error for Error {}
