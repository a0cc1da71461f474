//! A spring balancer on one joint (joint 2 of most large industrial arms).
//!
//! Physically: a spring (coil or gas) between a point `A` on the body before the joint and a point
//! `B` on the body the joint moves, both in a plane normal to the joint axis, at distances `a` and
//! `r` from the axis. With `θ = q + θ₀` the angle between the directions to `A` and to `B`, the law
//! of cosines gives the spring length `L(q) = √(a² + r² − 2 a r cos θ)`. The spring pulls with
//! `F(L) = F₀ + k (L − L₀)` (tension positive; a pushing gas spring has `F₀ < 0`), `L₀ = L(0)`, so
//! its potential is `U = F₀ (L − L₀) + ½ k (L − L₀)²` and its torque on the joint
//! `τ = −dU/dq = −F(L) · a r sin θ / L`.
//!
//! With `A` straight above the axis, `θ₀ = 0` and a zero-free-length spring (`F₀ = k L₀`) this is the
//! classical exact gravity balancer: `τ = −k a r sin q` cancels the torque `M g d sin q` of a
//! pendulum when `k a r = M g d` (Herder, *Energy-free systems*, 2001, ch. 2; Rivin, *Mechanical
//! design of robots*, 1988). Real balancers are only close to that, which leaves a torque the joint
//! stiffness turns into deflection.

use crate::Error;
use serde::{Deserialize, Serialize};

/// A two-point spring balancer on one revolute joint; see the module doc for the geometry.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Counterbalance {
    /// 0-based index of the balanced joint (1 for joint 2).
    pub joint_index: usize,
    /// `a`: distance of the fixed anchor `A` from the joint axis, m.
    pub anchor_radius_m: f64,
    /// `r`: distance of the moving attachment `B` from the joint axis, m.
    pub attachment_radius_m: f64,
    /// `θ₀`: angle from `A` to `B` about the joint axis at joint value zero, rad.
    pub angle_at_zero_rad: f64,
    /// `F₀`: spring force at joint value zero, N, tension positive.
    pub force_at_zero_n: f64,
    /// `k`: spring rate, N/m.
    pub stiffness_n_per_m: f64,
}

impl Counterbalance {
    /// Checks the geometry: radii positive and distinct (so the spring never has zero length),
    /// numbers finite, joint inside the robot.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        if self.joint_index >= joint_count {
            return Err(Error::UnknownJoint { field: "counterbalance", joint_index: self.joint_index, joint_count });
        }
        for (field, value) in [
            ("counterbalance.anchor_radius_m", self.anchor_radius_m),
            ("counterbalance.attachment_radius_m", self.attachment_radius_m),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidParameter { field, value });
            }
        }
        let gap = (self.anchor_radius_m - self.attachment_radius_m).abs();
        if gap < 1e-6 {
            return Err(Error::InvalidParameter { field: "counterbalance radii difference", value: gap });
        }
        for (field, value) in [
            ("counterbalance.angle_at_zero_rad", self.angle_at_zero_rad),
            ("counterbalance.force_at_zero_n", self.force_at_zero_n),
            ("counterbalance.stiffness_n_per_m", self.stiffness_n_per_m),
        ] {
            if !value.is_finite() {
                return Err(Error::InvalidParameter { field, value });
            }
        }
        Ok(())
    }

    /// Spring length `L(q)`, m.
    pub fn spring_length_m(&self, q: f64) -> f64 {
        let (a, r) = (self.anchor_radius_m, self.attachment_radius_m);
        (a * a + r * r - 2.0 * a * r * (q + self.angle_at_zero_rad).cos()).sqrt()
    }

    /// `dL/dq = a r sin θ / L`, m/rad.
    fn length_rate(&self, q: f64) -> f64 {
        self.anchor_radius_m * self.attachment_radius_m * (q + self.angle_at_zero_rad).sin() / self.spring_length_m(q)
    }

    /// The balancer's torque on its joint at joint value `q`, N·m (same sign convention as the
    /// gravity torque: positive drives the joint towards positive values).
    pub fn torque_nm(&self, q: f64) -> f64 {
        let rate = self.regressor(q);
        rate[0] * self.force_at_zero_n + rate[1] * self.stiffness_n_per_m
    }

    /// The torque written as linear in `(F₀, k)`: `τ = ρ · (F₀, k)` with
    /// `ρ = (−dL/dq, −(L − L₀) dL/dq)`, for fixed geometry.
    pub fn regressor(&self, q: f64) -> [f64; 2] {
        let rate = self.length_rate(q);
        let stretch = self.spring_length_m(q) - self.spring_length_m(0.0);
        [-rate, -stretch * rate]
    }
}
