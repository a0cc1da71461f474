//! The Python classes that refer to each other (a `Measurements` is read against a `Model`'s
//! joints, a `Model` evaluates `Measurements`), defined here so that their methods' modules import
//! this one and not each other, and the numpy helper both use.

use measurements::MeasurementSet;
use model::CalibratedModel;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;

/// A calibrated model (what `calib fit` writes).
#[pyclass(module = "calib._calib", frozen)]
#[derive(Debug, Clone)]
pub struct Model {
    /// The model as its file holds it: what predictions use.
    pub(crate) model: CalibratedModel,
    /// For a model fitted in this session, the fit's own: what `save` writes, the bytes
    /// `calib fit --out` writes (the file's text does not read back to the same bits, so a
    /// model read back and written again differs from it in the last digits).
    pub(crate) fitted: Option<CalibratedModel>,
    /// Where it was read from or fitted, for messages.
    pub(crate) name: String,
}

/// A set of measured (or only commanded) poses, SI inside.
#[pyclass(module = "calib._calib", frozen)]
#[derive(Debug, Clone)]
pub struct Measurements {
    pub(crate) set: MeasurementSet,
}

/// A `(rows, width)` array from rows of `width` values.
pub(crate) fn matrix<'py>(py: Python<'py>, rows: Vec<Vec<f64>>, width: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.into_iter().flatten().collect();
    PyArray1::from_vec(py, flat).reshape([n, width])
}
