//! Periodic error of a linear axis driven by a ball screw or a rack: the carriage's position
//! error repeats with every turn of the screw (or of the pinion), so it is a function of the
//! axis's own position with the screw's lead (the pinion's circumference) as period `p`:
//! `δq_j = Σ_h A_h cos(2π h q_j / p + φ_h)`, metres (ISO 230-2's periodic deviation of a
//! ball-screw axis; the once-per-turn harmonic from the screw's run-out and the nut's
//! eccentricity, higher ones from the balls' circulation). The same series as a gear's
//! ([`crate::GearPeriodicModel`]) in the phase `2π q_j / p` of the screw.

use crate::Error;
use crate::{EntryFault, MAX_ORDER, PoseInput, RobotFacts, SimulatedCell, SimulatedEffect, beyond, short};
use serde::{Deserialize, Serialize};

/// One harmonic of one linear axis's screw (or rack) error.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ScrewHarmonic {
    /// 0-based joint index (a prismatic joint).
    pub joint_index: usize,
    /// The screw's lead (or the pinion's circumference): the travel per turn, m.
    pub pitch_m: f64,
    /// Order `h`: cycles per turn of the screw.
    pub order: f64,
    /// Amplitude `A`, m.
    pub amplitude_m: f64,
    /// Phase `φ`, rad.
    pub phase_rad: f64,
}

/// Screw (or rack) errors on some linear axes. Default: no harmonic.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct ScrewPeriodicModel {
    /// The harmonics, any number per joint.
    pub harmonics: Vec<ScrewHarmonic>,
}

impl ScrewPeriodicModel {
    /// Checks indices, joint kinds and values against a robot whose joints are `prismatic`.
    pub fn validate(&self, prismatic: &[bool]) -> Result<(), Error> {
        for h in &self.harmonics {
            let joint_count = prismatic.len();
            match prismatic.get(h.joint_index) {
                None => {
                    return Err(Error::from(dynamics::Error::UnknownJoint {
                        field: "screw",
                        joint_index: h.joint_index,
                        joint_count,
                    }));
                }
                Some(false) => return Err(Error::NotPrismatic { field: "screw", joint_index: h.joint_index }),
                Some(true) => {}
            }
            if !(h.pitch_m.is_finite() && h.pitch_m > 0.0) {
                return Err(Error::from(dynamics::Error::InvalidParameter {
                    field: "screw.pitch_m",
                    value: h.pitch_m,
                }));
            }
            for (field, value) in
                [("screw.order", h.order), ("screw.amplitude_m", h.amplitude_m), ("screw.phase_rad", h.phase_rad)]
            {
                if !value.is_finite() {
                    return Err(Error::from(dynamics::Error::InvalidParameter { field, value }));
                }
            }
        }
        Ok(())
    }

    /// The joint offsets at joint values `q`, m (0 on joints without a harmonic).
    pub fn deflection(&self, q: &[f64]) -> Vec<f64> {
        let mut dq = vec![0.0; q.len()];
        for h in &self.harmonics {
            let phase = std::f64::consts::TAU * q[h.joint_index] / h.pitch_m;
            dq[h.joint_index] += h.amplitude_m * (h.order * phase + h.phase_rad).cos();
        }
        dq
    }
}

/// Largest amplitude of a linear axis's screw (or rack) error, m: ground ball screws err
/// periodically by a few µm per turn (ISO 3408-3's `v_2π` of class 5 to 10: 8 to 40 µm), rolled
/// screws and racks by tens of µm; a millimetre per turn is a broken drive.
pub const MAX_SCREW_ERROR_M: f64 = 1e-3;

impl SimulatedEffect for ScrewPeriodicModel {
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        let prismatic: Vec<bool> = cell.robot.joints().iter().map(|j| j.kind == poe::JointKind::Prismatic).collect();
        ScrewPeriodicModel::validate(self, &prismatic)
    }

    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        let prismatic: Vec<bool> = robot.joints.iter().map(|&kind| kind == poe::JointKind::Prismatic).collect();
        let (low, high) = robot.pitch_bounds_mm;
        for (k, h) in self.harmonics.iter().enumerate() {
            let alone = ScrewPeriodicModel { harmonics: vec![*h] };
            let fault = ScrewPeriodicModel::validate(&alone, &prismatic).err().map(|e| e.to_string()).or_else(|| {
                beyond(&[("amplitude_m", h.amplitude_m, MAX_SCREW_ERROR_M), ("order", h.order, MAX_ORDER)])
            });
            let pitch_mm = h.pitch_m * 1e3;
            let fault = fault.or_else(|| {
                (!(low..=high).contains(&pitch_mm))
                    .then(|| format!("pitch_m is {}, expected {} to {} m", short(h.pitch_m), low * 1e-3, high * 1e-3))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_repeats_with_every_pitch_of_travel_and_is_refused_on_a_revolute_joint() {
        let screw = ScrewPeriodicModel {
            harmonics: vec![ScrewHarmonic {
                joint_index: 0,
                pitch_m: 0.01,
                order: 1.0,
                amplitude_m: 5e-6,
                phase_rad: 0.3,
            }],
        };
        assert!(screw.validate(&[true, false]).is_ok());
        let a = screw.deflection(&[0.1234, 0.5])[0];
        let b = screw.deflection(&[0.1234 + 7.0 * 0.01, 0.5])[0];
        assert!((a - b).abs() < 1e-15 && a.abs() <= 5e-6, "{a} {b}");
        assert_eq!(screw.deflection(&[0.1234, 0.5])[1], 0.0);
        let half = screw.deflection(&[0.1234 + 0.005, 0.5])[0];
        assert!((a + half).abs() < 1e-15, "half a pitch on, the first harmonic is opposite: {a} {half}");
        assert!(matches!(screw.validate(&[false]), Err(Error::NotPrismatic { joint_index: 0, .. })));
        assert!(matches!(screw.validate(&[]), Err(Error::Dynamics { source: dynamics::Error::UnknownJoint { .. } })));
        let mut bad = screw.clone();
        bad.harmonics[0].pitch_m = 0.0;
        assert!(matches!(
            bad.validate(&[true]),
            Err(Error::Dynamics { source: dynamics::Error::InvalidParameter { field: "screw.pitch_m", .. } })
        ));
    }
}
