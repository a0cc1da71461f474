//! The calibrated model as a file: RON with a schema version, written atomically.

use crate::CalibratedModel;
use crate::ErrorKind;
use errors::{CommonKind, Error};
use std::path::Path;

/// The schema version this build writes. Version 2 holds the non-geometric effects as a list
/// (`effects`); version 1 files, whose only effect was `joint_compliance`, still read.
pub const SCHEMA_VERSION: u32 = 2;

/// Writes `model` to `path` as RON, atomically ([`measurements::write_file`]): a crash never leaves a
/// half-written model behind, and a symbolic link at `path` keeps pointing at the new model.
pub fn write_model(path: &Path, model: &CalibratedModel) -> Result<(), Error> {
    let mut text = model_text(model, &path.display().to_string())?;
    text.push('\n');
    measurements::write_file(path, text.as_bytes())
}

/// The text [`write_model`] writes; `file` names it in errors.
pub fn model_text(model: &CalibratedModel, file: &str) -> Result<String, Error> {
    ron::ser::to_string_pretty(model, ron::ser::PrettyConfig::default().depth_limit(6))
        .map_err(|e| Error::at_line(file.to_owned(), 1, 1, CommonKind::RonFormat { message: e.to_string() }))
}

/// Reads a calibrated model, refusing a file of another schema version.
pub fn read_model(path: &Path) -> Result<CalibratedModel, Error> {
    let text = errors::ron_position::read_text(path)?;
    parse_model(&text, &path.display().to_string())
}

/// Parses a calibrated model from RON text and checks that its parts fit together
/// ([`CalibratedModel::check`]); `file` names it in errors.
pub fn parse_model(text: &str, file: &str) -> Result<CalibratedModel, Error> {
    #[derive(serde::Deserialize)]
    struct Version {
        schema_version: u32,
    }
    let position_error = |e: ron::error::SpannedError| Error::ron(file, &e);
    // Read the version alone first so that a model from another version is refused with that
    // reason rather than with whichever field changed.
    let options = errors::ron_position::ron_options();
    let version: Version = match options.from_str::<ron::Value>(text) {
        Ok(value) => value.into_rust().map_err(|e| {
            Error::at_line(file.to_owned(), 1, 1, CommonKind::RonFormat { message: format!("no schema_version: {e}") })
        })?,
        Err(e) => return Err(position_error(e)),
    };
    let model: CalibratedModel = match version.schema_version {
        1 => options.from_str::<version_1::Model>(text).map_err(position_error)?.into(),
        SCHEMA_VERSION => options.from_str(text).map_err(position_error)?,
        found => {
            return Err(Error::at_line(
                file.to_owned(),
                1,
                1,
                ErrorKind::SchemaVersion { found, supported: SCHEMA_VERSION },
            ));
        }
    };
    model.check(text, file)?;
    Ok(model)
}

/// The version-1 layout: the same model with joint compliance as its only possible effect.
mod version_1 {
    use crate::{CalibratedModel, Method, ResidualGp, SCHEMA_VERSION};
    use effects::{ComplianceParameter, ComplianceTorque, IdentifiedEffect, JointComplianceTerm, LoadFrame};
    use poe::LocalPoe;
    use serde::Deserialize;

    #[derive(Deserialize)]
    pub(super) struct Compliance {
        base_model: LocalPoe,
        gravity_m_per_s2: [f64; 3],
        terms: Vec<ComplianceParameter>,
        theta: Vec<f64>,
    }

    #[derive(Deserialize)]
    pub(super) struct Model {
        #[allow(dead_code)]
        schema_version: u32,
        robot: String,
        method: Method,
        full_pose: bool,
        tools: Vec<String>,
        kinematics: LocalPoe,
        #[serde(default)]
        joint_compliance: Option<Compliance>,
        #[serde(default, rename = "compensation")]
        residual_gp: Option<ResidualGp>,
    }

    impl From<Model> for CalibratedModel {
        fn from(v1: Model) -> Self {
            let effects = v1
                .joint_compliance
                .map(|c| {
                    let load = LoadFrame { base_model: c.base_model, gravity_m_per_s2: c.gravity_m_per_s2 };
                    IdentifiedEffect::JointCompliance(JointComplianceTerm {
                        torque: ComplianceTorque::GravityRegressor(load),
                        terms: c.terms,
                        theta: c.theta,
                        payload_span: None,
                    })
                })
                .into_iter()
                .collect();
            CalibratedModel {
                schema_version: SCHEMA_VERSION,
                robot: v1.robot,
                method: v1.method,
                full_pose: v1.full_pose,
                tools: v1.tools,
                kinematics: v1.kinematics,
                effects,
                fallback_kinematics: None,
                effect_uncertainty: None,
                geometry_uncertainty: None,
                residual_gp: v1.residual_gp,
                training_range: None,
                joint_limits: Vec::new(),
                heldout: None,
                fit_warnings: None,
                robot_description: None,
            }
        }
    }
}
