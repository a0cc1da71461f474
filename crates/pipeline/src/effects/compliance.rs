//! Joint compliance: each joint turns by `δq_j = c_j τ_j` under the torque it carries (the paper's
//! ref. \[15\]; `loadsim::compliance_deflection`). With measured torques (`tauN_nm`) that is one
//! parameter per joint. Without them the gravity torque is linear in the links' unknown mass
//! moments, `τ_j = Y_j(q) π + τ_payload,j(q, m)` (`loadsim::gravity_regressor`), so the deflection
//! is linear in the products `c_j π_l` and in `c_j`: one parameter per entry of `Y`'s row `j` that
//! is not zero on every row, and one for the payload; no masses needed.

use super::{LoadFrame, Regressor, rms_scales};

use crate::effects::Direction;
use crate::{Error, Measurement};
use serde::{Deserialize, Serialize};

/// Which torque drives the deflection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ComplianceTorque {
    /// The measured joint torques of each row (`tauN_nm`).
    Measured,
    /// The gravity-torque regressors of the nominal arm, with the payload's torque.
    GravityRegressor(LoadFrame),
}

/// One parameter: one joint's deflection per unit of one torque regressor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ComplianceTerm {
    /// 0-based joint whose deflection the term drives.
    pub joint: usize,
    /// Column of the gravity regressor `Y` (4 per link), or `4n` for the payload torque; 0 for a
    /// measured torque.
    pub column: usize,
    /// The regressor is divided by this (its RMS on the training poses), so that the parameters
    /// are comparable in size: each is the joint's deflection, rad, at an RMS torque.
    pub scale: f64,
}

/// Joint compliance, identified with the geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointCompliance {
    /// The torque that drives the deflection.
    pub torque: ComplianceTorque,
    /// The parameters' meaning.
    pub terms: Vec<ComplianceTerm>,
    /// Their values: radians of deflection per unit of the scaled regressor.
    pub theta: Vec<f64>,
}

impl JointCompliance {
    /// The terms of `joints` (0-based) seen on `rows` driven by `torque`: every regressor that is
    /// not zero on every row.
    pub(crate) fn new(
        torque: ComplianceTorque,
        joints: &[usize],
        rows: &[Measurement],
        tools: &[usize],
    ) -> Result<Self, Error> {
        let mut model = Self { torque, terms: Vec::new(), theta: Vec::new() };
        let raw: Vec<Vec<Vec<f64>>> =
            rows.iter().zip(tools).map(|(row, &tool)| model.torques(row, tool)).collect::<Result<_, _>>()?;
        for &joint in joints {
            let width = raw.first().and_then(|r| r.get(joint)).map_or(0, Vec::len);
            for column in 0..width {
                let values: Vec<Vec<f64>> = raw.iter().map(|r| vec![r[joint][column]]).collect();
                // Columns that vanish on every pose (joint 1's vertical axis, a payload of zero
                // throughout) carry nothing.
                if values.iter().any(|v| v[0].abs() > 1e-12) {
                    let scale = rms_scales(&values)[0];
                    model.terms.push(ComplianceTerm { joint, column, scale });
                }
            }
        }
        model.theta = vec![0.0; model.terms.len()];
        Ok(model)
    }

    /// The torque regressors of one row, joint by joint (one column for measured torques).
    fn torques(&self, row: &Measurement, tool: usize) -> Result<Vec<Vec<f64>>, Error> {
        match &self.torque {
            ComplianceTorque::Measured => match &row.torques_nm {
                Some(tau) => Ok(tau.iter().map(|t| vec![*t]).collect()),
                None => Err(Error::EffectNeedsColumn { line: row.line, effect: "joint_compliance", column: "tau1_nm" }),
            },
            ComplianceTorque::GravityRegressor(load) => load.regressors(row, tool),
        }
    }

    /// The 0-based joints the terms act on, ascending.
    pub fn joints(&self) -> Vec<usize> {
        let mut joints: Vec<usize> = self.terms.iter().map(|t| t.joint).collect();
        joints.dedup();
        joints
    }
}

impl Regressor for JointCompliance {
    fn directions(&self) -> Vec<Direction> {
        self.terms.iter().map(|t| Direction::Joint(t.joint)).collect()
    }

    fn features(&self, row: &Measurement, tool: usize) -> Result<Vec<f64>, Error> {
        let torques = self.torques(row, tool)?;
        self.terms
            .iter()
            .map(|t| {
                let value = torques
                    .get(t.joint)
                    .and_then(|r| r.get(t.column))
                    .copied()
                    .ok_or(Error::EffectJoint { joint: t.joint + 1, joint_count: torques.len() })?;
                Ok(value / t.scale)
            })
            .collect()
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }
}
