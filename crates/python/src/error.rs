//! Errors as Python exceptions: the pipeline's message as it is (it names file, line and column),
//! `FileNotFoundError` for a missing file, `calib.CalibError` for everything else.

use pyo3::PyErr;
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};

pyo3::create_exception!(
    calib,
    CalibError,
    pyo3::exceptions::PyException,
    "A refusal of the calibration pipeline; the message names the file, line and column where it has them."
);

/// The exception of a pipeline error.
pub fn to_py(error: errors::Error) -> PyErr {
    let message = error.to_string();
    match error.kind() {
        errors::ErrorKind::Io { source } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(message)
        }
        _ => CalibError::new_err(message),
    }
}

/// A bad argument, named.
pub fn argument(name: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{name}: {message}"))
}
