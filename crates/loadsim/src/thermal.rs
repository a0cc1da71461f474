//! Thermal growth: every link length grows with temperature, `l' = l (1 + α ΔT)`, with
//! `ΔT = T − T_ref` (linear thermal expansion; the reference temperature of dimensional metrology
//! is 20 °C, ISO 1:2016).
//!
//! In the local POE model a link length is the translation of a constant transform
//! `T_{i-1,i}(0) = (R_i, t_i)`; growing it is the left perturbation
//! `(R_i, (1 + s) t_i) = exp(s (t_i, 0)^) · (R_i, t_i)`. Rotations do not change, so the tool
//! position `p = Σ_i R_{i-1}(q) t_i` is exactly linear in each strain `s_i = α_i ΔT`: the pose
//! change is `Σ_i s_i (R_{i-1}(q) t_i, 0)`, which [`crate::thermal_regressor`] returns.

use crate::Error;
use crate::{EntryFault, PoseContext, RobotFacts, SimulatedCell, SimulatedEffect, beyond};
use lie::{SE3, Vector3, Vector6};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// Thermal growth of the link lengths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ThermalModel {
    /// Temperature at which the model's lengths hold, °C. Default 20 (ISO 1).
    pub reference_temp_c: f64,
    /// Linear expansion coefficient of every link, 1/K. Default 12e-6, steel and cast iron
    /// (aluminium arms: about 23e-6).
    pub expansion_per_k: f64,
    /// Per-link coefficients overriding `expansion_per_k`: empty (default) or one per constant
    /// transform, joints first and the tool transform last (n + 1 entries).
    pub link_expansion_per_k: Vec<f64>,
}

impl Default for ThermalModel {
    fn default() -> Self {
        Self { reference_temp_c: 20.0, expansion_per_k: 12e-6, link_expansion_per_k: Vec::new() }
    }
}

impl ThermalModel {
    /// Checks the values against a robot with `joint_count` joints.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        if !self.reference_temp_c.is_finite() {
            return Err(Error::from(dynamics::Error::InvalidParameter {
                field: "thermal.reference_temp_c",
                value: self.reference_temp_c,
            }));
        }
        if !self.link_expansion_per_k.is_empty() && self.link_expansion_per_k.len() != joint_count + 1 {
            return Err(Error::from(dynamics::Error::LengthMismatch {
                field: "thermal.link_expansion_per_k",
                given: self.link_expansion_per_k.len(),
                expected: joint_count + 1,
            }));
        }
        match std::iter::once(&self.expansion_per_k).chain(&self.link_expansion_per_k).find(|a| !a.is_finite()) {
            Some(&value) => {
                Err(Error::from(dynamics::Error::InvalidParameter { field: "thermal.expansion_per_k", value }))
            }
            None => Ok(()),
        }
    }

    /// The expansion coefficient of each of the n + 1 constant transforms, 1/K.
    pub fn coefficients(&self, joint_count: usize) -> Vec<f64> {
        if self.link_expansion_per_k.is_empty() {
            vec![self.expansion_per_k; joint_count + 1]
        } else {
            self.link_expansion_per_k.clone()
        }
    }

    /// The model with every link length grown to temperature `temp_c`: joint `i`'s constant
    /// transform by `1 + α_i ΔT`, every tool transform by `1 + α_{n+1} ΔT`.
    pub fn grown_model(&self, model: &LocalPoe, temp_c: f64) -> Result<LocalPoe, Error> {
        self.validate(model.joint_count())?;
        if !temp_c.is_finite() {
            return Err(Error::from(dynamics::Error::InvalidParameter { field: "temp_c", value: temp_c }));
        }
        let delta = temp_c - self.reference_temp_c;
        let coefficients = self.coefficients(model.joint_count());
        let grow = |t: &SE3, alpha: f64| SE3::new(t.rotation(), t.translation() * (1.0 + alpha * delta));
        let mut grown = model.clone();
        for (joint, &alpha) in grown.joints_mut().iter_mut().zip(&coefficients) {
            joint.previous_from_joint_zero = grow(&joint.previous_from_joint_zero, alpha);
        }
        let tool_alpha = coefficients[model.joint_count()];
        grown.set_tools(model.tools().iter().map(|t| grow(t, tool_alpha)).collect());
        Ok(grown)
    }
}

/// Largest thermal expansion coefficient an effects file may give, 1/K: engineering solids lie
/// below 2e-4 (steel 1.2e-5, aluminium 2.3e-5, plastics up to 2e-4).
pub const MAX_EXPANSION_PER_K: f64 = 1e-3;

/// Largest magnitude of a reference temperature an effects file may give, °C.
pub const MAX_TEMPERATURE_C: f64 = 1e4;

impl SimulatedEffect for ThermalModel {
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        ThermalModel::validate(self, cell.robot.joint_count())
    }

    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        ThermalModel::validate(self, robot.joints.len()).map_err(|e| EntryFault::of_section(&e))?;
        let mut bounds = vec![
            ("reference_temp_c", self.reference_temp_c, MAX_TEMPERATURE_C),
            ("expansion_per_k", self.expansion_per_k, MAX_EXPANSION_PER_K),
        ];
        bounds.extend(self.link_expansion_per_k.iter().map(|&a| ("link_expansion_per_k", a, MAX_EXPANSION_PER_K)));
        match bounds.iter().find_map(|b| beyond(&[*b]).map(|f| (b.0, f))) {
            Some((field, message)) => Err(EntryFault { field: field.into(), index: 0, message }),
            None => Ok(()),
        }
    }

    fn grown_model(&self, model: &LocalPoe, context: &PoseContext) -> Result<Option<LocalPoe>, Error> {
        self.grown_model(model, context.temp_c).map(Some)
    }
}

/// The pose change per unit of each expansion coefficient, one per constant transform (n joints,
/// then the tool): growing transform `i` by the strain `α_i ΔT` moves the pose by
/// `α_i ΔT (R_{i-1}(q) t_i, 0)` exactly (module doc), a left-perturbation twist `(v, ω)` in the
/// model's reference frame. With a tracker-frame model, entry 0 grows the tracker-to-base
/// distance, which is not a robot link: leave it out there.
pub fn thermal_regressor(model: &LocalPoe, q: &[f64], tool: usize, delta_t_k: f64) -> Result<Vec<Vector6>, Error> {
    model.forward(q, tool)?;
    let frames = model.frames(q)?;
    let before = std::iter::once(SE3::identity()).chain(frames.iter().copied());
    let transforms =
        model.joints().iter().map(|j| j.previous_from_joint_zero).chain(std::iter::once(model.tools()[tool]));
    Ok(before
        .zip(transforms)
        .map(|(frame, local)| {
            let v: Vector3 = frame.rotation().act(&local.translation()) * delta_t_k;
            Vector6::new(v.x, v.y, v.z, 0.0, 0.0, 0.0)
        })
        .collect())
}
