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
//! unit twist times `|ξ_a + Σ m_i ξ_i|`, the joint's `scale`.
//!
//! Shipped URDFs often draw a telescopic column (or a gripper) as one actuated joint that moves a
//! pseudo link beside the chain, the chain itself running through two or more mimic stages of it.
//! The driver's value is still the joint value (the measurements' column for that motor): its
//! stages fold the same way with `ξ_a` left out of the sum, `exp((Σ m_i ξ_i) q) · C`, and the
//! joint takes the driver's kind and limits. Anything else (a parallelogram's mimic on a parallel
//! but offset axis, stages of one driver with another joint moving between them, a driver that is
//! itself a mimic or moves the chain's base link, a revolute stage on a prismatic joint) does not
//! commute or does not close on the chain and is refused.

use crate::urdf_steps::{ChainStep, StepMotion};
use crate::{FoldedJoint, MimicStage};
use lie::{SE3, SO3, Vector3};
use std::collections::HashMap;

/// One joint of the description: an actuated joint and the mimic joints folded into it.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainJoint {
    /// The joint's first step on the chain, as an index into the chain's steps: its actuated
    /// joint, or its first mimic stage where the joint that drives the stages is beside the chain.
    pub first: usize,
    /// The mimic joints that follow it, as indices into the chain's steps, base first (`first`
    /// among them where the driver is beside the chain).
    pub stages: Vec<usize>,
    /// The actuated joint where it is not on the chain (a column's motor moving a pseudo link):
    /// read as a step of its own, whose `from_to` means nothing for the chain.
    pub driver_beside: Option<ChainStep>,
    /// The unit direction of the summed motion in the base link's frame at the zero configuration
    /// (the actuated joint's axis where nothing is folded).
    pub direction: Vector3,
    /// The summed motion per unit of the joint value, `|ξ_a + Σ m_i ξ_i|` (1 where nothing is folded).
    pub scale: f64,
}

impl ChainJoint {
    /// The actuated joint: its value is the joint value, its kind and limits the joint's.
    pub fn actuated<'a>(&'a self, steps: &'a [ChainStep]) -> &'a ChainStep {
        self.driver_beside.as_ref().unwrap_or(&steps[self.first])
    }
}

