//! `Measurements`: a measurement set read by the SPEC's CSV reader, from a file or from columns.
//!
//! Columns given as arrays are written as CSV text and parsed by the same reader as a file, so
//! that every check of the SPEC (names, units, ranges, quaternion norms) holds for them too and
//! their refusals name a line and a column: row `i` of the arrays is line `i + 2` (line 1 is the
//! header), numbered as in the CSV file `to_csv` writes. Rust's `{}` of an `f64` is its shortest
//! round-trip text, so the numbers the reader gets back are the arrays' numbers exactly.

use crate::error::{argument, to_py};
use crate::robot::Robot;
use crate::types::{Measurements, Model, matrix};
use measurements::{ColumnMap, ReadOptions};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;
use std::path::PathBuf;

/// The read options for the joints of a robot or a model, or of any robot, keeping the columns
/// `inputs` as measured signals (`fit(..., inputs=...)`) and, for a model, the inputs it takes.
fn read_options(
    py: Python<'_>,
    against: Option<&Bound<'_, PyAny>>,
    columns: ColumnMap,
    inputs: Vec<String>,
) -> PyResult<ReadOptions> {
    let Some(against) = against.filter(|a| !a.is_none()) else {
        return Ok(ReadOptions { columns, inputs, ..ReadOptions::default() });
    };
    let kinds = if let Ok(robot) = against.cast::<Robot>() {
        robot.get().description.joint_kinds()
    } else if let Ok(model) = against.cast::<Model>() {
        let model = &model.get().model;
        let mut options = model.read_options(columns);
        options.inputs.extend(inputs.into_iter().filter(|name| !model.input_names().contains(name)));
        return Ok(options);
    } else {
        let _ = py;
        return Err(argument(
            "robot",
            "expected a calib Robot or Model (whose joints the columns are checked against)",
        ));
    };
    Ok(ReadOptions::for_joints(kinds).with_columns(columns).with_inputs(inputs))
}

/// `inputs=[...]` as `--inputs` checks it: no name empty or given twice.
fn input_names(inputs: Option<Vec<String>>) -> PyResult<Vec<String>> {
    let names =
        measurements::InputNames::new(inputs.unwrap_or_default(), "inputs").map_err(|e| argument("inputs", e))?;
    Ok(names.names().to_vec())
}

/// `--columns NAME=HEADER,…` from a mapping, through the CLI's own parser of the option.
fn column_map(columns: Option<Vec<(String, String)>>) -> PyResult<ColumnMap> {
    let Some(pairs) = columns else { return Ok(ColumnMap::default()) };
    if pairs.is_empty() {
        return Ok(ColumnMap::default());
    }
    let text: Vec<String> =
        pairs.iter().map(|(name, header)| format!("{name}=\"{}\"", header.replace('"', "\"\""))).collect();
    text.join(",").parse::<ColumnMap>().map_err(|e| argument("columns", e))
}

impl Measurements {
    /// The set parsed from CSV text, as `calib` parses a file.
    pub(crate) fn parse(text: &[u8], source: &str, options: &ReadOptions) -> Result<Self, errors::Error> {
        Ok(Self { set: measurements::parse_measurements(text, source, options)? })
    }
}

#[pymethods]
impl Measurements {
    /// Reads a measurement CSV (SPEC; `;` and decimal commas are detected) as `calib fit --data`
    /// does. `robot` (a Robot or a Model) checks the joint columns against its joints at once, as
    /// the CLI does; without it they are checked when the set is used. `columns` maps SPEC names
    /// onto other headers (`--columns`). With `positions=False` the position columns may be left
    /// out (`calib predict --data`).
    #[staticmethod]
    #[pyo3(signature = (path, robot=None, columns=None, positions=true, inputs=None))]
    fn read(
        py: Python<'_>,
        path: PathBuf,
        robot: Option<&Bound<'_, PyAny>>,
        columns: Option<Vec<(String, String)>>,
        positions: bool,
        inputs: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let options = read_options(py, robot, column_map(columns)?, input_names(inputs)?)?;
        let set = py
            .detach(|| {
                if positions {
                    measurements::read_measurements(&path, &options)
                } else {
                    measurements::read_configurations(&path, &options)
                }
            })
            .map_err(to_py)?;
        Ok(Self { set })
    }

