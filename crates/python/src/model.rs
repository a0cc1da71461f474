//! `Model` and `fit`: what `calib fit`, `eval`, `predict` and `compensate` do, through the flows
//! those commands run (`calib::flow`).

use crate::error::{argument, to_py};
use crate::robot::Robot;
use crate::types::{Measurements, Model, matrix};
use calib::flow::{FitOverrides, Refused};
use effects::EffectSelection;
use measurements::{BoundSet, Measurement};
use model::{CalibratedModel, GpChoice, Method};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pipeline::FitOptions;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// Fits `method` to `data` for `robot` as `calib fit` does: options from a RON file or JSON text,
/// then `effects`, `force` and `gp` over them, as the CLI's flags go over `--options`. Returns the
/// model, the fit report as the JSON text `calib fit --json` prints, and its warnings in words.
#[pyfunction]
#[pyo3(signature = (robot, data, method, effects=None, gp=None, options_path=None, options_json=None, force=false, inputs=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit(
    py: Python<'_>,
    robot: &Robot,
    data: &Measurements,
    method: &str,
    effects: Option<&str>,
    gp: Option<&str>,
    options_path: Option<PathBuf>,
    options_json: Option<&str>,
    force: bool,
    inputs: Option<Vec<String>>,
) -> PyResult<(Model, String, Vec<String>)> {
    let method: Method = method.parse().map_err(|e| argument("method", e))?;
    let mut options = match (&options_path, options_json) {
        (Some(path), _) => FitOptions::read(path).map_err(to_py)?,
        (None, Some(json)) => {
            let options: FitOptions = serde_json::from_str(json).map_err(|e| argument("options", e))?;
            options.validate().map_err(|(_, message)| argument("options", message))?;
            options
        }
        (None, None) => FitOptions::default(),
    };
    // The flags over the options, as `calib fit` sets them.
    let overrides = FitOverrides {
        effects: effects.map(str::parse::<EffectSelection>).transpose().map_err(to_py)?,
        force,
        gp: gp.map(str::parse::<GpChoice>).transpose().map_err(|e| argument("gp", e))?,
        inputs: inputs
            .filter(|i| !i.is_empty())
            .map(|i| measurements::InputNames::new(i, "inputs").map(|names| names.names().to_vec()))
            .transpose()
            .map_err(|e| argument("inputs", e))?,
    };
    overrides.apply(&mut options, method).map_err(|e| argument("inputs", e))?;
    let (robot, data) = (&robot.description, &data.set);
    let ((model, fitted), report) = py
        .detach(|| {
            // The phases timed as `calib fit` times them (its report's `timings`).
            let (fitted, timings) = timings::record(|| {
                let (fitted, report, held) =
                    calib::flow::fit_and_write(robot, data, method, &options, as_its_file_holds)?;
                Ok::<_, errors::Error>(((held, fitted), report))
            });
            fitted.map(|(models, report)| (models, (report, timings)))
        })
        .map(|(models, (report, timings))| {
            let report = pipeline::FitReport { timings: timings.phases, ..report };
            (models, report)
        })
        .map_err(to_py)?;
    let json = serde_json::to_string(&report).map_err(|e| argument("report", e))?;
    let warnings = report.warnings.iter().map(ToString::to_string).collect();
    let name = format!("the {method} model fitted on {}", data.source);
    Ok((Model { model, fitted: Some(fitted), name }, json, warnings))
}

/// The model as its file holds it: written and read back, as `calib fit` then `calib eval` do.
/// The file does not keep every bit of the fitted model (predictions moved by ~1e-12 mm on the
/// test campaign), and the CLI only ever uses the file: so the package's numbers are the CLI's
/// to the last bit.
fn as_its_file_holds(model: &CalibratedModel) -> Result<CalibratedModel, errors::Error> {
    let io = |source| errors::Error::io("a temporary model file", source);
    let folder = tempfile::tempdir().map_err(io)?;
    let path = folder.path().join("model.ron");
    model::write_model(&path, model)?;
    model::read_model(&path)
}

/// What `predict` returns: poses, their standard deviations where the model has them, warnings.
type Predicted<'py> = (Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray2<f64>>>, Vec<String>);

