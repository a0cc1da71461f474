//! Mimic joints (`<mimic joint=".." multiplier=".." offset=".."/>`) folded into the joint that
//! drives them, so that the description has one joint where the hardware has one motor.
//!
//! A stage train folds exactly where its motions commute: the actuated joint's twist `ξ_a` and
//! each mimic's `m_i ξ_i` (spatial twists at the zero configuration), separated by fixed joints
//! only, give `exp(ξ_a q) F_1 exp(ξ_1 (m_1 q + o_1)) F_2 … = exp((ξ_a + Σ m_i ξ_i) q) · C` whenever
//! the twists commute: parallel translations (any prismatic stages: translations commute with
//! each other, and the fixed rotations between them only turn their directions), or rotations
//! about one line (coaxial revolute stages: the angles add). The offsets `o_i` go into the fixed
//! transforms `C` (the zero configuration has the mimics at their offsets). The summed twist is a
//! unit twist times `|ξ_a + Σ m_i ξ_i|`, the joint's `scale`. Anything else (a parallelogram's
//! mimic on a parallel but offset axis, a mimic of a joint off the chain, a movable joint between
//! the stages, a revolute stage on a prismatic joint) does not commute and is refused.

use crate::urdf_steps::{ChainStep, StepMotion};
use crate::{FoldedJoint, MimicStage};
use lie::{SE3, SO3, Vector3};

/// One joint of the description: an actuated joint of the chain and the mimic joints folded into it.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainJoint {
    /// The actuated joint, as an index into the chain's steps.
    pub actuated: usize,
    /// The mimic joints that follow it, as indices into the chain's steps.
    pub stages: Vec<usize>,
    /// The unit direction of the summed motion in the base link's frame at the zero configuration
    /// (the actuated joint's axis where nothing is folded).
    pub direction: Vector3,
    /// The summed motion per unit of the joint value, `|ξ_a + Σ m_i ξ_i|` (1 where nothing is folded).
    pub scale: f64,
}

/// Largest angle between two revolute stages' axes, and largest distance of one stage's axis from
/// the actuated joint's, for them to count as one line: the fold is exact only for coaxial stages,
/// and 1 µm or 1 µrad of misalignment moves the tool by less than a tracker resolves (≈ 10 µm),
/// while a URDF's axes written to six decimals stay within it.
const COAXIAL_ANGLE_RAD: f64 = 1e-6;
/// See [`COAXIAL_ANGLE_RAD`].
const COAXIAL_DISTANCE_M: f64 = 1e-6;

/// Why a chain's mimic joints do not fold: the step at fault and what to say.
#[derive(Debug)]
pub(crate) struct FoldRefusal {
    /// The mimic joint's step.
    pub step: usize,
    /// The message (without the joint's name in front).
    pub message: String,
}

impl ChainStep {
    /// The step's own motion at the chain's zero configuration, in its `to_link` frame: the
    /// identity, but a mimic joint's offset.
    pub fn zero_motion(&self) -> SE3 {
        let Some(mimic) = &self.mimic else { return SE3::identity() };
        match self.motion {
            StepMotion::Fixed => SE3::identity(),
            StepMotion::Revolute { .. } => SE3::new(SO3::exp(&(self.axis * mimic.offset)), Vector3::zeros()),
            StepMotion::Prismatic { .. } => SE3::from_translation(self.axis * mimic.offset),
        }
    }
}

fn kind_name(motion: StepMotion) -> &'static str {
    match motion {
        StepMotion::Fixed => "fixed",
        StepMotion::Revolute { .. } => "revolute",
        StepMotion::Prismatic { .. } => "prismatic",
    }
}

