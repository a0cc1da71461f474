//! Gravity torque of the links and the payload, from the potential energy.
//!
//! Sign convention: `τ = −∂V/∂q` with `V(q) = −Σ_k m_k gᵀ c_k(q)`, i.e. `τ` is the generalised
//! force gravity exerts on the joints (positive drives a joint towards positive values). A joint
//! spring holding it stretches by `δq = τ / k`, so the arm sags with gravity.
//!
//! `∂c/∂q_j = v_j + ω_j × c` for the joint's spatial twist `(v_j, ω_j)` (Lynch & Park, *Modern
//! Robotics*, 2017, §5.1), so `τ_j = Σ_{k ≥ j} m_k gᵀ (v_j + ω_j × c_k) = Σ_k J_{c,k}ᵀ m_k g`
//! (the load model of Tao, Yang & Tomizuka 2013, the paper's ref. \[15\]).

use crate::{Error, RobotDynamics};
use lie::{SE3, Twist, Vector3};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// A mass carried at the tool.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Payload {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Its centre of mass relative to the tool point, tool frame, m (zero: at the tool point).
    pub com_offset_m: [f64; 3],
}

impl Payload {
    /// A point mass at the tool point.
    pub fn at_tool(mass_kg: f64) -> Self {
        Self { mass_kg, com_offset_m: [0.0; 3] }
    }

    fn validate(&self) -> Result<(), Error> {
        if !(self.mass_kg.is_finite() && self.mass_kg >= 0.0) {
            return Err(Error::from(dynamics::Error::InvalidParameter { field: "payload_kg", value: self.mass_kg }));
        }
        if let Some(&c) = self.com_offset_m.iter().find(|c| !c.is_finite()) {
            return Err(Error::from(dynamics::Error::InvalidParameter { field: "payload com_offset_m", value: c }));
        }
        Ok(())
    }
}

/// How each link has moved from the zero configuration: `G_k(q) = F_k(q) · F_k(0)⁻¹`, with `F_k`
/// the frame of joint `k` after its motion. A point fixed to link `k` at `x₀` (zero configuration,
/// reference frame) is at `G_k(q) x₀`.
pub fn link_motions(model: &LocalPoe, q: &[f64]) -> Result<Vec<SE3>, Error> {
    let at_q = model.frames(q)?;
    let at_zero = model.frames(&vec![0.0; model.joint_count()])?;
    Ok(at_q.iter().zip(&at_zero).map(|(now, zero)| *now * zero.inverse()).collect())
}

/// Each link's centre of mass at joint values `q`, reference frame, m.
pub fn link_centres_of_mass(model: &LocalPoe, dynamics: &RobotDynamics, q: &[f64]) -> Result<Vec<Vector3>, Error> {
    dynamics.validate(model.joint_count())?;
    Ok(link_motions(model, q)?
        .iter()
        .zip(&dynamics.links)
        .map(|(motion, link)| motion.transform_point(&Vector3::from(link.com_m)))
        .collect())
}

/// The payload's centre of mass at joint values `q`, reference frame, m.
pub fn payload_centre_of_mass(model: &LocalPoe, q: &[f64], tool: usize, payload: &Payload) -> Result<Vector3, Error> {
    payload.validate()?;
    Ok(model.forward(q, tool)?.transform_point(&Vector3::from(payload.com_offset_m)))
}

/// `V(q) = −Σ m gᵀ c(q)` of the links and the payload, J (zero at the reference origin).
pub fn potential_energy(
    model: &LocalPoe,
    dynamics: &RobotDynamics,
    q: &[f64],
    tool: usize,
    payload: &Payload,
) -> Result<f64, Error> {
    let g = Vector3::from(dynamics.gravity_m_per_s2);
    let links: f64 = link_centres_of_mass(model, dynamics, q)?
        .iter()
        .zip(&dynamics.links)
        .map(|(c, link)| -link.mass_kg * g.dot(c))
        .sum();
    Ok(links - payload.mass_kg * g.dot(&payload_centre_of_mass(model, q, tool, payload)?))
}

/// The rate of a point `c` under a unit motion of a joint with spatial twist `s`: `v + ω × c`.
pub(crate) fn point_rate(s: &Twist, c: &Vector3) -> Vector3 {
    s.v + s.w.cross(c)
}

/// Gravity torque of the links and the payload, `τ = −∂V/∂q`, N·m, one per joint.
pub fn gravity_torque(
    model: &LocalPoe,
    dynamics: &RobotDynamics,
    q: &[f64],
    tool: usize,
    payload: &Payload,
) -> Result<Vec<f64>, Error> {
    let g = Vector3::from(dynamics.gravity_m_per_s2);
    let centres = link_centres_of_mass(model, dynamics, q)?;
    let twists = model.spatial_twists(q)?;
    let mut torque = payload_gravity_torque(model, q, tool, payload, &g)?;
    for (j, s) in twists.iter().enumerate() {
        // Joint j moves links j, j+1, …: the links before it do not move with it.
        torque[j] +=
            centres.iter().zip(&dynamics.links).skip(j).map(|(c, l)| l.mass_kg * g.dot(&point_rate(s, c))).sum::<f64>();
    }
    Ok(torque)
}

/// Gravity torque of the payload alone, `J_pᵀ m_p g`, N·m, for gravity `g` in the reference frame.
pub fn payload_gravity_torque(
    model: &LocalPoe,
    q: &[f64],
    tool: usize,
    payload: &Payload,
    gravity: &Vector3,
) -> Result<Vec<f64>, Error> {
    let c = payload_centre_of_mass(model, q, tool, payload)?;
    Ok(model.spatial_twists(q)?.iter().map(|s| payload.mass_kg * gravity.dot(&point_rate(s, &c))).collect())
}

/// The torque the joint transmissions carry at rest: gravity plus the balancer, N·m. This is what
/// the joint springs deflect under and what sets the side of the backlash band.
pub fn static_torque(
    model: &LocalPoe,
    dynamics: &RobotDynamics,
    q: &[f64],
    tool: usize,
    payload: &Payload,
) -> Result<Vec<f64>, Error> {
    let mut torque = gravity_torque(model, dynamics, q, tool, payload)?;
    if let Some(balancer) = &dynamics.counterbalance {
        torque[balancer.joint_index] += balancer.torque_nm(q[balancer.joint_index]);
    }
    Ok(torque)
}