#[pymethods]
impl Model {
    /// Reads a model file (RON, from `calib fit` or `Model.save`), with the checks `calib eval`
    /// runs on it.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let model = py.detach(|| model::read_model(&path)).map_err(to_py)?;
        Ok(Self { model, fitted: None, name: path.display().to_string() })
    }

    /// Writes the model file (RON) as `calib fit --out` does (atomically; never over a symbolic
    /// link's target without following it).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let model = self.fitted.as_ref().unwrap_or(&self.model);
        py.detach(|| model::write_model(&path, model)).map_err(to_py)
    }

    /// The method that produced the model.
    #[getter]
    fn method(&self) -> String {
        self.model.method.to_string()
    }

    /// The robot's name.
    #[getter]
    fn robot(&self) -> String {
        self.model.robot.clone()
    }

    /// Whether the model was fitted on full poses (otherwise orientation is not calibrated).
    #[getter]
    fn full_pose(&self) -> bool {
        self.model.full_pose
    }

    /// Tool identifiers (`""` the default tool).
    #[getter]
    fn tools(&self) -> Vec<String> {
        self.model.tools.clone()
    }

    /// Number of joints.
    #[getter]
    fn joint_count(&self) -> usize {
        self.model.joint_count()
    }

    /// Whether predictions carry a standard deviation.
    #[getter]
    fn predicts_std(&self) -> bool {
        self.model.predicts_std()
    }

    /// The parts a URDF cannot hold (effects, the GP), in the order they apply.
    #[getter]
    fn non_geometric_parts(&self) -> Vec<String> {
        self.model.non_geometric_parts()
    }

    /// `calib eval --json`: the report's JSON text, the position error of each row (mm), the
    /// rotation error of each row (mrad; `None` unless data and model are full pose) and the
    /// notes and warnings the CLI prints, in its order (`calib::flow::EvalNotices`).
    #[allow(clippy::type_complexity)]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        data: &Measurements,
    ) -> PyResult<(String, Bound<'py, PyArray1<f64>>, Option<Bound<'py, PyArray1<f64>>>, Vec<String>)> {
        let (model, name) = (&self.model, Path::new(&self.name));
        // A model loaded from a file is named by it, as the CLI names its `--model`.
        let from_file = self.fitted.is_none();
        let evaluated =
            py.detach(|| calib::flow::evaluate(model, name, from_file, data.set.clone())).map_err(refused)?;
        let calib::flow::Evaluated { evaluation, report, notices, .. } = evaluated;
        // `calib eval`'s notes, then its warnings: the same list, raised in the same order.
        let mut warnings = notices.notes;
        warnings.extend(notices.warnings);
        let json = serde_json::to_string(&report).map_err(|e| argument("report", e))?;
        let position = PyArray1::from_vec(py, evaluation.errors.iter().map(|e| e.position_mm).collect());
        let rotation: Option<Vec<f64>> = evaluation.errors.iter().map(|e| e.rotation_mrad).collect();
        Ok((json, position, rotation.map(|r| PyArray1::from_vec(py, r)), warnings))
    }

    /// `calib predict` on a measurement set (tools matched by name, as the CLI matches them).
    fn predict_set<'py>(&self, py: Python<'py>, data: &Measurements) -> PyResult<Predicted<'py>> {
        let (set, wrapped) = calib::flow::wrapped(&self.model, data.set.clone());
        let bound = self.model.bind(&set).map_err(to_py)?;
        self.predict_rows(py, &bound, &wrapped)
    }

    /// `calib predict` on arrays: `q` `(n, joints)` rad (m), and per row `payload_kg`, the tool
    /// identifier, `temp_c`, `t_s` and `torques_nm` `(n, joints)` where the model needs them, and
    /// `inputs`, each measured signal the model takes by name (refused by name where missing).
    /// Row `i` is named line `i + 2` in messages, as in the CSV of the same rows.
    #[pyo3(signature = (q, payload_kg=None, tools=None, temp_c=None, t_s=None, torques_nm=None, inputs=None))]
    #[allow(clippy::too_many_arguments)]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        payload_kg: Option<PyReadonlyArray1<'py, f64>>,
        tools: Option<Vec<String>>,
        temp_c: Option<PyReadonlyArray1<'py, f64>>,
        t_s: Option<PyReadonlyArray1<'py, f64>>,
        torques_nm: Option<PyReadonlyArray2<'py, f64>>,
        inputs: Option<Vec<(String, PyReadonlyArray1<'py, f64>)>>,
    ) -> PyResult<Predicted<'py>> {
        let q = q.as_array();
        let (n, joints) = q.dim();
        if joints != self.model.joint_count() {
            return Err(argument("q", format!("{joints} columns, the model has {} joints", self.model.joint_count())));
        }
        let (names, signals) = self.signals(inputs, n)?;
        let payload = array_column("payload_kg", payload_kg, n)?;
        let temp = array_column("temp_c", temp_c, n)?;
        let time = array_column("t_s", t_s, n)?;
        let torques = torques_nm.map(|t| t.as_array().to_owned());
        if let Some(t) = &torques
            && t.dim() != (n, joints)
        {
            return Err(argument("torques_nm", format!("shape {:?}, expected ({n}, {joints})", t.dim())));
        }
        if let Some(tools) = &tools
            && tools.len() != n
        {
            return Err(argument("tools", format!("{} values for {n} rows", tools.len())));
        }
        let columns = RowColumns { q, payload, temp, time, torques, signals, names, tools };
        let source = "predict";
        let rows = (0..n).map(|i| columns.row(i, &self.model, source)).collect::<PyResult<Vec<_>>>()?;
        // Angles a turn away from the fitted range are taken into it, as `calib predict` does.
        let (rows, wrapped) = model::wrapped(&self.model, &rows);
        // Made here, each row's tool the model's index found above.
        self.predict_rows(py, &BoundSet::made_for_model(source, rows), &wrapped)
    }

    /// `calib compensate`: targets rewritten so that the model reaches what they mean. Returns the
    /// CSV text the CLI prints, the compensated joints `(n, joints)` (NaN where a row is refused),
    /// residuals (mm, mrad; NaN where none), each row's status, the summary (JSON) and warnings.
    #[pyo3(signature = (targets, robot=None, frame="tracker", columns=None))]
    #[allow(clippy::type_complexity)]
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        targets: PathBuf,
        robot: Option<&Robot>,
        frame: &str,
        columns: Option<Vec<(String, String)>>,
    ) -> PyResult<(
        String,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Vec<String>,
        String,
        Vec<String>,
    )> {
        let frame: cell::TargetFrame = frame.parse().map_err(|e| argument("frame", e))?;
        let columns = match columns {
            Some(pairs) if !pairs.is_empty() => {
                let text: Vec<String> =
                    pairs.iter().map(|(n, h)| format!("{n}=\"{}\"", h.replace('"', "\"\""))).collect();
                text.join(",").parse::<measurements::ColumnMap>().map_err(|e| argument("columns", e))?
            }
            _ => measurements::ColumnMap::default(),
        };
        let model = &self.model;
        let robot_ref = robot.map(|r| (&r.description, r.path.as_str()));
        let (compensated, csv) = py
            .detach(|| {
                let compensated = calib::flow::compensate(model, &targets, columns, robot_ref, frame)?;
                let mut csv = Vec::new();
                cell::write_compensated(&mut csv, &compensated.file, &compensated.solved)
                    .map_err(|source| errors::Error::io("the compensated targets", source))?;
                Ok::<_, errors::Error>((compensated, csv))
            })
            .map_err(to_py)?;
        let calib::flow::CompensatedTargets { solved, summary, warnings, .. } = compensated;
        let n = model.joint_count();
        let q: Vec<Vec<f64>> =
            solved.iter().map(|s| if s.status.is_ok() { s.q.clone() } else { vec![f64::NAN; n] }).collect();
        let residual_mm = PyArray1::from_vec(py, solved.iter().map(|s| s.residual_m * 1e3).collect());
        let residual_mrad =
            PyArray1::from_vec(py, solved.iter().map(|s| s.residual_rad.map_or(f64::NAN, |r| r * 1e3)).collect());
        let status = solved.iter().map(|s| s.status.to_string()).collect();
        let summary = serde_json::to_string(&summary).map_err(|e| argument("summary", e))?;
        let csv = String::from_utf8_lossy(&csv).into_owned();
        Ok((csv, matrix(py, q, n)?, residual_mm, residual_mrad, status, summary, warnings))
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({} of {:?}, {} joints, from {})",
            self.model.method,
            self.model.robot,
            self.model.joint_count(),
            self.name
        )
    }
}

