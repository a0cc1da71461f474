//! A calibrated model evaluated on measurements: one error per row and their summary.

use crate::{CalibratedModel, ErrorSummary, PoseError, pose_error};
use errors::Error;
use lie::SE3;
use measurements::BoundSet;

/// Per-row errors and their summary.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// One error per row, in file order.
    pub errors: Vec<PoseError>,
    /// Their statistics.
    pub summary: ErrorSummary,
    /// Each row's predicted tool pose (tracker frame), in file order.
    pub poses: Vec<SE3>,
}

/// Evaluates a fitted model on measurements bound to it ([`CalibratedModel::bind`]). A model fitted on positions only has no rotation
/// errors, whatever the data holds: it never calibrated the tool's orientation, so the angle it
/// would report is that of an uncalibrated frame, not an error of the fit.
pub fn evaluate(model: &CalibratedModel, data: &BoundSet<'_>) -> Result<Evaluation, Error> {
    let predictions = model.predict(data)?;
    let errors: Vec<PoseError> = predictions
        .iter()
        .zip(data.rows())
        .map(|(p, row)| {
            let error = pose_error(&p.pose, row);
            if model.full_pose { error } else { PoseError { rotation_mrad: None, ..error } }
        })
        .collect();
    let summary = ErrorSummary::from_errors(&errors);
    Ok(Evaluation { errors, summary, poses: predictions.iter().map(|p| p.pose).collect() })
}
