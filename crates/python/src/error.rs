//! Errors as Python exceptions: the pipeline's message as it is (it names file, line and column),
//! `FileNotFoundError` for a missing file, `calib.CalibError` for everything else.

use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    calib,
    CalibError,
    pyo3::exceptions::PyException,
    "A refusal of the calibration pipeline; the message names the file, line and column where it has them."
);

/// The exception of a pipeline error. A `CalibError` also carries the place as attributes, `file`,
/// `line` and `column` (`None` where the error has none): the line as an editor counts it, as in
/// the message.
pub fn to_py(error: errors::Error) -> PyErr {
    let message = error.to_string();
    match error.kind::<errors::CommonKind>() {
        Some(errors::CommonKind::Io { source }) if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(message)
        }
        _ => {
            let raised = CalibError::new_err(message);
            let place = error.place();
            Python::attach(|py| {
                let value = raised.value(py);
                // Setting an attribute on a fresh exception instance cannot fail but for memory.
                let _ = value.setattr("file", place.map(|p| p.file().to_owned()));
                let _ = value.setattr("line", place.and_then(errors::Place::line));
                let _ = value.setattr("column", place.and_then(errors::Place::column));
            });
            raised
        }
    }
}

/// A bad argument, named.
pub fn argument(name: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{name}: {message}"))
}
