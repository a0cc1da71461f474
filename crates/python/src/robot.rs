//! `Robot`: a robot description read as `calib --robot … [--base-link …] [--tip-link …]` reads it.

use crate::error::to_py;
use pyo3::prelude::*;
use robot::{ChainEnds, RobotDescription};
use std::path::PathBuf;

/// A robot description (RON with axes or a DH table, or URDF with its chain's ends).
#[pyclass(module = "calib._calib", frozen)]
#[derive(Debug, Clone)]
pub struct Robot {
    pub(crate) description: RobotDescription,
    /// The path it was read from, for messages.
    pub(crate) path: String,
}

#[pymethods]
impl Robot {
    /// Reads a robot description: RON (axes or DH table) or URDF (`.urdf`), with the URDF chain's
    /// base and tip links (default: the root link and the leaf with the most movable joints).
    #[staticmethod]
    #[pyo3(signature = (path, base_link=None, tip_link=None))]
    fn load(py: Python<'_>, path: PathBuf, base_link: Option<String>, tip_link: Option<String>) -> PyResult<Self> {
        let ends = ChainEnds { base_link, tip_link };
        let description = py.detach(|| RobotDescription::read_with(&path, &ends)).map_err(to_py)?;
        Ok(Self { description, path: path.display().to_string() })
    }

    /// The robot's name.
    #[getter]
    fn name(&self) -> String {
        self.description.name.clone()
    }

    /// The path the description was read from.
    #[getter]
    fn path(&self) -> String {
        self.path.clone()
    }

    /// Number of joints.
    #[getter]
    fn joint_count(&self) -> usize {
        self.description.joint_count()
    }

    /// `"revolute"` or `"prismatic"` for each joint, base first.
    #[getter]
    fn joint_kinds(&self) -> Vec<String> {
        self.description.joint_kinds().iter().map(|k| format!("{k:?}").to_lowercase()).collect()
    }

    /// The joint limits, SI (rad or m), `(low, high)` per joint; infinite where none.
    #[getter]
    fn limits(&self) -> Vec<(f64, f64)> {
        self.description.limits()
    }

    /// The description as RON text.
    fn to_ron(&self) -> String {
        self.description.to_ron()
    }

    fn __repr__(&self) -> String {
        format!("Robot({:?}, {} joints, from {:?})", self.description.name, self.description.joint_count(), self.path)
    }
}
