//! Measured joint torques: what a robot with joint torque sensors (the KUKA LBR iiwa, the DLR
//! lightweight arms) or a controller reading its motor currents at standstill reports for each
//! measured pose.
//!
//! At rest a joint's drive holds the static torque: the measured torque is the drive torque of
//! the robot controller's convention, `M q̈ + c + ∂V/∂q = τ`, so `τ_measured = −τ_static` with
//! `τ_static = −∂V/∂q` (+ the balancer) the generalised force of [`crate::static_torque`]. A joint
//! spring then deflects by `δq = −τ_measured / k`. Sensor noise is Gaussian, independent per joint
//! and per pose.

use crate::Error;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Gaussian noise of measured joint torques.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TorqueSensorNoise {
    /// Standard deviation of every joint's reading, N·m. Default 0.5 N·m, an ENGINEERING ESTIMATE
    /// for strain-gauge joint torque sensors of the 100–200 N·m class (LBR iiwa 7: 176 N·m on
    /// joints 1–2, 110 on 3–5, 40 on 6–7, KUKA's data sheet): their resolution is far finer, but
    /// offset drift and hysteresis of a few tenths of a per cent of the range remain in a static
    /// reading. No manufacturer figure for a static reading's accuracy was found; a motor-current
    /// estimate on a large industrial arm is an order of magnitude worse and should say so here.
    pub sigma_nm: f64,
    /// Per-joint standard deviations overriding `sigma_nm`: empty (default) or one per joint.
    pub joint_sigma_nm: Vec<f64>,
}

impl Default for TorqueSensorNoise {
    fn default() -> Self {
        Self { sigma_nm: 0.5, joint_sigma_nm: Vec::new() }
    }
}

impl TorqueSensorNoise {
    /// Checks the values against a robot with `joint_count` joints.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        if !self.joint_sigma_nm.is_empty() && self.joint_sigma_nm.len() != joint_count {
            return Err(Error::from(dynamics::Error::LengthMismatch {
                field: "torque_sensor.joint_sigma_nm",
                given: self.joint_sigma_nm.len(),
                expected: joint_count,
            }));
        }
        match std::iter::once(&self.sigma_nm).chain(&self.joint_sigma_nm).find(|s| !(s.is_finite() && **s >= 0.0)) {
            Some(&value) => {
                Err(Error::from(dynamics::Error::InvalidParameter { field: "torque_sensor.sigma_nm", value }))
            }
            None => Ok(()),
        }
    }

    /// The standard deviation of joint `j`'s reading, N·m.
    pub fn sigma_of(&self, joint_index: usize) -> f64 {
        self.joint_sigma_nm.get(joint_index).copied().unwrap_or(self.sigma_nm)
    }

    /// A reading of the drive torques that hold `static_torque_nm` (`τ_measured = −τ_static`
    /// plus noise), N·m.
    pub fn measure<R: Rng + ?Sized>(&self, static_torque_nm: &[f64], rng: &mut R) -> Vec<f64> {
        static_torque_nm
            .iter()
            .enumerate()
            .map(|(j, t)| {
                let z: f64 = StandardNormal.sample(rng);
                -t + self.sigma_of(j) * z
            })
            .collect()
    }
}
