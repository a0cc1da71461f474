//! Link deflection: the link of a joint bends under the gravity moment of everything
//! beyond it, and the arm beyond turns with the link's far end by `θ_a = f_a L(q) (e_a · M(q))`
//! about the link's midpoint, about the x and y axes `e_a` of the joint's frame
//! (`loadsim::link_deflection_features`; a column's lever `L` grows with its extension). One
//! parameter per bending axis, the link's flexibility `1/EI` about it times the feature's RMS.
//!
//! The moment comes from a mass model: the robot file's masses and centres of mass where it has
//! them, otherwise [`crate::stand_in_dynamics`] (the configuration alone). The diagnosis offers it
//! on prismatic joints only (a lifting column, a linear axis's carriage): on a revolute joint the
//! bending within the plane of the joint axes is, to first order, the compliance of the joints at
//! both ends (a beam under an end moment turns by `θ` about its midpoint; `δq_j = δq_{j+1} = θ/2`
//! does the same to first order), so a candidate there would only split ties with joint
//! compliance. `--effects link_deflection:J` takes any joint.

use super::{LoadFrame, Regressor, rms_scales};
use crate::check::{Cursor, EffectFault, FaultKind};
use crate::term::{EffectTerm, NewEffect};
use crate::{
    Argument, BeyondSpan, CandidateContext, CandidateModel, Direction, EffectContext, EffectSpec, IdentifiedEffect,
    PayloadSpan, stand_in_dynamics,
};
use errors::Error;
use loadsim::{Payload, RobotDynamics};
use measurements::{BoundSet, Measurement};
use poe::JointKind;
use serde::{Deserialize, Serialize};

/// A bending axis is kept where its feature's RMS over the training rows exceeds this, N·m²:
/// below it the axis carries no moment (a link whose joint axis is vertical under vertical gravity
/// has no moment about it), and a column of rounding noise would be identified as a parameter.
/// 1e-9 N·m² is far below any physical moment (1 g at 1 mm over 1 mm is 1e-8).
const AXIS_RMS_FLOOR_NM2: f64 = 1e-9;

/// The diagnosis's place for the candidate among those of no one joint: after thermal growth and
/// drift (0), and, being of no one joint, after every joint's compliance, which wins ties.
const CANDIDATE_ORDER: u8 = 5;

/// The bending of one joint's link, identified with the geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkDeflectionTerm {
    /// 0-based joint whose link bends.
    pub joint: usize,
    /// Gravity and the nominal arm (the moment is computed in the robot's base frame).
    pub load: LoadFrame,
    /// The mass model that gives the moment: the robot file's, or a stand-in.
    pub dynamics: RobotDynamics,
    /// The bending axes kept (0: the joint frame's x axis, 1: its y axis).
    pub axes: Vec<usize>,
    /// Each axis's feature is divided by this (its RMS on the training poses, N·m²).
    pub scale: Vec<f64>,
    /// The far end's rotation about each axis, rad per unit of the scaled feature.
    pub theta: Vec<f64>,
    /// The payloads of the training rows and the rule beyond them (`PayloadSpan`: the
    /// moment held at the nearer end's payload unless the fit chose otherwise). Absent in model
    /// files written before it was recorded: extended as fitted, as they were.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub payload_span: Option<PayloadSpan>,
}

impl LinkDeflectionTerm {
    /// The bending of `joint`'s link (0-based) with the moment of `dynamics`, its axes those that
    /// carry a moment on the rows of `data`, scaled there, its parameters at zero.
    pub fn new(joint: usize, load: LoadFrame, dynamics: RobotDynamics, data: &BoundSet<'_>) -> Result<Self, Error> {
        let mut model =
            Self { joint, load, dynamics, axes: vec![0, 1], scale: vec![1.0, 1.0], theta: vec![], payload_span: None };
        let raw: Vec<Vec<f64>> = data.iter().map(|(row, tool)| model.features(row, tool)).collect::<Result<_, _>>()?;
        let rms = rms_scales(&raw);
        let carries = |a: usize| raw.iter().any(|r| r[a] != 0.0) && rms[a] > AXIS_RMS_FLOOR_NM2;
        model.axes = (0..2).filter(|&a| carries(a)).collect();
        model.scale = model.axes.iter().map(|&a| rms[a]).collect();
        model.theta = vec![0.0; model.axes.len()];
        model.payload_span = PayloadSpan::of(data.rows(), false);
        Ok(model)
    }

