//! `calib._calib`, the native half of the Python package `calib` (sources in `python/calib`, built
//! by maturin from `python/pyproject.toml`). It runs the flows of the `calib` binary (`calib::flow`,
//! the library half of the crate `calib`) with the same inputs, so that a number in Python equals
//! the CLI's to the last bit:
//! files are read by the same readers, arrays are written as CSV text (Rust's shortest
//! round-trip form, so every `f64` reads back unchanged) and parsed by the same parser, and
//! faer runs sequentially as in the binary's `main`.
//!
//! The classes here are the thin core; `python/calib/__init__.py` wraps them in Python's
//! conventions (keyword arguments, pandas, dataclass reports, warnings). Every long call
//! (`fit`, `eval`, `predict`, `diagnose`, `simulate`, `compensate`) releases the GIL.
//!
//! A Python session that does what `calib fit` and `calib eval --json` do:
//!
//! ```python
//! import calib
//! robot = calib.Robot.load("fixtures/robots/ur10.ron")
//! model = calib.fit(robot, calib.Measurements.read("train.csv"), method="poe-gp", effects="auto")
//! print(model.eval(calib.Measurements.read("test.csv")).mean_position_error_mm)
//! poses, sigma = model.predict(q)  # q: (n, joints) radians
//! ```

mod error;
mod measurements;
mod model;
mod robot;
mod studies;
mod types;

use pyo3::prelude::*;

/// The native module: the classes and functions `calib` wraps.
#[pymodule]
fn _calib(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // As the binary's `main`: faer's own operations split their work by the global thread count,
    // which changes their last bits; parallelism comes from the pipeline's rayon loops instead.
    faer::set_global_parallelism(faer::Par::Seq);
    m.add("CalibError", m.py().get_type::<error::CalibError>())?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<types::Measurements>()?;
    m.add_class::<types::Model>()?;
    m.add_function(wrap_pyfunction!(model::fit, m)?)?;
    m.add_function(wrap_pyfunction!(studies::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(studies::simulate, m)?)?;
    Ok(())
}
