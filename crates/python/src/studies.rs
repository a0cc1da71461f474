//! `diagnose` and `simulate`: what `calib diagnose` and `calib simulate` do.

use crate::error::{argument, to_py};
use crate::robot::Robot;
use crate::types::Measurements;
use ::diagnose::DiagnoseOptions;
use campaign::{GeneratorConfig, Perturbation, Remount, TorqueSensorNoise};
use errors::Error;
use measurements::ReadOptions;
use pyo3::prelude::*;
use report::ErrorKind;
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
    // As the CLI, which reads the data against the robot's joints: bound once, here.
    let bound = measurements::BoundSet::to_robot(set, &description.joint_kinds()).map_err(to_py)?;
    let robot_path = PathBuf::from(&robot.path);
    let data_path = PathBuf::from(&set.source);
    py.detach(|| {
        let diagnosis = ::diagnose::diagnose_bound(description, &bound, &options)?;
        let inputs = measurements::InputFiles::new().with("robot", &robot_path).with("data", &data_path);
        // The folder `calib diagnose --report` writes, through the report crate's one writer.
        let written = report
            .as_deref()
            .map(|folder| {
                report::write_diagnosis_report(&diagnosis, folder, "report", &inputs).map_err(|e| {
                    match e.kind::<ErrorKind>() {
                        // A chart or the embedded JSON: named by the folder they were for, as before the
                        // report crate had an error type of its own.
                        Some(ErrorKind::Plot { .. } | ErrorKind::EvaluationJson { .. }) => {
                            errors::Error::io(folder.display().to_string(), std::io::Error::other(e.to_string()))
                        }
                        _ => e,
                    }
                })
            })
            .transpose()?;
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
        return Err(argument(
            "rows",
            Error::new(campaign::ErrorKind::TooManySimulatedRows { rows, max: campaign::MAX_ROWS }),
        ));
    }
    if rows == 0 {
        return Err(argument("rows", "at least one pose is needed"));
    }
    let description = &robot.description;
    let effects = match &effects {
        Some(path) => campaign::read_effects(path, description).map_err(to_py)?,
        None => campaign::paper_effects(),
    };
    let shape = Shape { payloads, moving_joints, fixed_jitter_mrad, runs, tool_per_payload, torques, torque_sigma_nm };
    let config = shape.config(rows, seed)?;
    if config.moving_joints.is_empty()
        && let Some(direction) = description.planar_direction()
    {
        let file = robot.path.clone();
        return Err(to_py(Error::in_file(
            file,
            campaign::ErrorKind::PlanarChain { direction, joints: description.joint_count() },
        )));
    }
    let source = out.as_ref().map_or_else(|| "simulated".to_owned(), |p| p.display().to_string());
    py.detach(|| {
        let cell = campaign::campaign_cell(description, &Perturbation::default(), &Remount::default(), &config)?;
        let mut csv = Vec::new();
        campaign::simulate_to_csv(
            &cell,
            &effects,
            &campaign::joint_ranges(description),
            &config,
            full_pose,
            &mut csv,
            &source,
        )?;
        if let Some(path) = &out {
            measurements::write_file(path, &csv)?;
        }
        let options = ReadOptions::for_joints(description.joint_kinds());
        Measurements::parse(&csv, &source, &options)
    })
    .map_err(to_py)
}

/// The campaign's shape, as `calib simulate`'s flags give it.
struct Shape {
    payloads: Option<Vec<f64>>,
    moving_joints: Option<Vec<usize>>,
    fixed_jitter_mrad: Option<f64>,
    runs: bool,
    tool_per_payload: bool,
    torques: bool,
    torque_sigma_nm: Option<f64>,
}

impl Shape {
    /// The generator's configuration, checked as `crates/calib/src/simulate.rs` checks the flags.
    fn config(self, rows: usize, seed: u64) -> PyResult<GeneratorConfig> {
        let defaults = GeneratorConfig::default();
        let payloads_kg = self.payloads.unwrap_or_else(|| defaults.payloads_kg.clone());
        let mut moving_joints = Vec::new();
        for joint in self.moving_joints.into_iter().flatten() {
            if joint == 0 {
                return Err(argument("moving_joints", "joints are numbered from 1"));
            }
            moving_joints.push(joint - 1);
        }
        moving_joints.sort_unstable();
        moving_joints.dedup();
        if self.fixed_jitter_mrad.is_some() && moving_joints.is_empty() {
            return Err(argument("fixed_jitter_mrad", "needs moving_joints (only joints that do not move are held)"));
        }
        let jitter = self.fixed_jitter_mrad.unwrap_or(0.0);
        if !(jitter.is_finite() && jitter >= 0.0) {
            return Err(argument("fixed_jitter_mrad", format!("{jitter} is not a non-negative number")));
        }
        if self.torque_sigma_nm.is_some() && !self.torques {
            return Err(argument("torque_sigma_nm", "needs torques=True"));
        }
        if let Some(sigma) = self.torque_sigma_nm.filter(|s| !(s.is_finite() && *s >= 0.0)) {
            return Err(argument("torque_sigma_nm", format!("{sigma} is not a non-negative number")));
        }
        let torque_sensor = self.torques.then(|| match self.torque_sigma_nm {
            Some(sigma_nm) => TorqueSensorNoise { sigma_nm, ..TorqueSensorNoise::default() },
            None => TorqueSensorNoise::default(),
        });
        Ok(GeneratorConfig {
            sample_count: rows,
            seed,
            payloads_kg,
            moving_joints,
            fixed_jitter_rad: jitter * 1e-3,
            payload_runs: self.runs || self.tool_per_payload,
            tool_per_run: self.tool_per_payload,
            torque_sensor,
            ..defaults
        })
    }
}
