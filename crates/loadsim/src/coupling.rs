//! A coupled joint error: one joint's angle is off by a smooth function of *other* joints'
//! angles, e.g. joint 3's error depending on `q2` and `q4`. Physically: a dress pack (cables and
//! hoses) whose pull on a joint changes with the posture of its neighbours, or a wrist gear
//! train whose motor drives through another axis's bearing (coupled wrist drives: Craig,
//! *Introduction to Robotics*, 3rd ed., ch. 8). No candidate of `calib diagnose` has this form, which
//! is why it exists: a blind check of the diagnosis on an effect outside its list, whose honest
//! verdict is `unknown`.
//!
//! Each term is a product of harmonics of other joints' angles,
//! `δq_j = A · Π_f cos(h_f q_{s_f} + φ_f)`, summed over terms.

use crate::Error;
use crate::{
    EntryFault, MAX_JOINT_ERROR_RAD, MAX_ORDER, PoseInput, RobotFacts, SimulatedCell, SimulatedEffect, beyond,
};
use serde::{Deserialize, Serialize};

/// One factor of a coupling term: a harmonic of another joint's angle.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CouplingFactor {
    /// 0-based index of the joint whose angle drives the error.
    pub source_joint_index: usize,
    /// Order `h`: cycles per revolution of the source joint.
    pub order: f64,
    /// Phase `φ`, rad.
    pub phase_rad: f64,
}

/// One term: an amplitude on one joint times a product of factors.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CouplingTerm {
    /// 0-based index of the joint whose angle is off.
    pub joint_index: usize,
    /// Amplitude `A`, rad.
    pub amplitude_rad: f64,
    /// The factors; at least one, none on `joint_index` itself (that would be a gear error).
    pub factors: Vec<CouplingFactor>,
}

/// Coupled joint errors. Default: no term.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct CouplingModel {
    /// The terms, any number per joint.
    pub terms: Vec<CouplingTerm>,
}

impl CouplingModel {
    /// Checks indices and values against a robot with `joint_count` joints: every index inside
    /// the robot, every term with at least one factor and none on its own joint, values finite.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        for term in &self.terms {
            if term.joint_index >= joint_count {
                return Err(Error::from(dynamics::Error::UnknownJoint {
                    field: "coupling",
                    joint_index: term.joint_index,
                    joint_count,
                }));
            }
            if !term.amplitude_rad.is_finite() {
                return Err(Error::from(dynamics::Error::InvalidParameter {
                    field: "coupling.amplitude_rad",
                    value: term.amplitude_rad,
                }));
            }
            if term.factors.is_empty() {
                return Err(Error::from(dynamics::Error::LengthMismatch {
                    field: "coupling.factors",
                    given: 0,
                    expected: 1,
                }));
            }
            for factor in &term.factors {
                if factor.source_joint_index >= joint_count {
                    return Err(Error::from(dynamics::Error::UnknownJoint {
                        field: "coupling.source_joint_index",
                        joint_index: factor.source_joint_index,
                        joint_count,
                    }));
                }
                if factor.source_joint_index == term.joint_index {
                    return Err(Error::SelfCoupling { joint_index: term.joint_index });
                }
                for (field, value) in [("coupling.order", factor.order), ("coupling.phase_rad", factor.phase_rad)] {
                    if !value.is_finite() {
                        return Err(Error::from(dynamics::Error::InvalidParameter { field, value }));
                    }
                }
            }
        }
        Ok(())
    }

    /// The joint offsets at joint values `q`, rad.
    pub fn deflection(&self, q: &[f64]) -> Vec<f64> {
        let mut dq = vec![0.0; q.len()];
        for term in &self.terms {
            let product: f64 =
                term.factors.iter().map(|f| (f.order * q[f.source_joint_index] + f.phase_rad).cos()).product();
            dq[term.joint_index] += term.amplitude_rad * product;
        }
        dq
    }
}

impl SimulatedEffect for CouplingModel {
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        CouplingModel::validate(self, cell.robot.joint_count())
    }

    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        for (k, term) in self.terms.iter().enumerate() {
            let alone = CouplingModel { terms: vec![term.clone()] };
            let mut bounds = vec![("amplitude_rad", term.amplitude_rad, MAX_JOINT_ERROR_RAD)];
            bounds.extend(term.factors.iter().map(|f| ("order", f.order, MAX_ORDER)));
            let fault = CouplingModel::validate(&alone, robot.joints.len())
                .err()
                .map(|e| e.to_string())
                .or_else(|| beyond(&bounds));
            if let Some(fault) = fault {
                return Err(EntryFault::entry(k, format!("term {}: {fault}", k + 1)));
            }
        }
        Ok(())
    }

    fn joint_offset(&self, at: &PoseInput<'_>) -> Result<Option<Vec<f64>>, Error> {
        Ok(Some(self.deflection(at.q)))
    }
}
