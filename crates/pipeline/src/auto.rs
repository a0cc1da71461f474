//! `--effects auto`: the effects `calib diagnose` selects on the training data, as a list the fit
//! identifies (its `selected` effects, with their joints and harmonic orders).

use diagnose::{DiagnoseOptions, SelectedEffect, Verdict, diagnose_bound};
use effects::{Argument, EffectSpec};
use errors::Error;
use measurements::BoundSet;
use robot::RobotDescription;
use serde::Serialize;

/// What `auto` chose and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AutoChoice {
    /// The diagnosis's verdict on the training data.
    pub verdict: Verdict,
    /// The effects its selection kept, in order, with the cross-validated error after each.
    pub selected: Vec<SelectedEffect>,
    /// Cross-validated mean position error of the geometric model on the training data, mm.
    pub heldout_before_mm: f64,
    /// The same with every selected effect: the prediction for poses like the training poses, mm.
    #[serde(default)]
    pub heldout_after_mm: f64,
    /// The diagnosis's prediction off the training poses (arcs of each moving joint held out),
    /// without and with the selected effects, mm.
    #[serde(default)]
    pub off_poses_mm: Option<[f64; 2]>,
    /// The effects the fit identifies.
    #[serde(serialize_with = "as_text")]
    pub chosen: Vec<EffectSpec>,
    /// For a method with a GP stage: the same two predictions with the fit's GP on top of each
    /// fold's geometry and effects (module `gp_folds`; absent without a GP, for the sparse GP and
    /// for the tracker-frame residual).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_with_gp: Option<crate::PredictedWithGp>,
    /// The diagnosis's folds, for the GP's prediction (not in the JSON).
    #[serde(skip)]
    pub folds: diagnose::HeldoutFolds,
}

fn as_text<S: serde::Serializer>(specs: &[EffectSpec], serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(specs.iter().map(ToString::to_string))
}

/// The list the fit identifies for a diagnosis's selection, read from each kind's arguments: one
/// item per joint the selection names for a kind that takes a joint (backlash, gear error), one
/// item for a kind that does not (compliance: the fit's `joint_compliance` covers every joint;
/// thermal growth, drift), a series at the highest order selected for it (the series runs from
/// harmonic 1).
pub fn effects_of(selected: &[SelectedEffect]) -> Vec<EffectSpec> {
    let mut specs: Vec<EffectSpec> = Vec::new();
    for s in selected {
        let Some(kind) = s.effect.kind() else { continue };
        let mut template = EffectSpec::new(kind);
        let arguments = template.arguments();
        if arguments.contains(&Argument::Harmonics) {
            template.harmonics = Some(s.harmonic.unwrap_or(1).max(1));
        }
        let new: Vec<EffectSpec> = if arguments.contains(&Argument::Joint) {
            s.joints.iter().map(|&joint| EffectSpec { joint: Some(joint), ..template }).collect()
        } else {
            vec![template]
        };
        for spec in new {
            match specs.iter_mut().find(|s| s.overlaps(&spec)) {
                Some(old) => {
                    if let (Some(a), Some(b)) = (old.harmonics, spec.harmonics) {
                        old.harmonics = Some(a.max(b));
                    }
                }
                None => specs.push(spec),
            }
        }
    }
    specs
}

/// Runs the diagnosis on the training data, bound to `robot` as the fit binds it
/// ([`measurements::BoundSet::to_robot`]), and returns what its selection keeps.
pub fn choose(robot: &RobotDescription, data: &BoundSet<'_>, options: &DiagnoseOptions) -> Result<AutoChoice, Error> {
    let diagnosis = diagnose_bound(robot, data, options)?;
    let mut chosen = effects_of(&diagnosis.selected);
    // A screw's pitch is the robot file's (the diagnosis offers the screw only where it is stated),
    // written into the item so that the report shows one that `--effects` reads back.
    for spec in &mut chosen {
        if spec.arguments().contains(&Argument::Pitch) && spec.pitch_mm.is_none() {
            spec.pitch_mm = spec.joint.and_then(|j| robot.joints.get(j - 1)).and_then(|j| j.pitch_mm);
        }
    }
    Ok(AutoChoice {
        chosen,
        verdict: diagnosis.verdict,
        selected: diagnosis.selected,
        heldout_before_mm: diagnosis.heldout_before_mm,
        heldout_after_mm: diagnosis.heldout_after_selected_mm,
        off_poses_mm: diagnosis.off_poses_before_mm.zip(diagnosis.off_poses_after_mm).map(|(b, a)| [b, a]),
        predicted_with_gp: None,
        folds: diagnosis.folds,
    })
}
