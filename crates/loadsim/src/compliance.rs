//! Joint compliance: each joint transmission is a torsion spring, so the static torque turns the
//! link by `δq = C τ`, `C = diag(1/k_i)` (the lumped joint-stiffness model of Salisbury 1980 and
//! Tao, Yang & Tomizuka 2013, the paper's ref. \[15\]; links taken as rigid, which Dumas et al.,
//! *Robotica* 2011, found adequate for 6R industrial arms).

use crate::{DynamicsNeed, EntryFault, PoseInput, RobotFacts, SimulatedCell, SimulatedEffect};
use crate::{Error, Payload, RobotDynamics, gravity::payload_gravity_torque, gravity::static_torque};
use lie::Vector3;
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// Settings of the joint-compliance effect (the stiffness itself is robot data, in
/// [`RobotDynamics`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct JointComplianceModel {
    /// Deflect under the payload's weight only, leaving out the arm's own weight and its balancer
    /// (the paper's load effect in isolation). Default: false, everything.
    pub payload_only: bool,
    /// 0 (default): the first-order model `δq = C τ(q)`. `m > 0`: `m` fixed-point steps
    /// `δq ← C τ(q + δq)` towards the true equilibrium, the minimum of `V(q + δq) + ½ δqᵀ K δq`;
    /// the difference is second order in `C`, below 0.1 % of the deflection for industrial arms.
    pub fixed_point_iterations: usize,
}

/// The torque the joint springs carry under these settings, N·m.
pub fn spring_torque(
    model: &LocalPoe,
    dynamics: &RobotDynamics,
    q: &[f64],
    tool: usize,
    payload: &Payload,
    settings: &JointComplianceModel,
) -> Result<Vec<f64>, Error> {
    if settings.payload_only {
        dynamics.validate(model.joint_count())?;
        payload_gravity_torque(model, q, tool, payload, &Vector3::from(dynamics.gravity_m_per_s2))
    } else {
        static_torque(model, dynamics, q, tool, payload)
    }
}

/// The joint deflection `δq = C τ`, rad, one per joint.
pub fn compliance_deflection(
    model: &LocalPoe,
    dynamics: &RobotDynamics,
    q: &[f64],
    tool: usize,
    payload: &Payload,
    settings: &JointComplianceModel,
) -> Result<Vec<f64>, Error> {
    dynamics.validate(model.joint_count())?;
    let stiffness = dynamics.stiffness("joint compliance")?;
    let deflect = |torque: Vec<f64>| -> Vec<f64> { torque.iter().zip(stiffness).map(|(t, k)| t / k).collect() };
    let mut dq = deflect(spring_torque(model, dynamics, q, tool, payload, settings)?);
    for _ in 0..settings.fixed_point_iterations {
        let moved: Vec<f64> = q.iter().zip(&dq).map(|(a, b)| a + b).collect();
        dq = deflect(spring_torque(model, dynamics, &moved, tool, payload, settings)?);
    }
    Ok(dq)
}

/// Most fixed-point steps of the compliance equilibrium an effects file may ask for. Each step
/// shrinks the error by the factor `C·∂τ/∂q`, below 1e-2 for industrial arms ([`JointComplianceModel`]),
/// so 100 steps are far past double precision; more is a typo or a hostile file.
pub const MAX_FIXED_POINT_ITERATIONS: usize = 100;

impl SimulatedEffect for JointComplianceModel {
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        let dynamics = cell.dynamics_for("joint compliance")?;
        dynamics.validate(cell.robot.joint_count())?;
        dynamics.stiffness("joint compliance")?;
        Ok(())
    }

    fn needs_dynamics(&self) -> DynamicsNeed {
        DynamicsNeed::MassesAndStiffness
    }

    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        // A URDF's masses come without stiffness: joint compliance has nothing to deflect by.
        if let Some(Err(error)) = robot.dynamics.map(|d| d.stiffness("joint compliance")) {
            return Err(EntryFault { field: "compliance".into(), index: 0, message: error.to_string() });
        }
        if self.fixed_point_iterations > MAX_FIXED_POINT_ITERATIONS {
            let message = format!(
                "fixed_point_iterations is {}, at most {MAX_FIXED_POINT_ITERATIONS} (each step gains about two digits)",
                self.fixed_point_iterations
            );
            return Err(EntryFault { field: "fixed_point_iterations".into(), index: 0, message });
        }
        Ok(())
    }

    fn joint_offset(&self, at: &PoseInput<'_>) -> Result<Option<Vec<f64>>, Error> {
        let n = at.model.joint_count();
        Ok(Some(match &at.cell.dynamics {
            Some(d) => compliance_deflection(at.model, d, at.q, at.cell.tool, &at.context.payload, self)?,
            None => vec![0.0; n],
        }))
    }
}
