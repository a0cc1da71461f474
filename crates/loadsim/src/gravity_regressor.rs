//! The gravity torque written as linear in the links' mass moments, for identification without
//! known masses.
//!
//! A point fixed to link `k` at `c₀` (zero configuration) is at `G_k(q) c₀ = R_k c₀ + t_k`, so
//! `V_k = −gᵀ(R_k (m_k c₀) + t_k m_k)` is linear in `π_k = (m_k, m_k c₀)` and so is
//! `τ_j = −∂V/∂q_j = Σ_{k ≥ j} [gᵀ(v_j + ω_j × t_k) m_k + gᵀ ω_j^ R_k (m_k c₀)]`
//! (the classical linearity of robot dynamics in the inertial parameters; Khalil & Dombre,
//! *Modeling, identification and control of robots*, 2002, §12.4).

use crate::{Error, gravity::link_motions, gravity::point_rate};
use lie::{SO3, Vector3};
use nalgebra::DMatrix;
use poe::LocalPoe;

/// `Y(q)`, n × 4n: the links' gravity torque is `Y(q) · π` with
/// `π = (m_1, m_1 c_1, …, m_n, m_n c_n)` ([`crate::RobotDynamics::inertial_parameters`]),
/// `c_k` the zero-configuration centre of mass in the reference frame, `gravity` in the reference
/// frame. Not every column is identifiable (e.g. joint 1's vertical axis sees no gravity): the
/// diagnosis must reduce it to a base set.
pub fn gravity_regressor(model: &LocalPoe, q: &[f64], gravity: &Vector3) -> Result<DMatrix<f64>, Error> {
    let n = model.joint_count();
    let motions = link_motions(model, q)?;
    let twists = model.spatial_twists(q)?;
    let mut y = DMatrix::zeros(n, 4 * n);
    for (j, s) in twists.iter().enumerate() {
        // gᵀ ω^ R as a row: the coefficient of m_k c₀.
        let g_w = gravity.transpose() * SO3::hat(&s.w);
        for (k, motion) in motions.iter().enumerate().skip(j) {
            y[(j, 4 * k)] = gravity.dot(&point_rate(s, &motion.translation()));
            let row = g_w * motion.rotation().matrix();
            for axis in 0..3 {
                y[(j, 4 * k + 1 + axis)] = row[axis];
            }
        }
    }
    Ok(y)
}
