//! A calibrated model: the identified kinematics, the optional GP compensation, and prediction.

use crate::effects::IdentifiedEffect;
use crate::{Error, Measurement, Method, PoseError};
use lie::SE3;
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// What `calib fit` produces and `calib eval` / `calib predict` use.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CalibratedModel {
    /// Version of this file layout ([`crate::SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// Name of the robot description the fit started from.
    pub robot: String,
    /// The method that produced the model.
    pub method: Method,
    /// Whether the model was fitted on full-pose data (otherwise orientation is not calibrated).
    pub full_pose: bool,
    /// Tool identifiers, in the order of the kinematic model's tools.
    pub tools: Vec<String>,
    /// The identified local POE model; its reference frame is the tracker frame.
    pub kinematics: LocalPoe,
    /// Non-geometric effects identified with the geometry (`calib fit --effects`), applied after
    /// it and before the GP, in one left exponential of the sum of their twists.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<IdentifiedEffect>,
    /// The GP compensation of the residual (methods `poe-gp`, `poe-gp-load`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compensation: Option<crate::Compensation>,
}

/// A predicted tool pose and, where a GP is part of the model, its standard deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictedPose {
    /// `tracker_from_tool`.
    pub pose: SE3,
    /// GP standard deviation of the six pose-error components `(v, ω)` (metres, radians).
    pub std: Option<[f64; 6]>,
}

impl CalibratedModel {
    /// Number of joints of the robot.
    pub fn joint_count(&self) -> usize {
        self.kinematics.joint_count()
    }

    /// The kinds of the joints, base first.
    pub fn joint_kinds(&self) -> Vec<poe::JointKind> {
        self.kinematics.joints().iter().map(|j| j.kind).collect()
    }

    /// Index of a tool by its identifier. `""` is the default tool (a blank `tool` cell, or a
    /// file without the column), matched like any other name, as in the fit (SPEC v2); an
    /// identifier the model was not fitted with is refused.
    pub fn tool_index(&self, name: &str, file: &str, line: u64, column: usize) -> Result<usize, Error> {
        self.tools.iter().position(|t| t == name).ok_or_else(|| Error::UnknownTool {
            file: file.to_owned(),
            line,
            column,
            tool: name.to_owned(),
            known: self.tools.clone(),
        })
    }

    /// The model without its non-geometric parts (joint compliance, the GP): the geometry alone,
    /// which is what a URDF can hold (`calib export`).
    pub fn geometry_only(&self) -> CalibratedModel {
        CalibratedModel { effects: Vec::new(), compensation: None, ..self.clone() }
    }

    /// The names of the parts besides the geometry, in the order they apply.
    pub fn non_geometric_parts(&self) -> Vec<String> {
        let mut parts: Vec<String> = self.effects.iter().map(IdentifiedEffect::label).collect();
        if self.compensation.is_some() {
            parts.push("gaussian_process".into());
        }
        parts
    }

    /// The poses of the kinematics moved by the effects, before any GP.
    pub fn geometric_poses(&self, rows: &[Measurement], tools: &[usize]) -> Result<Vec<SE3>, Error> {
        let mut poses = Vec::with_capacity(rows.len());
        for (row, &tool) in rows.iter().zip(tools) {
            let pose = self.kinematics.forward(&row.q, tool)?;
            poses.push(crate::effects::apply(&self.effects, &self.kinematics, row, tool, pose)?);
        }
        Ok(poses)
    }

    /// Predicts the tool pose of rows of a measurement set, with the GP placed before the POE
    /// model as in the paper's Eq. 9: `T = exp(ĝ(q, m)) · T_POE(q)`.
    pub fn predict(&self, rows: &[Measurement], tools: &[usize]) -> Result<Vec<PredictedPose>, Error> {
        let poses = self.geometric_poses(rows, tools)?;
        match &self.compensation {
            None => Ok(poses.into_iter().map(|pose| PredictedPose { pose, std: None }).collect()),
            Some(compensation) => {
                let corrections = compensation.predict(rows, &poses)?;
                Ok(poses
                    .into_iter()
                    .zip(corrections)
                    .map(|(pose, (g, std))| PredictedPose { pose: g * pose, std: Some(std) })
                    .collect())
            }
        }
    }
}

/// The error of a prediction against a measured row.
pub fn pose_error(predicted: &SE3, row: &Measurement) -> PoseError {
    PoseError {
        position_mm: (row.position - predicted.translation()).norm() * 1e3,
        rotation_mrad: row.orientation.map(|measured| (measured * predicted.rotation().inverse()).log().norm() * 1e3),
    }
}
