//! The simulated measurement cell and the per-pose conditions.

use crate::{Error, Payload, RobotDynamics};
use lie::SE3;
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// A robot in a measurement cell: its true geometry (reference frame = robot base, z up), its
/// masses and stiffness if known, where the tracker sees the base from, and which tool is measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulatedCell {
    /// The true kinematic model, base reference frame.
    pub robot: LocalPoe,
    /// Masses, centres of mass, stiffness and balancer; needed by compliance and backlash.
    pub dynamics: Option<RobotDynamics>,
    /// Placement of the robot base in the tracker frame.
    pub tracker_from_base: SE3,
    /// Index of the measured tool in `robot`.
    pub tool: usize,
}

impl SimulatedCell {
    /// A cell with the tracker frame on the robot base and tool 0 measured.
    pub fn new(robot: LocalPoe, dynamics: Option<RobotDynamics>) -> Self {
        Self { robot, dynamics, tracker_from_base: SE3::identity(), tool: 0 }
    }

    /// The dynamics, or the error that `effect` needs them.
    pub(crate) fn dynamics_for(&self, effect: &'static str) -> Result<&RobotDynamics, Error> {
        self.dynamics.as_ref().ok_or(Error::MissingDynamics { effect })
    }
}

/// What changes from one measured pose to the next besides the joint values (the CSV columns
/// `payload_kg`, `temp_c`, `t_s`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PoseContext {
    /// The payload at the tool.
    pub payload: Payload,
    /// Temperature of the robot, °C.
    pub temp_c: f64,
    /// Time of the measurement, s from the start of the campaign.
    pub t_s: f64,
}

impl Default for PoseContext {
    fn default() -> Self {
        Self { payload: Payload::default(), temp_c: 20.0, t_s: 0.0 }
    }
}