/// The chain's joints with every mimic joint folded into the joint it follows. `frames` are the
/// steps' `base_from_to_link` at the zero configuration (mimics at their offsets), `defined`
/// tells whether the URDF has a joint of that name at all.
pub(crate) fn fold(
    steps: &[ChainStep],
    frames: &[SE3],
    defined: &dyn Fn(&str) -> bool,
) -> Result<Vec<ChainJoint>, FoldRefusal> {
    let axis = |k: usize| frames[k].rotation().act(&steps[k].axis);
    let mut joints: Vec<ChainJoint> = Vec::new();
    for (k, step) in steps.iter().enumerate() {
        if step.motion == StepMotion::Fixed {
            continue;
        }
        let Some(mimic) = &step.mimic else {
            joints.push(ChainJoint { actuated: k, stages: Vec::new(), direction: axis(k), scale: 1.0 });
            continue;
        };
        let refuse = |message: String| FoldRefusal { step: k, message };
        let Some(a) = steps.iter().position(|s| s.joint == mimic.joint) else {
            return Err(refuse(if defined(&mimic.joint) {
                format!(
                    "follows joint '{}', which is not on the calibrated chain: the chain's motion would depend on a \
                     joint the measurements do not carry; choose the chain's ends with --base-link/--tip-link",
                    mimic.joint
                )
            } else {
                format!("follows joint '{}', which the URDF does not define", mimic.joint)
            }));
        };
        let actuated = &steps[a];
        if actuated.motion == StepMotion::Fixed {
            return Err(refuse(format!("follows joint '{}', a fixed joint", mimic.joint)));
        }
        if actuated.mimic.is_some() {
            return Err(refuse(format!(
                "follows joint '{}', itself a mimic joint: name the joint that drives both",
                mimic.joint
            )));
        }
        if a > k {
            return Err(refuse(format!(
                "follows joint '{}', further from the base: only stages after the joint that drives them are folded",
                mimic.joint
            )));
        }
        // Every movable joint between the actuated joint and this one must be another of its stages.
        let between = steps[a + 1..k]
            .iter()
            .find(|s| s.motion != StepMotion::Fixed && s.mimic.as_ref().is_none_or(|m| m.joint != mimic.joint));
        if let Some(other) = between {
            return Err(refuse(format!(
                "follows joint '{}', but joint '{}' moves between them: the stages' motions do not add into one \
                 joint (only stages separated from the joint that drives them by fixed joints fold)",
                mimic.joint, other.joint
            )));
        }
        let (kind, actuated_kind) = (kind_name(step.motion), kind_name(actuated.motion));
        if kind != actuated_kind {
            return Err(refuse(format!(
                "a {kind} joint following the {actuated_kind} joint '{}': only translations, or rotations about one \
                 line, add into one joint",
                mimic.joint
            )));
        }
        if matches!(step.motion, StepMotion::Revolute { .. }) {
            let (u, v) = (axis(a), axis(k));
            let angle = u.cross(&v).norm().atan2(u.dot(&v).abs());
            let offset = frames[k].translation() - frames[a].translation();
            let distance = (offset - u * u.dot(&offset)).norm();
            if angle > COAXIAL_ANGLE_RAD {
                return Err(refuse(format!(
                    "its axis is at {:.4} deg to the axis of joint '{}': only rotations about one line add into one \
                     joint",
                    angle.to_degrees(),
                    mimic.joint
                )));
            }
            if distance > COAXIAL_DISTANCE_M {
                return Err(refuse(format!(
                    "its axis is parallel to the axis of joint '{}' but {:.6} m from it (a parallelogram): rotations \
                     about different lines do not add into one joint, and the loop they close cannot be calibrated \
                     as a serial chain",
                    mimic.joint, distance
                )));
            }
        }
        let Some(joint) = joints.iter_mut().find(|j| j.actuated == a) else {
            return Err(refuse(format!("follows joint '{}', which is not a joint of the chain", mimic.joint)));
        };
        joint.stages.push(k);
    }
    for joint in &mut joints {
        if joint.stages.is_empty() {
            continue;
        }
        let sum = joint.stages.iter().fold(axis(joint.actuated), |sum, &k| {
            sum + axis(k) * steps[k].mimic.as_ref().map_or(0.0, |m| m.multiplier)
        });
        let scale = sum.norm();
        let last = joint.stages.last().copied().unwrap_or(joint.actuated);
        if !crate::description::scale_in_bounds(scale) {
            let (lo, hi) = crate::description::SCALE_BOUNDS;
            return Err(FoldRefusal {
                step: last,
                message: format!(
                    "with joint '{}' and its other stages it moves {scale:e} per unit of '{}', outside {lo:e} … {hi:e}: \
                     {}",
                    steps[joint.actuated].joint,
                    steps[joint.actuated].joint,
                    if scale < lo {
                        "the stages cancel, the motor moves nothing"
                    } else {
                        "no stage train gears so far"
                    }
                ),
            });
        }
        joint.direction = sum / scale;
        joint.scale = scale;
    }
    Ok(joints)
}

/// What a folded joint of the description records: the URDF joints and their multipliers.
pub(crate) fn folded_joint(index: usize, joint: &ChainJoint, steps: &[ChainStep]) -> Option<FoldedJoint> {
    if joint.stages.is_empty() {
        return None;
    }
    let stages = joint
        .stages
        .iter()
        .filter_map(|&k| {
            let mimic = steps[k].mimic.as_ref()?;
            Some(MimicStage { joint: steps[k].joint.clone(), multiplier: mimic.multiplier, offset: mimic.offset })
        })
        .collect();
    Some(FoldedJoint { joint: index + 1, actuated: steps[joint.actuated].joint.clone(), stages, scale: joint.scale })
}
