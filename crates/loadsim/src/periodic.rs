//! Periodic transmission error: a gear train (RV or harmonic drive) turns its output by slightly
//! more or less than the commanded angle, periodically in the angles of its rotating parts. On the
//! joint side it is a sum of harmonics of the joint angle,
//! `δq_j = Σ_h A_h cos(h q_j + φ_h) = Σ_h a_h cos(h q_j) + b_h sin(h q_j)`, with
//! `a = A cos φ`, `b = −A sin φ` (Tuttle & Seering 1996 for harmonic drives; the order `h` is 1
//! for output-side eccentricity, the reduction ratio or a multiple of it for motor-side error).

use crate::Error;
use crate::{
    EntryFault, MAX_JOINT_ERROR_RAD, MAX_ORDER, PoseInput, RobotFacts, SimulatedCell, SimulatedEffect, beyond,
};
use serde::{Deserialize, Serialize};

/// One harmonic of one joint's transmission error.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Harmonic {
    /// 0-based joint index.
    pub joint_index: usize,
    /// Order `h`: cycles per joint revolution (need not be an integer for motor-side errors).
    pub order: f64,
    /// Amplitude `A`, rad.
    pub amplitude_rad: f64,
    /// Phase `φ`, rad.
    pub phase_rad: f64,
}

impl Harmonic {
    /// The linear parameters `(a, b) = (A cos φ, −A sin φ)` that multiply
    /// [`periodic_joint_regressor`].
    pub fn cos_sin_coefficients(&self) -> [f64; 2] {
        [self.amplitude_rad * self.phase_rad.cos(), -self.amplitude_rad * self.phase_rad.sin()]
    }
}

/// Transmission error on some joints. Default: no harmonic.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct GearPeriodicModel {
    /// The harmonics, any number per joint.
    pub harmonics: Vec<Harmonic>,
}

impl GearPeriodicModel {
    /// Checks indices and values against a robot with `joint_count` joints.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        for h in &self.harmonics {
            if h.joint_index >= joint_count {
                return Err(Error::from(dynamics::Error::UnknownJoint {
                    field: "periodic",
                    joint_index: h.joint_index,
                    joint_count,
                }));
            }
            for (field, value) in [
                ("periodic.order", h.order),
                ("periodic.amplitude_rad", h.amplitude_rad),
                ("periodic.phase_rad", h.phase_rad),
            ] {
                if !value.is_finite() {
                    return Err(Error::from(dynamics::Error::InvalidParameter { field, value }));
                }
            }
        }
        Ok(())
    }

    /// The joint offsets at joint values `q`, rad.
    pub fn deflection(&self, q: &[f64]) -> Vec<f64> {
        let mut dq = vec![0.0; q.len()];
        for h in &self.harmonics {
            dq[h.joint_index] += h.amplitude_rad * (h.order * q[h.joint_index] + h.phase_rad).cos();
        }
        dq
    }
}

/// The joint-space regressor of one harmonic: `(cos h q_j, sin h q_j)`, so that
/// `δq_j = a cos(h q_j) + b sin(h q_j)`.
pub fn periodic_joint_regressor(joint_value: f64, order: f64) -> [f64; 2] {
    let (s, c) = (order * joint_value).sin_cos();
    [c, s]
}

impl SimulatedEffect for GearPeriodicModel {
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        GearPeriodicModel::validate(self, cell.robot.joint_count())
    }

    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        for (k, h) in self.harmonics.iter().enumerate() {
            let alone = GearPeriodicModel { harmonics: vec![*h] };
            let fault =
                GearPeriodicModel::validate(&alone, robot.joints.len()).err().map(|e| e.to_string()).or_else(|| {
                    beyond(&[("amplitude_rad", h.amplitude_rad, MAX_JOINT_ERROR_RAD), ("order", h.order, MAX_ORDER)])
                });
            if let Some(fault) = fault {
                return Err(EntryFault::entry(k, format!("harmonic {}: {fault}", k + 1)));
            }
        }
        Ok(())
    }

    fn joint_offset(&self, at: &PoseInput<'_>) -> Result<Option<Vec<f64>>, Error> {
        Ok(Some(self.deflection(at.q)))
    }
}
