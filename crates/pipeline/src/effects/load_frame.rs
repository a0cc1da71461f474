//! What the torque-driven effects need to know of gravity: the nominal arm in the robot's base
//! frame (where gravity is known; a calibrated model's frame is the tracker's) with the calibrated
//! tools, and gravity in that frame.

use crate::{Error, Measurement, RobotDescription};
use lie::{SE3, Vector3};
use loadsim::Payload;
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// The nominal arm in the base frame and gravity there: the gravity-torque regressors of a row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoadFrame {
    /// The nominal arm in the robot's base frame, with the calibrated tools (the payload hangs
    /// from them).
    pub base_model: LocalPoe,
    /// Gravity in the base frame, m/s².
    pub gravity_m_per_s2: [f64; 3],
}

impl LoadFrame {
    /// The frame of `robot` carrying `tools` (the calibrated ones, tracker-independent offsets).
    pub(crate) fn new(robot: &RobotDescription, tools: &[SE3]) -> Result<Self, Error> {
        let mut base_model = robot.nominal_model()?;
        base_model.set_tools(tools.to_vec());
        let gravity = robot.dynamics.as_ref().map_or(loadsim::FLOOR_GRAVITY_M_PER_S2, |d| d.gravity_m_per_s2);
        Ok(Self { base_model, gravity_m_per_s2: gravity })
    }

    pub(crate) fn gravity(&self) -> Vector3 {
        Vector3::from(self.gravity_m_per_s2)
    }

    /// The gravity-torque regressor `Y(q)` (`loadsim::gravity_regressor`) row by row, with the
    /// payload's gravity torque appended to each row: `n × (4n + 1)`. Joint `j`'s gravity torque
    /// is `Y_j(q) π + τ_payload,j` with `π` the links' unknown mass moments.
    pub(crate) fn regressors(&self, row: &Measurement, tool: usize) -> Result<Vec<Vec<f64>>, Error> {
        let g = self.gravity();
        let y = loadsim::gravity_regressor(&self.base_model, &row.q, &g)?;
        let payload =
            loadsim::payload_gravity_torque(&self.base_model, &row.q, tool, &Payload::at_tool(row.payload_kg), &g)?;
        Ok((0..y.nrows())
            .map(|j| (0..y.ncols()).map(|c| y[(j, c)]).chain(std::iter::once(payload[j])).collect())
            .collect())
    }
}