impl Model {
    /// The model's measured signals in its order, each found by name among those `inputs` gives
    /// (refused by name where missing) and holding `n` values.
    #[allow(clippy::type_complexity)]
    fn signals(
        &self,
        inputs: Option<Vec<(String, PyReadonlyArray1<'_, f64>)>>,
        n: usize,
    ) -> PyResult<(std::sync::Arc<[String]>, Vec<Vec<f64>>)> {
        let mut given: std::collections::HashMap<String, PyReadonlyArray1<'_, f64>> =
            inputs.unwrap_or_default().into_iter().collect();
        let names = self.model.input_names();
        let mut signals = Vec::with_capacity(names.len());
        for name in &names {
            let values = given.remove(name).ok_or_else(|| {
                argument("inputs", format!("no values of '{name}', a measured signal the model takes as an input"))
            })?;
            signals.push(array_column(name, Some(values), n)?.unwrap_or_default());
        }
        Ok((names.into(), signals))
    }

    /// The prediction of `rows` as `calib predict` makes it: poses `[x_mm, y_mm, z_mm]` and, for a
    /// full-pose model, `qw, qx, qy, qz`; standard deviations in mm (and mrad); the refusal of a
    /// non-finite pose; the warnings (first the joints `wrapped` into the fitted range, as the
    /// CLI's notes).
    fn predict_rows<'py>(
        &self,
        py: Python<'py>,
        data: &BoundSet<'_>,
        wrapped: &[model::WrappedJoint],
    ) -> PyResult<Predicted<'py>> {
        let (model, name) = (&self.model, Path::new(&self.name));
        let predicted = py.detach(|| calib::flow::predict(model, name, data, wrapped)).map_err(refused)?;
        let (predictions, mut warnings) = (predicted.poses, predicted.notes);
        warnings.extend(predicted.warnings);
        let full = model.full_pose;
        let width = if full { 7 } else { 3 };
        let mut poses = Vec::with_capacity(predictions.len() * width);
        let mut sigma = Vec::with_capacity(predictions.len() * (width - 1));
        for p in &predictions {
            poses.extend((p.pose.translation() * 1e3).iter());
            if full {
                poses.extend(p.pose.rotation().to_quaternion());
            }
            if let Some(std) = p.std {
                sigma.extend(std[..if full { 6 } else { 3 }].iter().map(|s| s * 1e3));
            }
        }
        let n = predictions.len();
        let poses = PyArray1::from_vec(py, poses).reshape([n, width])?;
        let sigma = if model.predicts_std() && sigma.len() == n * (width - 1) {
            Some(PyArray1::from_vec(py, sigma).reshape([n, width - 1])?)
        } else {
            None
        };
        Ok((poses, sigma, warnings))
    }
}

