//! What `calib eval --json` prints: one typed object with the SPEC's keys (`n`,
//! `mean_position_error_mm`, `rms_position_error_mm`, `max_position_error_mm`, and for
//! full-pose data and a model fitted on it `mean_rotation_error_mrad`) and what identifies the run.

use crate::Evaluation;
use crate::{CalibratedModel, ErrorSummary, ExtrapolationWarning, Method, PoseError};
use measurements::{FileFormat, MeasurementSet};
use serde::Serialize;

/// What `eval` says when the data has orientations that a position-only model cannot be judged on.
pub const ORIENTATIONS_NOT_EVALUATED: &str =
    "the model was fitted on positions only: orientations in the data are not evaluated";

/// The evaluation of a model on one measurement file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvalReport {
    /// The model's method.
    pub method: Method,
    /// The robot the model was fitted for.
    pub robot: String,
    /// The measurement file.
    pub data: String,
    /// Whether the rotation errors are given: the data has orientations and the model was
    /// fitted on them.
    pub full_pose: bool,
    /// The data has orientations but the model was fitted on positions only: they are not
    /// evaluated (see [`ORIENTATIONS_NOT_EVALUATED`]).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub orientations_not_evaluated: bool,
    /// The error statistics, at the top level of the object.
    #[serde(flatten)]
    pub errors: ErrorSummary,
    /// How the measurement file was written.
    pub format: FileFormat,
    /// The errors on the rows inside the model's coverage (every effect's joint within the
    /// angles it was fitted on) and on the others, apart: the model is on firm ground only on
    /// the first. `None` for a model without effects that record their angles.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coverage: Option<CoverageSplit>,
    /// Effects used outside the joint angles they were fitted on.
    pub warnings: Vec<ExtrapolationWarning>,
    /// Inputs (joints, payload, temperature, time) outside the range the model was fitted on,
    /// for every model that records it.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub out_of_range: Vec<crate::OutOfRangeWarning>,
    /// Joints beyond the robot's limits, for every model that keeps them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub beyond_joint_limits: Vec<crate::BeyondLimitsWarning>,
    /// Revolute joints whose angles some rows had wrapped by whole turns into the range the model
    /// was fitted on before it was applied ([`crate::wrapped`], as `calib register` does); empty
    /// where none was (and left out of the JSON).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub wrapped: Vec<crate::WrappedJoint>,
}

/// The errors inside and outside a model's coverage.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CoverageSplit {
    /// Rows whose every effect is within the angles it was fitted on.
    pub inside: ErrorSummary,
    /// The other rows: there the effects fade out and the model falls back to the geometry.
    pub outside: ErrorSummary,
}

impl EvalReport {
    /// The report of `evaluation`, the result of `model` on `data`.
    pub fn new(model: &CalibratedModel, data: &MeasurementSet, evaluation: &Evaluation) -> Self {
        Self {
            method: model.method,
            robot: model.robot.clone(),
            data: data.source.clone(),
            full_pose: data.full_pose && model.full_pose,
            orientations_not_evaluated: data.full_pose && !model.full_pose,
            errors: evaluation.summary,
            format: data.format.clone(),
            coverage: model.records_coverage().then(|| {
                let (inside, outside): (Vec<_>, Vec<_>) =
                    data.rows.iter().zip(&evaluation.errors).partition(|(row, _)| model.covers(row));
                let summary = |part: Vec<(_, &PoseError)>| {
                    ErrorSummary::from_errors(&part.into_iter().map(|(_, e)| *e).collect::<Vec<_>>())
                };
                CoverageSplit { inside: summary(inside), outside: summary(outside) }
            }),
            warnings: model.extrapolation(&data.rows),
            out_of_range: model.outside_training_range(&data.rows),
            beyond_joint_limits: model.beyond_joint_limits(&data.rows),
            wrapped: Vec::new(),
        }
    }
}
