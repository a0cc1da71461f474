//! Joint compliance: each joint transmission is a torsion spring, so the static torque turns the
//! link by `δq = C τ`, `C = diag(1/k_i)` (the lumped joint-stiffness model of Salisbury 1980 and
//! Tao, Yang & Tomizuka 2013, the paper's ref. \[15\]; links taken as rigid, which Dumas et al.,
//! *Robotica* 2011, found adequate for 6R industrial arms).

use crate::{Error, Payload, RobotDynamics, gravity::payload_gravity_torque, gravity::static_torque};
use lie::Vector3;
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// Settings of the joint-compliance effect (the stiffness itself is robot data, in
/// [`RobotDynamics`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct JointCompliance {
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
    settings: &JointCompliance,
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
    settings: &JointCompliance,
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