    /// A set from columns named as the SPEC names them (`q1_rad` …, `x_mm`, `y_mm`, `z_mm`,
    /// `qw` …, `payload_kg`, `temp_c`, `t_s`, `tau1_nm` …): `numeric` as float arrays, `text`
    /// (the `tool` column) as strings, all of one length. `source` names the set in messages;
    /// row `i` is line `i + 2`.
    #[staticmethod]
    #[pyo3(signature = (numeric, text, source, robot=None, inputs=None))]
    fn from_columns(
        py: Python<'_>,
        numeric: Vec<(String, PyReadonlyArray1<'_, f64>)>,
        text: Vec<(String, Vec<String>)>,
        source: String,
        robot: Option<&Bound<'_, PyAny>>,
        inputs: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let options = read_options(py, robot, ColumnMap::default(), input_names(inputs)?)?;
        let numeric: Vec<(String, Vec<f64>)> =
            numeric.into_iter().map(|(name, values)| (name, values.as_array().to_vec())).collect();
        let rows = numeric.first().map(|(_, v)| v.len()).or_else(|| text.first().map(|(_, v)| v.len())).unwrap_or(0);
        for (name, len) in numeric.iter().map(|(n, v)| (n, v.len())).chain(text.iter().map(|(n, v)| (n, v.len()))) {
            if len != rows {
                return Err(argument(name, format!("{len} values where the first column has {rows}")));
            }
        }
        let csv = py.detach(|| columns_csv(&numeric, &text, rows)).map_err(|e| argument("columns", e))?;
        py.detach(|| Self::parse(&csv, &source, &options)).map_err(to_py)
    }

    /// Number of rows.
    fn __len__(&self) -> usize {
        self.set.rows.len()
    }

    /// Where the rows come from, as messages name it.
    #[getter]
    fn source(&self) -> String {
        self.set.source.clone()
    }

    /// Number of joint columns.
    #[getter]
    fn joint_count(&self) -> usize {
        self.set.joint_count
    }

    /// Whether every row has an orientation.
    #[getter]
    fn full_pose(&self) -> bool {
        self.set.full_pose
    }

    /// Whether the rows carry measured positions.
    #[getter]
    fn positions_measured(&self) -> bool {
        self.set.positions_measured
    }

    /// The tool identifiers in order of first appearance (`""` the default tool).
    #[getter]
    fn tools(&self) -> Vec<String> {
        self.set.tools.clone()
    }

    /// Columns found but not used.
    #[getter]
    fn ignored_columns(&self) -> Vec<String> {
        self.set.ignored_columns.clone()
    }

    /// The reader's one-line summary (`read FILE: N rows, …`), as the CLI prints it.
    fn read_summary(&self) -> String {
        self.set.read_summary()
    }

    /// Line of each row in its file.
    fn lines<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        PyArray1::from_vec(py, self.set.rows.iter().map(|r| r.line).collect())
    }

    /// Joint values, `(n, joints)`, rad (m for prismatic joints).
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows: Vec<Vec<f64>> = self.set.rows.iter().map(|r| r.q.clone()).collect();
        matrix(py, rows, self.set.joint_count)
    }

    /// Measured tool points, `(n, 3)`, tracker frame, mm.
    fn positions_mm<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows: Vec<Vec<f64>> = self.set.rows.iter().map(|r| (r.position * 1e3).iter().copied().collect()).collect();
        matrix(py, rows, 3)
    }

    /// Measured orientations as unit quaternions `(qw, qx, qy, qz)`, `(n, 4)`; `None` for
    /// position-only data.
    fn quaternions<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let rows: Option<Vec<Vec<f64>>> =
            self.set.rows.iter().map(|r| r.orientation.map(|o| o.to_quaternion().to_vec())).collect();
        rows.map(|rows| matrix(py, rows, 4)).transpose()
    }

    /// Payload of each row, kg.
    fn payload_kg<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.set.rows.iter().map(|r| r.payload_kg).collect())
    }

    /// Tool identifier of each row.
    fn tool_of_rows(&self) -> Vec<String> {
        self.set.rows.iter().map(|r| self.set.tools.get(r.tool).cloned().unwrap_or_default()).collect()
    }

    /// Temperature of each row, °C (NaN where the file has none).
    fn temp_c<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.set.rows.iter().map(|r| r.temp_c.unwrap_or(f64::NAN)).collect())
    }

    /// Time of each row, s (NaN where the file has none).
    fn t_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.set.rows.iter().map(|r| r.t_s.unwrap_or(f64::NAN)).collect())
    }

    /// The rows at `indices` (0-based), as a set of their own with the same tools.
    fn subset(&self, indices: Vec<usize>) -> PyResult<Self> {
        let n = self.set.rows.len();
        if let Some(&bad) = indices.iter().find(|&&i| i >= n) {
            return Err(argument("indices", format!("row {bad} of a set of {n}")));
        }
        Ok(Self { set: self.set.subset(&indices) })
    }

    fn __repr__(&self) -> String {
        let kind = if self.set.full_pose { "full pose" } else { "position only" };
        format!("Measurements({:?}, {} rows, {kind})", self.set.source, self.set.rows.len())
    }
}

/// The columns as SPEC CSV text: header, then one record per row; numbers in Rust's shortest
/// round-trip form.
fn columns_csv(
    numeric: &[(String, Vec<f64>)],
    text: &[(String, Vec<String>)],
    rows: usize,
) -> Result<Vec<u8>, csv::Error> {
    let mut out = csv::Writer::from_writer(Vec::new());
    let header: Vec<&str> =
        numeric.iter().map(|(n, _)| n.as_str()).chain(text.iter().map(|(n, _)| n.as_str())).collect();
    out.write_record(&header)?;
    let mut record: Vec<String> = Vec::with_capacity(header.len());
    for i in 0..rows {
        record.clear();
        record.extend(numeric.iter().map(|(_, v)| v[i].to_string()));
        record.extend(text.iter().map(|(_, v)| v[i].clone()));
        out.write_record(&record)?;
    }
    out.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}
