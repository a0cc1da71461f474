//! What a fit says of its effects: each parameter by name, its value, and whether the data
//! determined it or the prior held it.

use super::IdentifiedEffect;
use serde::Serialize;

/// One identified effect, for the fit report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectReport {
    /// The SPEC name (`joint_compliance`, `gear_periodic`, …).
    pub effect: &'static str,
    /// What it is and what drives it (`gear_periodic:1:24`, …).
    pub label: String,
    /// 1-based joints it acts on.
    pub joints: Vec<usize>,
    /// Its parameters.
    pub parameters: Vec<ParameterReport>,
}

/// One parameter of an effect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterReport {
    /// What it multiplies.
    pub name: String,
    /// Its value, in the unit of its scaled feature: the joint angle (rad), drift (m or rad) or
    /// strain it causes at the feature's RMS over the training rows.
    pub value: f64,
    /// The data barely determines it (posterior standard deviation above half the prior's): the
    /// prior holds it near zero.
    pub held_at_prior: bool,
}

/// The reports of `effects`, `held` the indices (over all their parameters, in order) that the
/// identification held at the prior.
pub fn effect_reports(effects: &[IdentifiedEffect], held: &[usize]) -> Vec<EffectReport> {
    let mut offset = 0;
    effects
        .iter()
        .map(|effect| {
            let parameters = effect
                .parameter_names()
                .into_iter()
                .zip(effect.theta())
                .enumerate()
                .map(|(l, (name, &value))| ParameterReport { name, value, held_at_prior: held.contains(&(offset + l)) })
                .collect();
            offset += effect.parameter_count();
            EffectReport { effect: effect.kind(), label: effect.label(), joints: effect.joints(), parameters }
        })
        .collect()
}
