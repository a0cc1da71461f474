//! The fit of a method on a measurement set, and the evaluation of a fitted model.

use crate::geometric::fit_geometry;
use crate::{
    CalibratedModel, Compensation, CompensationOptions, CompensationReport, Error, ErrorSummary, MeasurementSet,
    Method, PoseError, RobotDescription, SCHEMA_VERSION, pose_error,
};
use poe::identify::{IdentificationOptions, IdentificationReport, Scope};
use serde::{Deserialize, Serialize};

/// Options of a fit.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FitOptions {
    /// The geometric identification.
    pub identification: IdentificationOptions,
    /// The Gaussian-process compensation (methods `poe-gp`, `poe-gp-load`).
    pub compensation: CompensationOptions,
}

/// What a fit reports besides the model.
#[derive(Debug, Clone)]
pub struct FitReport {
    /// The method fitted.
    pub method: Method,
    /// Training errors of the nominal model, registered into the tracker frame.
    pub before: ErrorSummary,
    /// Training errors of the fitted model.
    pub after: ErrorSummary,
    /// The geometric identification's report.
    pub identification: IdentificationReport,
    /// The GP stage's report, for the GP methods.
    pub compensation: Option<CompensationReport>,
}

/// Per-row errors and their summary.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// One error per row, in file order.
    pub errors: Vec<PoseError>,
    /// Their statistics.
    pub summary: ErrorSummary,
}

/// Fits `method` to `data` for `robot` (paper Section III: step 1, then step 2 for the GP
/// methods, trained on the error the identified model leaves on the same rows, Eq. 8).
pub fn fit(
    robot: &RobotDescription,
    data: &MeasurementSet,
    method: Method,
    options: &FitOptions,
) -> Result<(CalibratedModel, FitReport), Error> {
    if data.joint_count != robot.joint_count() {
        return Err(Error::JointCountMismatch {
            file: data.source.clone(),
            line: 1,
            column: 1,
            found: data.joint_count,
            expected: robot.joint_count(),
        });
    }
    let nominal = robot.nominal_model()?;
    let scope = if method == Method::BaseTool { Scope::BaseTool } else { Scope::Full };
    let geometry = fit_geometry(&nominal, data, scope, &options.identification)?;
    let mut model = CalibratedModel {
        schema_version: SCHEMA_VERSION,
        robot: robot.name.clone(),
        method,
        full_pose: data.full_pose,
        tools: data.tools.clone(),
        kinematics: geometry.model,
        compensation: None,
    };
    let mut compensation = None;
    if method.uses_gp() {
        let with_payload = method == Method::PoeGpLoad;
        let (fitted, report) = Compensation::fit(&model.kinematics, data, with_payload, &options.compensation)?;
        model.compensation = Some(fitted);
        compensation = Some(report);
    }
    let registered = CalibratedModel { kinematics: geometry.registered, compensation: None, ..model.clone() };
    let before = evaluate(&registered, data)?.summary;
    let after = evaluate(&model, data)?.summary;
    Ok((model, FitReport { method, before, after, identification: geometry.report, compensation }))
}

/// Evaluates a fitted model on measurements.
pub fn evaluate(model: &CalibratedModel, data: &MeasurementSet) -> Result<Evaluation, Error> {
    let tools = tool_indices(model, data)?;
    let predictions = model.predict(&data.rows, &tools)?;
    let errors: Vec<PoseError> = predictions.iter().zip(&data.rows).map(|(p, row)| pose_error(&p.pose, row)).collect();
    let summary = ErrorSummary::from_errors(&errors);
    Ok(Evaluation { errors, summary })
}

/// The model's tool index of every row of `data`, matched by tool identifier.
pub fn tool_indices(model: &CalibratedModel, data: &MeasurementSet) -> Result<Vec<usize>, Error> {
    if data.joint_count != model.joint_count() {
        return Err(Error::JointCountMismatch {
            file: data.source.clone(),
            line: 1,
            column: 1,
            found: data.joint_count,
            expected: model.joint_count(),
        });
    }
    let column = data.tool_column.unwrap_or(1);
    data.rows
        .iter()
        .map(|row| {
            let name = data.tools.get(row.tool).map(String::as_str).unwrap_or("");
            model.tool_index(name, &data.source, row.line, column)
        })
        .collect()
}