    /// `L (e_a · M)` of every bending axis at one row, unscaled, N·m², with the payload held in
    /// its span where the rule beyond it (`rule`) says so.
    fn raw_features(&self, row: &Measurement, tool: usize, rule: Option<BeyondSpan>) -> Result<[f64; 2], Error> {
        let payload_kg = self.payload_span.as_ref().map_or(row.payload_kg, |s| s.payload(rule, row.payload_kg));
        let payload = Payload::at_tool(payload_kg);
        loadsim::link_deflection_features(&self.load.base_model, &self.dynamics, &row.q, tool, &payload, self.joint)
            .map_err(Error::load)
    }
}

impl Regressor for LinkDeflectionTerm {
    fn directions(&self) -> Vec<Direction> {
        self.axes.iter().map(|&axis| Direction::LinkBend { joint: self.joint, axis }).collect()
    }

    fn features(&self, row: &Measurement, tool: usize) -> Result<Vec<f64>, Error> {
        let rule = self.payload_span.as_ref().and_then(|s| s.rule_at(row.payload_kg));
        let raw = self.raw_features(row, tool, rule)?;
        if rule == Some(BeyondSpan::Zero) {
            return Ok(vec![0.0; self.axes.len()]);
        }
        Ok(self.axes.iter().zip(&self.scale).map(|(&a, s)| raw[a.min(1)] / s).collect())
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        const AXIS: [&str; 2] = ["x", "y"];
        self.axes
            .iter()
            .map(|&a| format!("link {} bending about its {} axis", self.joint + 1, AXIS[a.min(1)]))
            .collect()
    }
}

impl EffectTerm for LinkDeflectionTerm {
    fn label(&self) -> String {
        format!("link_deflection:{} (gravity moment of the mass model)", self.joint + 1)
    }

    fn joints(&self) -> Vec<usize> {
        vec![self.joint + 1]
    }

    fn check(&self, cursor: &Cursor<'_>, n: usize, tools: usize) -> Result<(), EffectFault> {
        cursor.joint("joint", 0, "joint".into(), self.joint, n)?;
        if let Some(k) = self.axes.iter().position(|&a| a > 1) {
            return Err(cursor.fault(
                "axes",
                0,
                format!("axes[{k}]"),
                FaultKind::Index { index: self.axes[k], limit: 2 },
            ));
        }
        cursor.count("scale", self.scale.len(), self.axes.len())?;
        cursor.count("theta", self.theta.len(), self.axes.len())?;
        cursor.load(&self.load, n, tools)?;
        self.dynamics.validate(n).map_err(|_| {
            let kind = FaultKind::Count { what: "links", found: self.dynamics.links.len(), expected: n };
            cursor.fault("dynamics", 0, "dynamics".into(), kind)
        })?;
        cursor.payload_span(self.payload_span.as_ref())?;
        cursor.finite("scale", &self.scale, true)
    }

    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize)) {
        add("joint", 1);
        add("base_model", 1);
        // The load frame's and the mass model's.
        add("gravity_m_per_s2", 2);
        add("dynamics", 1);
        add("axes", 1);
        add("scale", 1);
        Cursor::count_payload_span(self.payload_span.as_ref(), add);
    }

    fn payload_span(&self) -> Option<&PayloadSpan> {
        self.payload_span.as_ref()
    }

    fn coverage_weight(&self, row: &Measurement) -> f64 {
        self.payload_span.as_ref().map_or(1.0, |s| s.coverage(row.payload_kg))
    }

    fn set_beyond_payload(&mut self, rule: BeyondSpan) {
        if let Some(span) = &mut self.payload_span {
            span.beyond = rule;
        }
    }
}

impl NewEffect for LinkDeflectionTerm {
    const ARGUMENTS: &'static [Argument] = &[Argument::Joint];

    /// The link of the item's joint, with the robot's mass model or a stand-in.
    fn build(spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        let joint = spec.joint_index()?;
        let dynamics = context.robot.dynamics.clone().unwrap_or_else(|| stand_in_dynamics(context.robot));
        LinkDeflectionTerm::new(joint, context.load_frame(data)?, dynamics, data)
    }

    /// One candidate per prismatic joint (module doc), after every joint's compliance.
    fn global_candidates(context: &CandidateContext<'_>) -> Result<Vec<CandidateModel>, Error> {
        let mut out = Vec::new();
        for (joint, description) in context.robot.joints.iter().enumerate() {
            if description.kind != JointKind::Prismatic {
                continue;
            }
            let bend = LinkDeflectionTerm::new(joint, context.load.clone(), context.dynamics.clone(), context.data)?;
            if !bend.axes.is_empty() {
                out.push(CandidateModel {
                    only_if_nonzero: true,
                    ..CandidateModel::plain(IdentifiedEffect::LinkDeflection(bend), CANDIDATE_ORDER)
                });
            }
        }
        Ok(out)
    }
}
