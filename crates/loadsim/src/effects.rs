//! All effects together: which are on, and the forward model from commanded joint values to the
//! measured tool pose. [`Effects`] is generated from the one list of kinds (module `kinds`): a
//! field per kind, named and typed as its line says; the forward model walks the effects that are
//! on through [`SimulatedEffect`], in the list's order.

use crate::{
    BacklashModel, EffectKind, Error, GearPeriodicModel, JointBacklash, JointComplianceModel, PoseContext, PoseInput,
    SimulatedCell, SimulatedEffect, ThermalModel, TrackerNoiseModel, gravity::static_torque, periodic::Harmonic,
};
use crate::{TimeDriftModel, effect_kinds};
use lie::SE3;
use rand::Rng;
use serde::{Deserialize, Serialize};

macro_rules! effects_struct {
    (identified { $( $(#[$doc:meta])* $kind:ident $name:ident: $term:ident
                     $(=> $field:ident $(| $former:literal)?: $sim:ty)?, )* }
     simulated { $( $(#[$sdoc:meta])* $skind:ident $sname:ident => $sfield:ident: $ssim:ty, )* }) => {
        /// Which effects act and with which parameters, a field per kind of
        /// [`effect_kinds!`](crate::effect_kinds) that the simulator models (named as its line
        /// says; serde spells each as the SPEC name, the spelling of files before SPEC version 5
        /// still read); `None` switches an effect off. The default has none: the measured pose is then
        /// the geometric model's.
        #[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
        #[serde(default)]
        pub struct Effects {
            $( $(
                #[doc = concat!("[`EffectKind::", stringify!($kind), "`] (`", stringify!($name), "`): its simulation, `None` when off.")]
                $( #[serde(alias = $former)] )?
                pub $field: Option<$sim>,
            )? )*
            $( $(#[$sdoc])* pub $sfield: Option<$ssim>, )*
        }

        impl Effects {
            /// The effects that are on, with their kinds, in the list's order.
            pub fn active(&self) -> Vec<(EffectKind, &dyn SimulatedEffect)> {
                let mut on: Vec<(EffectKind, &dyn SimulatedEffect)> = Vec::new();
                $( $( if let Some(effect) = &self.$field { on.push((EffectKind::$kind, effect)); } )? )*
                $( if let Some(effect) = &self.$sfield { on.push((EffectKind::$skind, effect)); } )*
                on
            }

            /// These effects with only `kind` left on (with its parameters here; off if it is off
            /// here, or not simulated).
            pub fn only(&self, kind: EffectKind) -> Self {
                let mut alone = Effects::default();
                match kind {
                    $( EffectKind::$kind => { $( alone.$field = self.$field.clone(); )? } )*
                    $( EffectKind::$skind => alone.$sfield = self.$sfield.clone(), )*
                }
                alone
            }

            /// Whether `kind` is on (never for a kind the simulator does not model).
            pub fn is_on(&self, kind: EffectKind) -> bool {
                match kind {
                    $( EffectKind::$kind => false $( || self.$field.is_some() )?, )*
                    $( EffectKind::$skind => self.$sfield.is_some(), )*
                }
            }
        }
    };
}

effect_kinds!(effects_struct);

/// The joint-space part of the forward model at one pose, each effect apart.
#[derive(Debug, Clone, PartialEq)]
pub struct JointOffsets {
    /// Static torque (gravity, payload, balancer) at the commanded joints, N·m; empty when the
    /// robot has no dynamics.
    pub static_torque_nm: Vec<f64>,
    /// The joint offsets of each effect that is on and moves the joints, in the list's order
    /// (rad, m on a prismatic joint).
    pub by_kind: Vec<(EffectKind, Vec<f64>)>,
    joint_count: usize,
}

impl JointOffsets {
    /// The joint offsets of `kind` (zero where it is off or moves no joint).
    pub fn of(&self, kind: EffectKind) -> Vec<f64> {
        self.by_kind.iter().find(|(k, _)| *k == kind).map_or_else(|| vec![0.0; self.joint_count], |(_, dq)| dq.clone())
    }

    /// The sum of the joint-space effects (rad, m on a prismatic joint), in the list's order.
    pub fn total(&self) -> Vec<f64> {
        let mut total = vec![0.0; self.joint_count];
        for (_, dq) in &self.by_kind {
            for (t, d) in total.iter_mut().zip(dq) {
                *t += d;
            }
        }
        total
    }
}

impl Effects {
    /// Every effect on, with plausible magnitudes for a 60 kg-class arm (engineering estimates):
    /// compliance from the robot's stiffness; backlash half-band 0.25 arcmin on every joint
    /// (a quarter of the ≤ 1 arcmin lost motion RV reducer catalogues allow); gear error
    /// of orders 1 and 2 with 20 and 10 µrad amplitude on joints 1–3; steel thermal growth;
    /// the default drift and AT901/T-Mac noise.
    pub fn typical(joint_count: usize) -> Self {
        let half_band = (0.25_f64 / 60.0).to_radians();
        let harmonics = (0..joint_count.min(3))
            .flat_map(|j| {
                let phase = 0.7 * (j as f64 + 1.0);
                [
                    Harmonic { joint_index: j, order: 1.0, amplitude_rad: 20e-6, phase_rad: phase },
                    Harmonic { joint_index: j, order: 2.0, amplitude_rad: 10e-6, phase_rad: 2.0 * phase },
                ]
            })
            .collect();
        Self {
            joint_compliance: Some(JointComplianceModel::default()),
            backlash: Some(BacklashModel {
                joints: (0..joint_count)
                    .map(|joint_index| JointBacklash { joint_index, half_band_rad: half_band })
                    .collect(),
            }),
            gear_periodic: Some(GearPeriodicModel { harmonics }),
            thermal: Some(ThermalModel::default()),
            time_drift: Some(TimeDriftModel::default()),
            tracker_noise: Some(TrackerNoiseModel::default()),
            ..Effects::default()
        }
    }

    /// Checks every active effect against the cell: indices inside the robot, finite values,
    /// dynamics present where an effect needs them.
    pub fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        if cell.tool >= cell.robot.tool_count() {
            return Err(poe::Error::UnknownTool { tool: cell.tool, tool_count: cell.robot.tool_count() }.into());
        }
        for (_, effect) in self.active() {
            effect.validate(cell)?;
        }
        Ok(())
    }

    /// The base-frame model at this pose's temperature (grown if thermal growth is on).
    fn model_at(&self, cell: &SimulatedCell, context: &PoseContext) -> Result<poe::LocalPoe, Error> {
        let mut model = cell.robot.clone();
        for (_, effect) in self.active() {
            if let Some(grown) = effect.grown_model(&model, context)? {
                model = grown;
            }
        }
        Ok(model)
    }

    /// The joint-space effects at commanded joints `q`, each apart.
    pub fn joint_offsets(&self, cell: &SimulatedCell, q: &[f64], context: &PoseContext) -> Result<JointOffsets, Error> {
        self.validate(cell)?;
        let model = self.model_at(cell, context)?;
        self.joint_offsets_on(&model, cell, q, context)
    }

    fn joint_offsets_on(
        &self,
        model: &poe::LocalPoe,
        cell: &SimulatedCell,
        q: &[f64],
        context: &PoseContext,
    ) -> Result<JointOffsets, Error> {
        let n = model.joint_count();
        if q.len() != n {
            return Err(poe::Error::JointCountMismatch { given: q.len(), expected: n }.into());
        }
        let static_torque_nm = match &cell.dynamics {
            Some(d) => static_torque(model, d, q, cell.tool, &context.payload)?,
            None => Vec::new(),
        };
        let at = PoseInput { model, cell, q, context, static_torque_nm: &static_torque_nm };
        let mut by_kind = Vec::new();
        for (kind, effect) in self.active() {
            if let Some(dq) = effect.joint_offset(&at)? {
                by_kind.push((kind, dq));
            }
        }
        Ok(JointOffsets { static_torque_nm, by_kind, joint_count: n })
    }

    /// The true `tracker_from_tool` at commanded joints `q`, every active effect applied except the
    /// tracker noise: `exp(t ξ̂) · tracker_from_base · exp(δ̂) · T_grown(q + δq)`, with `δ` the links'
    /// bending at the commanded joints (first order, as the joint compliance).
    pub fn true_pose(&self, cell: &SimulatedCell, q: &[f64], context: &PoseContext) -> Result<SE3, Error> {
        self.validate(cell)?;
        let model = self.model_at(cell, context)?;
        let offsets = self.joint_offsets_on(&model, cell, q, context)?;
        let moved: Vec<f64> = q.iter().zip(offsets.total()).map(|(a, b)| a + b).collect();
        let mut base_from_tool = model.forward(&moved, cell.tool)?;
        let at = PoseInput { model: &model, cell, q, context, static_torque_nm: &offsets.static_torque_nm };
        let active = self.active();
        for (_, effect) in &active {
            if let Some(bend) = effect.pose_twist(&at)? {
                base_from_tool = lie::Twist::from_vector(&bend).exp() * base_from_tool;
            }
        }
        let mut tracker_from_tool = cell.tracker_from_base * base_from_tool;
        for (_, effect) in &active {
            if let Some(motion) = effect.tracker_motion(context) {
                tracker_from_tool = motion * tracker_from_tool;
            }
        }
        Ok(tracker_from_tool)
    }

    /// What the tracker reports: [`Effects::true_pose`] with the tracker noise drawn from `rng`.
    pub fn measured_pose<R: Rng + ?Sized>(
        &self,
        cell: &SimulatedCell,
        q: &[f64],
        context: &PoseContext,
        rng: &mut R,
    ) -> Result<SE3, Error> {
        let pose = self.true_pose(cell, q, context)?;
        Ok(match &self.tracker_noise {
            Some(noise) => noise.measure(&pose, rng),
            None => pose,
        })
    }
}
