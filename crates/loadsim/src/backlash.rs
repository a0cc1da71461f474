//! Backlash (lost motion) in a joint transmission: under load the output sits at one end of its
//! play, `δq_j = b_j · sign(τ_j)`, with `b_j` the half-band and `τ_j` the static torque the gear
//! carries (the hysteresis model of backlash at rest; Nordin & Gutman, *Automatica* 2002).

use crate::Error;
use crate::{
    DynamicsNeed, EntryFault, MAX_JOINT_ERROR_RAD, PoseInput, RobotFacts, SimulatedCell, SimulatedEffect, beyond,
};
use serde::{Deserialize, Serialize};

/// The play of one joint.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct JointBacklash {
    /// 0-based joint index.
    pub joint_index: usize,
    /// Half the backlash band, rad (the output moves `±` this from the centre of the play).
    pub half_band_rad: f64,
}

/// Backlash on some joints. Default: none listed.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct BacklashModel {
    /// The joints with play; a joint not listed has none.
    pub joints: Vec<JointBacklash>,
}

impl BacklashModel {
    /// The same half-band on every joint of an `joint_count`-joint robot.
    pub fn uniform(joint_count: usize, half_band_rad: f64) -> Self {
        Self { joints: (0..joint_count).map(|joint_index| JointBacklash { joint_index, half_band_rad }).collect() }
    }

    /// Checks indices and values against a robot with `joint_count` joints.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        for entry in &self.joints {
            if entry.joint_index >= joint_count {
                return Err(Error::from(dynamics::Error::UnknownJoint {
                    field: "backlash",
                    joint_index: entry.joint_index,
                    joint_count,
                }));
            }
            if !(entry.half_band_rad.is_finite() && entry.half_band_rad >= 0.0) {
                return Err(Error::from(dynamics::Error::InvalidParameter {
                    field: "backlash.half_band_rad",
                    value: entry.half_band_rad,
                }));
            }
        }
        Ok(())
    }

    /// The joint offsets `δq_j = b_j sign(τ_j)` for the static torque `torque`, rad.
    pub fn deflection(&self, torque: &[f64]) -> Vec<f64> {
        let signs = backlash_joint_regressor(torque);
        let mut dq = vec![0.0; torque.len()];
        for entry in &self.joints {
            dq[entry.joint_index] += entry.half_band_rad * signs[entry.joint_index];
        }
        dq
    }
}

/// The joint-space regressor of backlash: `sign(τ_j)` per joint (0 where the torque is exactly 0),
/// so that `δq_j = b_j · sign(τ_j)`.
pub fn backlash_joint_regressor(torque: &[f64]) -> Vec<f64> {
    torque
        .iter()
        .map(|&t| {
            if t > 0.0 {
                1.0
            } else if t < 0.0 {
                -1.0
            } else {
                0.0
            }
        })
        .collect()
}

impl SimulatedEffect for BacklashModel {
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        let n = cell.robot.joint_count();
        BacklashModel::validate(self, n)?;
        Ok(cell.dynamics_for("backlash")?.validate(n)?)
    }

    fn needs_dynamics(&self) -> DynamicsNeed {
        DynamicsNeed::Masses
    }

    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        for (k, joint) in self.joints.iter().enumerate() {
            let alone = BacklashModel { joints: vec![*joint] };
            let fault = BacklashModel::validate(&alone, robot.joints.len())
                .err()
                .map(|e| e.to_string())
                .or_else(|| beyond(&[("half_band_rad", joint.half_band_rad, MAX_JOINT_ERROR_RAD)]));
            if let Some(fault) = fault {
                return Err(EntryFault::entry(k, format!("entry {}: {fault}", k + 1)));
            }
        }
        Ok(())
    }

    fn joint_offset(&self, at: &PoseInput<'_>) -> Result<Option<Vec<f64>>, Error> {
        Ok(Some(self.deflection(at.static_torque_nm)))
    }
}
