//! The fit of a method on a measurement set, and the evaluation of a fitted model.

use crate::geometric::{fit_geometry, observations};
use crate::load_model::ComplianceCorrection;
use crate::{
    CalibratedModel, Compensation, CompensationOptions, CompensationReport, ComplianceModel, Error, ErrorSummary,
    MeasurementSet, Method, PoseError, RobotDescription, SCHEMA_VERSION, pose_error,
};
use poe::identify::{IdentificationOptions, IdentificationReport, ParameterMask, Scope, identify_with_correction};
use serde::{Deserialize, Serialize};

/// Options of a fit.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FitOptions {
    /// The geometric identification.
    pub identification: IdentificationOptions,
    /// The Gaussian-process compensation (methods `poe-gp`, `poe-gp-load`).
    pub compensation: CompensationOptions,
    /// Identify joint compliance together with the geometry, through gravity-torque regressors
    /// (no masses needed), before any GP. Beyond the paper.
    pub joint_compliance: bool,
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
    data.check_joints(&robot.joint_kinds())?;
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
        joint_compliance: None,
        compensation: None,
    };
    let mut identification = geometry.report;
    if options.joint_compliance {
        let mut compliance = ComplianceModel::terms(robot, model.kinematics.tools(), data)?;
        let correction = ComplianceCorrection {
            terms: &compliance.terms,
            regressors: data.rows.iter().map(|row| compliance.regressors(row)).collect::<Result<_, _>>()?,
            q: data.rows.iter().map(|row| row.q.clone()).collect(),
        };
        let layout = model.kinematics.layout();
        let mask = if scope == Scope::BaseTool { ParameterMask::base_tool(layout) } else { ParameterMask::all(layout) };
        let observations = observations(data);
        // The torque regressors of neighbouring links are nearly collinear; directions kept at
        // 1e-9 of the largest singular value made the iterations crawl (50 without converging on
        // 250 position-only poses, 0.20 mm held-out), at 1e-6 they converge in 20 to the noise
        // floor (0.027 mm). The geometric directions sit far above it (condition numbers to 1e5).
        let id_options =
            IdentificationOptions { rcond: options.identification.rcond.max(1e-6), ..options.identification.clone() };
        let fitted = identify_with_correction(&model.kinematics, &observations, &mask, Some(&correction), &id_options)?;
        compliance.theta = fitted.correction;
        model.kinematics = fitted.model;
        model.joint_compliance = Some(compliance);
        identification = fitted.report;
    }
    let mut compensation = None;
    if method.uses_gp() {
        let with_payload = method == Method::PoeGpLoad;
        let tools: Vec<usize> = data.rows.iter().map(|r| r.tool).collect();
        let poses = model.geometric_poses(&data.rows, &tools)?;
        let (fitted, report) = Compensation::fit(&poses, data, with_payload, &options.compensation)?;
        model.compensation = Some(fitted);
        compensation = Some(report);
    }
    let registered = CalibratedModel {
        kinematics: geometry.registered,
        joint_compliance: None,
        compensation: None,
        ..model.clone()
    };
    let before = evaluate(&registered, data)?.summary;
    let after = evaluate(&model, data)?.summary;
    Ok((model, FitReport { method, before, after, identification, compensation }))
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
