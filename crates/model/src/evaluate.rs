//! A calibrated model evaluated on measurements: one error per row and their summary.

use crate::{CalibratedModel, ErrorSummary, PoseError, pose_error};
use errors::Error;
use measurements::MeasurementSet;

/// Per-row errors and their summary.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// One error per row, in file order.
    pub errors: Vec<PoseError>,
    /// Their statistics.
    pub summary: ErrorSummary,
}

/// Evaluates a fitted model on measurements. A model fitted on positions only has no rotation
/// errors, whatever the data holds: it never calibrated the tool's orientation, so the angle it
/// would report is that of an uncalibrated frame, not an error of the fit.
pub fn evaluate(model: &CalibratedModel, data: &MeasurementSet) -> Result<Evaluation, Error> {
    let tools = tool_indices(model, data)?;
    let predictions = model.predict(&data.rows, &tools)?;
    let errors: Vec<PoseError> = predictions
        .iter()
        .zip(&data.rows)
        .map(|(p, row)| {
            let error = pose_error(&p.pose, row);
            if model.full_pose { error } else { PoseError { rotation_mrad: None, ..error } }
        })
        .collect();
    let summary = ErrorSummary::from_errors(&errors);
    Ok(Evaluation { errors, summary })
}

/// The model's tool index of every row of `data`, matched by tool identifier.
pub fn tool_indices(model: &CalibratedModel, data: &MeasurementSet) -> Result<Vec<usize>, Error> {
    data.check_joints(&model.joint_kinds())?;
    let column = data.tool_column.unwrap_or(1);
    data.rows
        .iter()
        .map(|row| {
            let name = data.tools.get(row.tool).map(String::as_str).unwrap_or("");
            model.tool_index(name, &data.source, row.line, column)
        })
        .collect()
}
