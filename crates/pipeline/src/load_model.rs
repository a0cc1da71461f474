//! Beyond the paper: joint compliance identified together with the geometry, without knowing the
//! masses. Each joint turns by `δq_j = c_j τ_j(q, m)`; the gravity torque is linear in the links'
//! unknown mass moments, `τ_j = Y_j(q) π + m J_{p,j}(q)ᵀ g` (`loadsim::gravity_regressor`), so the
//! deflection is linear in the products `c_j π_l` and in `c_j`: one parameter per non-zero entry of
//! `Y`'s row `j`, plus one for the payload. The pose moves by `exp(Σ_j S_j(q) δq_j) T(q)`, a
//! [`poe::identify::PoseCorrection`] identified jointly with the local POE parameters.

use crate::{Error, Measurement, MeasurementSet, RobotDescription};
use lie::{SE3, Twist, Vector3, Vector6};
use loadsim::Payload;
use poe::LocalPoe;
use poe::identify::PoseCorrection;
use serde::{Deserialize, Serialize};

/// One parameter: a regressor of one joint's torque.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ComplianceTerm {
    /// 0-based joint whose deflection the term drives.
    pub joint: usize,
    /// Column of the gravity regressor `Y` (4 per link), or `4n` for the payload torque.
    pub column: usize,
    /// The regressor is divided by this (its RMS on the training poses), so that the parameters
    /// are comparable in size.
    pub scale: f64,
}

/// Identified joint compliance, stored in the model file.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ComplianceModel {
    /// The nominal arm in the robot's base frame (where gravity is known), with the calibrated
    /// tools: it gives the torque regressors.
    pub base_model: LocalPoe,
    /// Gravity in the base frame, m/s².
    pub gravity_m_per_s2: [f64; 3],
    /// The parameters' meaning.
    pub terms: Vec<ComplianceTerm>,
    /// Their identified values: radians of deflection per unit of the scaled regressor.
    pub theta: Vec<f64>,
}

impl ComplianceModel {
    /// The terms for `robot` seen on `data`: every joint's non-zero torque regressors.
    pub(crate) fn terms(robot: &RobotDescription, tools: &[SE3], data: &MeasurementSet) -> Result<Self, Error> {
        let mut base_model = robot.nominal_model()?;
        base_model.set_tools(tools.to_vec());
        let gravity = robot.dynamics.as_ref().map_or(loadsim::FLOOR_GRAVITY_M_PER_S2, |d| d.gravity_m_per_s2);
        let mut model = Self { base_model, gravity_m_per_s2: gravity, terms: Vec::new(), theta: Vec::new() };
        let n = robot.joint_count();
        let mut sum_sq = vec![vec![0.0; 4 * n + 1]; n];
        for row in &data.rows {
            let values = model.raw_regressors(row)?;
            for (j, joint) in values.iter().enumerate() {
                for (c, v) in joint.iter().enumerate() {
                    sum_sq[j][c] += v * v;
                }
            }
        }
        let count = data.rows.len().max(1) as f64;
        let largest = sum_sq.iter().flatten().fold(0.0_f64, |a, &b| a.max(b));
        for (joint, columns) in sum_sq.iter().enumerate() {
            for (column, &s) in columns.iter().enumerate() {
                // Columns that vanish on every pose (joint 1's vertical axis, a constant payload
                // of zero) carry nothing.
                if s > 1e-20 * largest && s > 0.0 {
                    model.terms.push(ComplianceTerm { joint, column, scale: (s / count).sqrt() });
                }
            }
        }
        model.theta = vec![0.0; model.terms.len()];
        Ok(model)
    }

    /// `Y(q)` row by row, with the payload torque appended to each row: `n × (4n + 1)`.
    fn raw_regressors(&self, row: &Measurement) -> Result<Vec<Vec<f64>>, Error> {
        let g = Vector3::from(self.gravity_m_per_s2);
        let y = loadsim::gravity_regressor(&self.base_model, &row.q, &g)?;
        let payload =
            loadsim::payload_gravity_torque(&self.base_model, &row.q, row.tool, &Payload::at_tool(row.payload_kg), &g)?;
        Ok((0..y.nrows())
            .map(|j| (0..y.ncols()).map(|c| y[(j, c)]).chain(std::iter::once(payload[j])).collect())
            .collect())
    }

    /// The scaled regressor of every term at one row.
    pub(crate) fn regressors(&self, row: &Measurement) -> Result<Vec<f64>, Error> {
        let raw = self.raw_regressors(row)?;
        Ok(self.terms.iter().map(|t| raw[t.joint][t.column] / t.scale).collect())
    }

    /// Each joint's deflection at one row, rad.
    pub fn deflection(&self, row: &Measurement) -> Result<Vec<f64>, Error> {
        let regressors = self.regressors(row)?;
        let mut dq = vec![0.0; self.base_model.joint_count()];
        for ((term, r), t) in self.terms.iter().zip(&regressors).zip(&self.theta) {
            dq[term.joint] += r * t;
        }
        Ok(dq)
    }

    /// The pose of `kinematics` at `row` moved by the deflection: `exp(Σ S_j δq_j) T(q)`.
    pub fn apply(&self, kinematics: &LocalPoe, row: &Measurement, pose: SE3) -> Result<SE3, Error> {
        let dq = self.deflection(row)?;
        let twists = kinematics.spatial_twists(&row.q)?;
        let total: Vector6 = twists.iter().zip(&dq).map(|(s, d)| s.to_vector() * *d).sum();
        Ok(Twist::from_vector(&total).exp() * pose)
    }
}

/// The correction as the identification sees it: the regressors are fixed per row, the joint
/// twists follow the model being identified.
pub(crate) struct ComplianceCorrection<'a> {
    pub terms: &'a [ComplianceTerm],
    pub regressors: Vec<Vec<f64>>,
    pub q: Vec<Vec<f64>>,
}

impl PoseCorrection for ComplianceCorrection<'_> {
    fn parameter_count(&self) -> usize {
        self.terms.len()
    }

    fn twists(&self, model: &LocalPoe, index: usize, out: &mut [Vector6]) {
        match model.spatial_twists(&self.q[index]) {
            Ok(twists) => {
                for ((o, term), r) in out.iter_mut().zip(self.terms).zip(&self.regressors[index]) {
                    *o = twists[term.joint].to_vector() * *r;
                }
            }
            Err(_) => out.fill(Vector6::zeros()),
        }
    }
}