/// A per-row argument's values, refused by `name` unless there are `n` of them.
fn array_column(name: &str, values: Option<PyReadonlyArray1<'_, f64>>, n: usize) -> PyResult<Option<Vec<f64>>> {
    let Some(values) = values else { return Ok(None) };
    let values = values.as_array().to_vec();
    if values.len() != n {
        return Err(argument(name, format!("{} values for {n} rows", values.len())));
    }
    Ok(Some(values))
}

/// The arguments of `predict` on arrays, their lengths checked: one value (or row) per row.
struct RowColumns<'a> {
    q: numpy::ndarray::ArrayView2<'a, f64>,
    payload: Option<Vec<f64>>,
    temp: Option<Vec<f64>>,
    time: Option<Vec<f64>>,
    torques: Option<numpy::ndarray::Array2<f64>>,
    /// The model's signals, in the order of `names`.
    signals: Vec<Vec<f64>>,
    names: std::sync::Arc<[String]>,
    tools: Option<Vec<String>>,
}

impl RowColumns<'_> {
    /// Row `i` as a measurement on the model's tool (named line `i + 2` of `source`): every value
    /// finite, the payload not negative.
    fn row(&self, i: usize, model: &CalibratedModel, source: &str) -> PyResult<Measurement> {
        let line = i as u64 + 2;
        let (payload, temp, time, torques) = (&self.payload, &self.temp, &self.time, &self.torques);
        let row_q: Vec<f64> = self.q.row(i).to_vec();
        let payload = payload.as_ref().map_or(0.0, |p| p[i]);
        let extra = [payload, temp.as_ref().map_or(0.0, |t| t[i]), time.as_ref().map_or(0.0, |t| t[i])];
        let torque_row = torques.as_ref().map(|t| t.row(i).to_vec()).unwrap_or_default();
        let signal_row: Vec<f64> = self.signals.iter().map(|s| s[i]).collect();
        if let Some(bad) = row_q.iter().chain(&extra).chain(&torque_row).chain(&signal_row).find(|v| !v.is_finite()) {
            return Err(argument("q", format!("row {i} has {bad}: every value must be finite")));
        }
        if payload < 0.0 {
            return Err(argument("payload_kg", format!("row {i} has {payload} kg: a payload is not negative")));
        }
        let tool_name = self.tools.as_ref().map_or("", |t| t[i].as_str());
        let tool = model.tool_index(tool_name, source, line, 0).map_err(to_py)?;
        Ok(Measurement {
            line,
            q: row_q,
            position: lie::Vector3::zeros(),
            orientation: None,
            payload_kg: payload,
            tool,
            temp_c: temp.as_ref().map(|t| t[i]),
            t_s: time.as_ref().map(|t| t[i]),
            torques_nm: torques.as_ref().map(|t| t.row(i).to_vec()),
            inputs: measurements::Inputs::new(self.names.clone(), signal_row),
            std: None,
        })
    }
}

/// A refusal of `eval` or `predict` as a Python exception.
fn refused(refused: Refused) -> PyErr {
    match refused {
        Refused::Error(error) => to_py(error),
        Refused::NonFinite(message) => crate::error::CalibError::new_err(message),
    }
}
