//! What a fit says of its effects: each parameter by name, its value in the unit it is read in,
//! and whether the data determined it or the prior held it.
//!
//! A parameter's value is the effect's size at the RMS of its scaled feature over the training
//! rows, in the unit of the twist it moves the pose along ([`Direction`]): a joint's own unit for
//! a joint's displacement (rad, and mm for a prismatic joint: a linear axis reads in
//! millimetres everywhere), m or rad for a fixed twist's component, a strain for the arm's growth,
//! rad for a link's bending. On a prismatic joint the generalised force that gravity, a payload
//! or a drive exerts is a force along the axis, not a torque, and its names say so: a compliance
//! along the axis (mm at the RMS force), a backlash's half band in mm.

use super::IdentifiedEffect;
use crate::Direction;
use poe::JointKind;
use serde::Serialize;

/// Millimetres per metre: a prismatic joint's displacement is reported in mm.
const MM_PER_M: f64 = 1e3;

/// One identified effect, for the fit report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectReport {
    /// The SPEC name (`joint_compliance`, `gear_periodic`, …).
    pub effect: &'static str,
    /// What it is and what drives it (`gear_periodic:1:24`, …; a force, not a torque, where every
    /// joint it acts on is prismatic).
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
    /// Its value in [`ParameterReport::unit`]: the effect's size at the RMS of its scaled feature
    /// over the training rows (module doc).
    pub value: f64,
    /// The unit of `value`: `rad`, `mm` (a prismatic joint's displacement), `m`, or `strain`.
    pub unit: &'static str,
    /// The data barely determines it (posterior standard deviation above half the prior's): the
    /// prior holds it near zero.
    pub held_at_prior: bool,
}

/// The reports of `effects` on a robot whose joints are of `kinds`, `held` the indices (over all
/// their parameters, in order) that the identification held at the prior.
pub fn effect_reports(effects: &[IdentifiedEffect], held: &[usize], kinds: &[JointKind]) -> Vec<EffectReport> {
    let mut offset = 0;
    effects
        .iter()
        .map(|effect| {
            let parameters = reported_parameters(effect, kinds)
                .into_iter()
                .enumerate()
                .map(|(l, (name, value, unit))| ParameterReport {
                    name,
                    value,
                    unit,
                    held_at_prior: held.contains(&(offset + l)),
                })
                .collect();
            offset += effect.parameter_count();
            EffectReport {
                effect: effect.kind(),
                label: reported_label(effect, kinds),
                joints: effect.joints(),
                parameters,
            }
        })
        .collect()
}

/// Whether 0-based joint `joint` is prismatic among `kinds` (a joint beyond them is not).
fn prismatic(kinds: &[JointKind], joint: usize) -> bool {
    kinds.get(joint) == Some(&JointKind::Prismatic)
}

/// On a linear axis the generalised force is a force: the names the effects give for a revolute
/// joint's torque, said of a prismatic one.
fn as_force(text: &str) -> String {
    text.replace("torques", "forces").replace("torque", "force")
}

/// `effect`'s label, its torques called forces where every joint it acts on is prismatic.
pub fn reported_label(effect: &IdentifiedEffect, kinds: &[JointKind]) -> String {
    let joints = effect.joints();
    let label = effect.label();
    if !joints.is_empty() && joints.iter().all(|&j| prismatic(kinds, j - 1)) { as_force(&label) } else { label }
}

/// Each parameter of `effect` as a report shows it: its name, its value and the value's unit
/// (module doc), on a robot whose joints are of `kinds`.
pub fn reported_parameters(effect: &IdentifiedEffect, kinds: &[JointKind]) -> Vec<(String, f64, &'static str)> {
    effect
        .parameter_names()
        .into_iter()
        .zip(effect.theta())
        .zip(effect.directions())
        .map(|((name, &value), direction)| match direction {
            Direction::Joint(j) if prismatic(kinds, j) => (as_force(&name), value * MM_PER_M, "mm"),
            Direction::Joint(_) | Direction::LinkBend { .. } => (name, value, "rad"),
            Direction::Component(k) if k < 3 => (name, value, "m"),
            Direction::Component(_) => (name, value, "rad"),
            Direction::LinkGrowth => (name, value, "strain"),
        })
        .collect()
}
