//! Each effect written as linear in its parameters, for the diagnosis: the measured pose error
//! `y = log(T_measured · T_model⁻¹)^∨` (left perturbation, `(v, ω)`, the model's reference frame)
//! is, to first order, `y ≈ Σ_p θ_p · column_p`.
//!
//! A joint offset `δq_j` moves the tool by `S_j(q) δq_j`, `S_j` the joint's spatial twist (the
//! column of the spatial manipulator Jacobian; Lynch & Park, *Modern Robotics*, §5.1.1), so a
//! joint-space regressor `δq_j = θ · r_j(q)` gives the pose column `S_j(q) r_j(q)`. The columns are
//! expressed in the reference frame of the model passed in: a base-frame model gives base-frame
//! columns, a tracker-frame (calibrated) model tracker-frame columns.

use crate::{Error, backlash::backlash_joint_regressor, periodic::periodic_joint_regressor};
use lie::{Vector3, Vector6};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// The parameter a regressor column multiplies.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum EffectParameter {
    /// Joint compliance `c_j = 1/k_j`, rad/(N·m).
    Compliance {
        /// 0-based joint index.
        joint_index: usize,
    },
    /// Backlash half-band `b_j`, rad.
    Backlash {
        /// 0-based joint index.
        joint_index: usize,
    },
    /// Cosine coefficient `a = A cos φ` of one harmonic, rad.
    PeriodicCos {
        /// 0-based joint index.
        joint_index: usize,
        /// Harmonic order `h`.
        order: f64,
    },
    /// Sine coefficient `b = −A sin φ` of one harmonic, rad.
    PeriodicSin {
        /// 0-based joint index.
        joint_index: usize,
        /// Harmonic order `h`.
        order: f64,
    },
    /// Expansion coefficient `α_i` of constant transform `i` (joints first, `n` = the tool), 1/K.
    ThermalExpansion {
        /// 0-based index of the constant transform.
        link_index: usize,
    },
    /// Component `i` of the drift twist rate `ξ` (`(v, ω)` order), per second.
    DriftRate {
        /// 0..6.
        component: usize,
    },
}

impl EffectParameter {
    /// The kind of effect the parameter belongs to.
    pub fn kind(&self) -> crate::EffectKind {
        use crate::EffectKind;
        match self {
            EffectParameter::Compliance { .. } => EffectKind::JointCompliance,
            EffectParameter::Backlash { .. } => EffectKind::Backlash,
            EffectParameter::PeriodicCos { .. } | EffectParameter::PeriodicSin { .. } => EffectKind::GearPeriodic,
            EffectParameter::ThermalExpansion { .. } => EffectKind::Thermal,
            EffectParameter::DriftRate { .. } => EffectKind::TimeDrift,
        }
    }
}

/// One column of an effect's linearisation: the pose error per unit of one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegressorColumn {
    /// The parameter.
    pub parameter: EffectParameter,
    /// The left-perturbation twist `(v, ω)` per unit of the parameter, reference frame.
    pub twist: Vector6,
}

fn joint_columns(model: &LocalPoe, q: &[f64]) -> Result<Vec<Vector6>, Error> {
    Ok(model.spatial_twists(q)?.iter().map(|s| s.to_vector()).collect())
}

fn check_len(field: &'static str, given: usize, expected: usize) -> Result<(), Error> {
    if given == expected { Ok(()) } else { Err(Error::LengthMismatch { field, given, expected }) }
}

/// Compliance columns, one per joint: `δq_j = c_j τ_j` gives `S_j(q) τ_j`. `torque` is the static
/// torque (known masses), or a column of `Y(q)` for a product parameter `c_j π_i`.
pub fn compliance_regressor(model: &LocalPoe, q: &[f64], torque: &[f64]) -> Result<Vec<RegressorColumn>, Error> {
    check_len("torque", torque.len(), model.joint_count())?;
    Ok(joint_columns(model, q)?
        .into_iter()
        .zip(torque)
        .enumerate()
        .map(|(joint_index, (s, t))| RegressorColumn {
            parameter: EffectParameter::Compliance { joint_index },
            twist: s * *t,
        })
        .collect())
}

/// Backlash columns, one per joint: `δq_j = b_j sign(τ_j)` gives `S_j(q) sign(τ_j)`.
pub fn backlash_regressor(model: &LocalPoe, q: &[f64], torque: &[f64]) -> Result<Vec<RegressorColumn>, Error> {
    check_len("torque", torque.len(), model.joint_count())?;
    Ok(joint_columns(model, q)?
        .into_iter()
        .zip(backlash_joint_regressor(torque))
        .enumerate()
        .map(|(joint_index, (s, sign))| RegressorColumn {
            parameter: EffectParameter::Backlash { joint_index },
            twist: s * sign,
        })
        .collect())
}

/// The two columns of one harmonic of joint `joint_index`: `S_j cos(h q_j)` and `S_j sin(h q_j)`.
pub fn periodic_regressor(
    model: &LocalPoe,
    q: &[f64],
    joint_index: usize,
    order: f64,
) -> Result<[RegressorColumn; 2], Error> {
    let columns = joint_columns(model, q)?;
    let s = columns.get(joint_index).ok_or(Error::UnknownJoint {
        field: "periodic",
        joint_index,
        joint_count: model.joint_count(),
    })?;
    let [c, sn] = periodic_joint_regressor(q[joint_index], order);
    Ok([
        RegressorColumn { parameter: EffectParameter::PeriodicCos { joint_index, order }, twist: s * c },
        RegressorColumn { parameter: EffectParameter::PeriodicSin { joint_index, order }, twist: s * sn },
    ])
}

/// Thermal columns, one per constant transform (n joints, then the tool): growing transform `i` by
/// the strain `α_i ΔT` moves the pose by `α_i ΔT (R_{i-1}(q) t_i, 0)` exactly (module
/// [`crate::ThermalModel`]). With a tracker-frame model, column 0 grows the tracker-to-base
/// distance, which is not a robot link: leave it out there.
pub fn thermal_regressor(
    model: &LocalPoe,
    q: &[f64],
    tool: usize,
    delta_t_k: f64,
) -> Result<Vec<RegressorColumn>, Error> {
    model.forward(q, tool)?;
    let frames = model.frames(q)?;
    let before = std::iter::once(lie::SE3::identity()).chain(frames.iter().copied());
    let transforms =
        model.joints().iter().map(|j| j.previous_from_joint_zero).chain(std::iter::once(model.tools()[tool]));
    Ok(before
        .zip(transforms)
        .enumerate()
        .map(|(link_index, (frame, local))| {
            let v: Vector3 = frame.rotation().act(&local.translation()) * delta_t_k;
            RegressorColumn {
                parameter: EffectParameter::ThermalExpansion { link_index },
                twist: Vector6::new(v.x, v.y, v.z, 0.0, 0.0, 0.0),
            }
        })
        .collect())
}

/// Drift columns: `exp(t ξ̂) T` has the pose error `t ξ` exactly, so column `i` is `t e_i`.
pub fn drift_regressor(t_s: f64) -> [RegressorColumn; 6] {
    std::array::from_fn(|component| {
        let mut twist = Vector6::zeros();
        twist[component] = t_s;
        RegressorColumn { parameter: EffectParameter::DriftRate { component }, twist }
    })
}
