//! What `calib eval --json` prints: one typed object with the SPEC's keys (`n`,
//! `mean_position_error_mm`, `rms_position_error_mm`, `max_position_error_mm`, and for
//! full-pose data `mean_rotation_error_mrad`) and what identifies the run.

use crate::{CalibratedModel, ErrorSummary, Evaluation, ExtrapolationWarning, FileFormat, MeasurementSet, Method};
use serde::Serialize;

/// The evaluation of a model on one measurement file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvalReport {
    /// The model's method.
    pub method: Method,
    /// The robot the model was fitted for.
    pub robot: String,
    /// The measurement file.
    pub data: String,
    /// Whether the data has orientations (then the rotation errors are given).
    pub full_pose: bool,
    /// The error statistics, at the top level of the object.
    #[serde(flatten)]
    pub errors: ErrorSummary,
    /// How the measurement file was written.
    pub format: FileFormat,
    /// Effects used outside the joint angles they were fitted on.
    pub warnings: Vec<ExtrapolationWarning>,
}

impl EvalReport {
    /// The report of `evaluation`, the result of `model` on `data`.
    pub fn new(model: &CalibratedModel, data: &MeasurementSet, evaluation: &Evaluation) -> Self {
        Self {
            method: model.method,
            robot: model.robot.clone(),
            data: data.source.clone(),
            full_pose: data.full_pose,
            errors: evaluation.summary,
            format: data.format.clone(),
            warnings: model.extrapolation(&data.rows),
        }
    }
}
