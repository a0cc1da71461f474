//! All effects together: which are on, and the forward model from commanded joint values to the
//! measured tool pose. [`Effects::only`] and [`Effects::is_on`] are generated with
//! [`crate::EffectKind`] from the one list of kinds (module `kinds`).

use crate::{
    Backlash, BaseDrift, Error, JointBacklash, JointCompliance, JointCoupling, LinkDeflection, PeriodicError,
    PoseContext, ScrewError, SimulatedCell, ThermalGrowth, TrackerNoise, compliance::compliance_deflection,
    gravity::static_torque, periodic::Harmonic,
};
use lie::SE3;
use rand::Rng;
use serde::{Deserialize, Serialize};

/// Which effects act and with which parameters; `None` switches an effect off. The default has
/// none: the measured pose is then the geometric model's.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Effects {
    /// Joint compliance (stiffness from the robot's dynamics).
    pub compliance: Option<JointCompliance>,
    /// Backlash (torque sign from the robot's dynamics).
    pub backlash: Option<Backlash>,
    /// Periodic transmission error.
    pub periodic: Option<PeriodicError>,
    /// Thermal growth of the links against `temp_c`.
    pub thermal: Option<ThermalGrowth>,
    /// Base drift against `t_s`.
    pub drift: Option<BaseDrift>,
    /// Tracker noise.
    pub tracker_noise: Option<TrackerNoise>,
    /// A joint error driven by other joints' angles (module [`JointCoupling`]).
    pub coupling: Option<JointCoupling>,
    /// Links bending under the gravity moment of everything beyond them (masses from the robot's
    /// dynamics; module [`LinkDeflection`]).
    pub deflection: Option<LinkDeflection>,
    /// Periodic error of linear axes per screw or rack pitch (module [`ScrewError`]).
    pub screw: Option<ScrewError>,
}

/// The joint-space part of the forward model at one pose, each effect apart.
#[derive(Debug, Clone, PartialEq)]
pub struct JointOffsets {
    /// Static torque (gravity, payload, balancer) at the commanded joints, N·m; empty when the
    /// robot has no dynamics.
    pub static_torque_nm: Vec<f64>,
    /// Compliance deflection, rad.
    pub compliance_rad: Vec<f64>,
    /// Backlash offset, rad.
    pub backlash_rad: Vec<f64>,
    /// Periodic transmission error, rad.
    pub periodic_rad: Vec<f64>,
    /// Coupled joint error, rad.
    pub coupling_rad: Vec<f64>,
    /// Screw (or rack) periodic error of the linear axes, m (0 on revolute joints).
    pub screw_m: Vec<f64>,
}

impl JointOffsets {
    /// The sum of the joint-space effects, rad.
    pub fn total(&self) -> Vec<f64> {
        (0..self.compliance_rad.len())
            .map(|j| {
                self.compliance_rad[j]
                    + self.backlash_rad[j]
                    + self.periodic_rad[j]
                    + self.coupling_rad[j]
                    + self.screw_m[j]
            })
            .collect()
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
            compliance: Some(JointCompliance::default()),
            backlash: Some(Backlash {
                joints: (0..joint_count)
                    .map(|joint_index| JointBacklash { joint_index, half_band_rad: half_band })
                    .collect(),
            }),
            periodic: Some(PeriodicError { harmonics }),
            thermal: Some(ThermalGrowth::default()),
            drift: Some(BaseDrift::default()),
            tracker_noise: Some(TrackerNoise::default()),
            coupling: None,
            deflection: None,
            screw: None,
        }
    }

    /// Checks every active effect against the cell: indices inside the robot, finite values,
    /// dynamics present where an effect needs them.
    pub fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        let n = cell.robot.joint_count();
        if cell.tool >= cell.robot.tool_count() {
            return Err(poe::Error::UnknownTool { tool: cell.tool, tool_count: cell.robot.tool_count() }.into());
        }
        if self.compliance.is_some() {
            let dynamics = cell.dynamics_for("joint compliance")?;
            dynamics.validate(n)?;
            dynamics.stiffness("joint compliance")?;
        }
        if let Some(backlash) = &self.backlash {
            backlash.validate(n)?;
            cell.dynamics_for("backlash")?.validate(n)?;
        }
        if let Some(periodic) = &self.periodic {
            periodic.validate(n)?;
        }
        if let Some(thermal) = &self.thermal {
            thermal.validate(n)?;
        }
        if let Some(drift) = &self.drift {
            drift.validate()?;
        }
        if let Some(noise) = &self.tracker_noise {
            noise.validate()?;
        }
        if let Some(coupling) = &self.coupling {
            coupling.validate(n)?;
        }
        if let Some(screw) = &self.screw {
            let prismatic: Vec<bool> =
                cell.robot.joints().iter().map(|j| j.kind == poe::JointKind::Prismatic).collect();
            screw.validate(&prismatic)?;
        }
        if let Some(deflection) = &self.deflection {
            deflection.validate(n)?;
            cell.dynamics_for("link deflection")?.validate(n)?;
        }
        Ok(())
    }

    /// The base-frame model at this pose's temperature (grown if thermal growth is on).
    fn model_at(&self, cell: &SimulatedCell, context: &PoseContext) -> Result<poe::LocalPoe, Error> {
        match &self.thermal {
            Some(thermal) => thermal.grown_model(&cell.robot, context.temp_c),
            None => Ok(cell.robot.clone()),
        }
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
        let compliance_rad = match (&self.compliance, &cell.dynamics) {
            (Some(settings), Some(d)) => compliance_deflection(model, d, q, cell.tool, &context.payload, settings)?,
            _ => vec![0.0; n],
        };
        let backlash_rad = match &self.backlash {
            Some(backlash) => backlash.deflection(&static_torque_nm),
            None => vec![0.0; n],
        };
        let periodic_rad = match &self.periodic {
            Some(periodic) => periodic.deflection(q),
            None => vec![0.0; n],
        };
        let coupling_rad = match &self.coupling {
            Some(coupling) => coupling.deflection(q),
            None => vec![0.0; n],
        };
        let screw_m = match &self.screw {
            Some(screw) => screw.deflection(q),
            None => vec![0.0; n],
        };
        Ok(JointOffsets { static_torque_nm, compliance_rad, backlash_rad, periodic_rad, coupling_rad, screw_m })
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
        if let (Some(deflection), Some(dynamics)) = (&self.deflection, &cell.dynamics) {
            let bend = deflection.twist(&model, dynamics, q, cell.tool, &context.payload)?;
            base_from_tool = lie::Twist::from_vector(&bend).exp() * base_from_tool;
        }
        let tracker_from_tool = cell.tracker_from_base * base_from_tool;
        Ok(match &self.drift {
            Some(drift) => drift.motion_at(context.t_s) * tracker_from_tool,
            None => tracker_from_tool,
        })
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