/// A joint that chain steps follow but that is not on the chain, as the chain's reader found it.
#[derive(Debug, Clone)]
pub(crate) enum OffChain {
    /// A joint above the chain's base link: it moves the base link itself.
    AboveBase,
    /// A floating or planar joint (its type's name): it drives no stage the chain can fold.
    Unsupported(&'static str),
    /// A joint beside the chain, read as a step.
    Beside(Box<ChainStep>),
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

/// The chain's joints with every mimic joint folded into the joint it follows. `frames` are the
/// steps' `base_from_to_link` at the zero configuration (mimics at their offsets), `off_chain`
/// the joints the chain's mimic joints follow that are defined in the URDF but not on the chain.
pub(crate) fn fold(
    steps: &[ChainStep],
    frames: &[SE3],
    off_chain: &HashMap<String, OffChain>,
) -> Result<Vec<ChainJoint>, FoldRefusal> {
    let mut joints: Vec<ChainJoint> = Vec::new();
    for (k, step) in steps.iter().enumerate() {
        if step.motion == StepMotion::Fixed {
            continue;
        }
        let Some(mimic) = &step.mimic else {
            joints.push(ChainJoint {
                first: k,
                stages: Vec::new(),
                driver_beside: None,
                direction: base_axis(steps, frames, k),
                scale: 1.0,
            });
            continue;
        };
        let refuse = |message: String| FoldRefusal { step: k, message };
        let Some(a) = steps.iter().position(|s| s.joint == mimic.joint) else {
            fold_beside(steps, frames, k, off_chain.get(&mimic.joint), &mut joints).map_err(refuse)?;
            continue;
        };
        fold_on_chain(steps, frames, a, k, &mimic.joint, &mut joints).map_err(refuse)?;
    }
    for joint in &mut joints {
        if !joint.stages.is_empty() {
            sum_stages(joint, steps, frames)?;
        }
    }
    Ok(joints)
}

/// Step `k`'s axis in the base link's frame at the zero configuration.
fn base_axis(steps: &[ChainStep], frames: &[SE3], k: usize) -> Vector3 {
    frames[k].rotation().act(&steps[k].axis)
}

/// Folds the mimic step `k` into the joint of step `a`, the chain's joint `driver` it follows: a movable,
/// actuated joint nearer the base, of the same kind and on the same line, with only fixed joints
/// or its other stages between them. The message says why it does not fold.
fn fold_on_chain(
    steps: &[ChainStep],
    frames: &[SE3],
    a: usize,
    k: usize,
    driver: &str,
    joints: &mut [ChainJoint],
) -> Result<(), String> {
    let (step, actuated) = (&steps[k], &steps[a]);
    if actuated.motion == StepMotion::Fixed {
        return Err(format!("follows joint '{driver}', a fixed joint"));
    }
    if actuated.mimic.is_some() {
        return Err(format!("follows joint '{driver}', itself a mimic joint: name the joint that drives both"));
    }
    if a > k {
        return Err(format!(
            "follows joint '{driver}', further from the base: only stages after the joint that drives them are folded"
        ));
    }
    // Every movable joint between the actuated joint and this one must be another of its stages.
    let between = steps[a + 1..k]
        .iter()
        .find(|s| s.motion != StepMotion::Fixed && s.mimic.as_ref().is_none_or(|m| m.joint != driver));
    if let Some(other) = between {
        return Err(format!(
            "follows joint '{driver}', but joint '{}' moves between them: the stages' motions do not add into one \
             joint (only stages separated from the joint that drives them by fixed joints fold)",
            other.joint
        ));
    }
    same_kind(step, actuated)?;
    coaxial(steps, frames, a, k)?;
    let Some(joint) = joints.iter_mut().find(|j| j.first == a && j.driver_beside.is_none()) else {
        return Err(format!("follows joint '{driver}', which is not a joint of the chain"));
    };
    joint.stages.push(k);
    Ok(())
}

/// The joint's direction and scale from its actuated joint's twist and its stages' (each times
/// its multiplier): refused, at its last stage, where the sum is outside the scale's bounds.
fn sum_stages(joint: &mut ChainJoint, steps: &[ChainStep], frames: &[SE3]) -> Result<(), FoldRefusal> {
    // A driver beside the chain moves nothing on it: only its stages' motions add.
    let own = if joint.driver_beside.is_some() { Vector3::zeros() } else { base_axis(steps, frames, joint.first) };
    let sum = joint
        .stages
        .iter()
        .fold(own, |sum, &k| sum + base_axis(steps, frames, k) * steps[k].mimic.as_ref().map_or(0.0, |m| m.multiplier));
    let scale = sum.norm();
    let last = joint.stages.last().copied().unwrap_or(joint.first);
    if !crate::description::scale_in_bounds(scale) {
        let (lo, hi) = crate::description::SCALE_BOUNDS;
        let name = &joint.actuated(steps).joint;
        return Err(FoldRefusal {
            step: last,
            message: format!(
                "with joint '{name}' and its other stages it moves {scale:e} per unit of '{name}', outside {lo:e} \
                 … {hi:e}: {}",
                if scale < lo { "the stages cancel, the motor moves nothing" } else { "no stage train gears so far" }
            ),
        });
    }
    joint.direction = sum / scale;
    joint.scale = scale;
    Ok(())
}

/// Folds the mimic step `k`, whose driver is not on the chain (`driver` as the chain's reader
/// found it, `None` where the URDF does not define it), into the joint of that driver's stages
/// (made at its first stage). The message says why it does not fold.
fn fold_beside(
    steps: &[ChainStep],
    frames: &[SE3],
    k: usize,
    driver: Option<&OffChain>,
    joints: &mut Vec<ChainJoint>,
) -> Result<(), String> {
    let Some(mimic) = &steps[k].mimic else { return Ok(()) };
    let name = &mimic.joint;
    let driver = match driver {
        None => return Err(format!("follows joint '{name}', which the URDF does not define")),
        Some(OffChain::AboveBase) => {
            return Err(format!(
                "follows joint '{name}', which moves the chain's base link itself: the chain's motion would depend \
                 on a joint whose motion the measurements do not see; choose a base link above it with --base-link"
            ));
        }
        Some(OffChain::Unsupported(kind)) => {
            return Err(format!(
                "follows joint '{name}', a {kind} joint: only a revolute, continuous or prismatic joint drives stages"
            ));
        }
        Some(OffChain::Beside(driver)) => driver.as_ref(),
    };
    if driver.motion == StepMotion::Fixed {
        return Err(format!("follows joint '{name}', a fixed joint"));
    }
    if let Some(other) = &driver.mimic {
        return Err(format!(
            "follows joint '{name}', beside the chain, which is itself a mimic joint of '{}': a stage's motion \
             would be a second fold away from any joint the measurements carry; name the joint that drives both",
            other.joint
        ));
    }
    same_kind(&steps[k], driver)?;
    let Some(joint) = joints.iter_mut().find(|j| j.driver_beside.as_ref().is_some_and(|d| d.joint == *name)) else {
        joints.push(ChainJoint {
            first: k,
            stages: vec![k],
            driver_beside: Some(driver.clone()),
            direction: frames[k].rotation().act(&steps[k].axis),
            scale: 1.0,
        });
        return Ok(());
    };
    // Stages are pushed base first, so a movable joint after the last one is not a stage of it.
    let last = joint.stages.last().copied().unwrap_or(joint.first);
    if let Some(other) = steps[last + 1..k].iter().find(|s| s.motion != StepMotion::Fixed) {
        return Err(format!(
            "follows joint '{name}' as stage '{}' does, but joint '{}' moves between them: the stages' motions do \
             not add into one joint (only stages separated from each other by fixed joints fold)",
            steps[last].joint, other.joint
        ));
    }
    coaxial(steps, frames, joint.first, k)?;
    joint.stages.push(k);
    Ok(())
}

fn kind_name(motion: StepMotion) -> &'static str {
    match motion {
        StepMotion::Fixed => "fixed",
        StepMotion::Revolute { .. } => "revolute",
        StepMotion::Prismatic { .. } => "prismatic",
    }
}

/// Refuses a stage of another kind than the joint it follows: a turn and a slide do not add.
fn same_kind(stage: &ChainStep, actuated: &ChainStep) -> Result<(), String> {
    let (kind, actuated_kind) = (kind_name(stage.motion), kind_name(actuated.motion));
    if kind != actuated_kind {
        return Err(format!(
            "a {kind} joint following the {actuated_kind} joint '{}': only translations, or rotations about one line, \
             add into one joint",
            actuated.joint
        ));
    }
    Ok(())
}

/// Refuses a revolute stage `k` whose axis is not the line of step `a` (the joint it follows, or
/// the first stage of a driver beside the chain); prismatic stages always commute.
fn coaxial(steps: &[ChainStep], frames: &[SE3], a: usize, k: usize) -> Result<(), String> {
    if !matches!(steps[k].motion, StepMotion::Revolute { .. }) {
        return Ok(());
    }
    let (u, v) = (frames[a].rotation().act(&steps[a].axis), frames[k].rotation().act(&steps[k].axis));
    let angle = u.cross(&v).norm().atan2(u.dot(&v).abs());
    let offset = frames[k].translation() - frames[a].translation();
    let distance = (offset - u * u.dot(&offset)).norm();
    let other = &steps[a].joint;
    if angle > COAXIAL_ANGLE_RAD {
        return Err(format!(
            "its axis is at {:.4} deg to the axis of joint '{other}': only rotations about one line add into one \
             joint",
            angle.to_degrees()
        ));
    }
    if distance > COAXIAL_DISTANCE_M {
        return Err(format!(
            "its axis is parallel to the axis of joint '{other}' but {distance:.6} m from it (a parallelogram): \
             rotations about different lines do not add into one joint, and the loop they close cannot be \
             calibrated as a serial chain"
        ));
    }
    Ok(())
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
    Some(FoldedJoint { joint: index + 1, actuated: joint.actuated(steps).joint.clone(), stages, scale: joint.scale })
}
