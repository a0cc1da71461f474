//! `diagnose` and `simulate`: what `calib diagnose` and `calib simulate` do.

use crate::error::{argument, to_py};
use crate::robot::Robot;
use crate::types::Measurements;
use ::diagnose::DiagnoseOptions;
use calib::flow::{CampaignShape, ShapeFault};
use errors::{Error, ErrorKind};
use measurements::ReadOptions;
use pyo3::prelude::*;
use std::path::PathBuf;

/// `calib diagnose --json`: the diagnosis's JSON text, the summary the CLI prints, and the path of
/// the markdown report where `report` names a folder.
#[pyfunction]
#[pyo3(signature = (robot, data, noise_mm=None, folds=5, seed=0, report=None))]
pub fn diagnose(
    py: Python<'_>,
    robot: &Robot,
    data: &Measurements,
    noise_mm: Option<f64>,
    folds: usize,
    seed: u64,
    report: Option<PathBuf>,
) -> PyResult<(String, String, Option<String>)> {
    if let Some(noise) = noise_mm
        && !(noise.is_finite() && noise > 0.0)
    {
        return Err(argument("noise_mm", format!("must be a positive number of millimetres, got {noise}")));
    }
    let options = DiagnoseOptions { folds, seed, noise_mm, ..DiagnoseOptions::default() };
    let (description, set) = (&robot.description, &data.set);
    let robot_path = PathBuf::from(&robot.path);
    let data_path = PathBuf::from(&set.source);
    py.detach(|| {
        let inputs = measurements::InputFiles::new().with("robot", &robot_path).with("data", &data_path);
        // The folder `calib diagnose --report` writes, through the report crate's one writer.
        let folder = report.as_deref().map(|folder| (folder, "report", &inputs));
        let (diagnosis, written) = calib::flow::diagnose(description, set, &options, folder).map_err(|e| {
            match (e.kind(), &report) {
                // A chart or the embedded JSON (only the report's writer raises them): named by
                // the folder they were for, as before the report crate had an error type of its own.
                (errors::ErrorKind::Plot { .. } | errors::ErrorKind::EvaluationJson { .. }, Some(folder)) => {
                    errors::Error::io(folder.display().to_string(), std::io::Error::other(e.to_string()))
                }
                _ => e,
            }
        })?;
        Ok((diagnosis.to_json()?, diagnosis.summary(), written.map(|p| p.display().to_string())))
    })
    .map_err(to_py)
}

/// `calib simulate`: the campaign as the CSV text the CLI writes, read back by the same reader
/// (so that a fit on it equals a fit on the CLI's file), and written to `out` where given.
#[pyfunction]
#[pyo3(signature = (
    robot, rows=300, seed=0, full_pose=false, effects=None, payloads=None, moving_joints=None,
    fixed_jitter_mrad=None, runs=false, tool_per_payload=false, torques=false, torque_sigma_nm=None, out=None
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    py: Python<'_>,
    robot: &Robot,
    rows: usize,
    seed: u64,
    full_pose: bool,
    effects: Option<PathBuf>,
    payloads: Option<Vec<f64>>,
    moving_joints: Option<Vec<usize>>,
    fixed_jitter_mrad: Option<f64>,
    runs: bool,
    tool_per_payload: bool,
    torques: bool,
    torque_sigma_nm: Option<f64>,
    out: Option<PathBuf>,
) -> PyResult<Measurements> {
    if rows > campaign::MAX_ROWS {
        return Err(argument("rows", Error::new(ErrorKind::TooManySimulatedRows { rows, max: campaign::MAX_ROWS })));
    }
    if rows == 0 {
        return Err(argument("rows", "at least one pose is needed"));
    }
    let description = &robot.description;
    let effects = match &effects {
        Some(path) => campaign::read_effects(path, description).map_err(to_py)?,
        None => campaign::paper_effects(),
    };
    let shape =
        CampaignShape { payloads, moving_joints, fixed_jitter_mrad, runs, tool_per_payload, torques, torque_sigma_nm };
    // The flags' checks, each refusal naming the keyword argument.
    let config = shape.config(rows, seed).map_err(|fault| match fault {
        ShapeFault::JointZero => argument("moving_joints", "joints are numbered from 1"),
        ShapeFault::JitterWithoutMovingJoints => {
            argument("fixed_jitter_mrad", "needs moving_joints (only joints that do not move are held)")
        }
        ShapeFault::Jitter(jitter) => argument("fixed_jitter_mrad", format!("{jitter} is not a non-negative number")),
        ShapeFault::SigmaWithoutTorques => argument("torque_sigma_nm", "needs torques=True"),
        ShapeFault::Sigma(sigma) => argument("torque_sigma_nm", format!("{sigma} is not a non-negative number")),
    })?;
    let source = out.as_ref().map_or_else(|| "simulated".to_owned(), |p| p.display().to_string());
    py.detach(|| {
        let mut csv = Vec::new();
        calib::flow::simulate(description, &robot.path, &effects, &config, full_pose, &mut csv, &source)?;
        if let Some(path) = &out {
            measurements::write_file(path, &csv)?;
        }
        let options = ReadOptions::for_joints(description.joint_kinds());
        Measurements::parse(&csv, &source, &options)
    })
    .map_err(to_py)
}
