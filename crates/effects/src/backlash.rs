//! Backlash: a joint sits at one side of its dead band or the other, following the sign of the
//! torque it carries, `δq_j = b_j sign(τ_j)` (`loadsim::backlash_joint_regressor`).

use super::{LoadFrame, Regressor, rms_scales};
use crate::Direction;
use crate::check::{Cursor, EffectFault, FaultKind};
use crate::term::{EffectTerm, NewEffect};
use crate::{
    Argument, CandidateContext, CandidateModel, EffectContext, EffectSpec, IdentifiedEffect, has_torques,
    stand_in_dynamics,
};
use errors::Error;
use crate::ErrorKind;
use loadsim::{Payload, RobotDynamics};
use measurements::{BoundSet, Measurement};
use serde::{Deserialize, Serialize};

/// Where the sign of the joint's torque comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TorqueSign {
    /// The measured torque (`tauN_nm`).
    Measured,
    /// The static torque of a mass model (the robot file's, or a stand-in):
    /// `loadsim::static_torque`.
    Stated {
        /// Gravity and the nominal arm.
        load: LoadFrame,
        /// The masses (and balancer) that give the torque.
        dynamics: RobotDynamics,
    },
    /// A torque learnt from the data as a combination of the gravity-torque regressors of the
    /// joint's row (`LoadFrame::regressors`): `Σ_l coefficients_l · regressor_{columns_l}`.
    Learnt {
        /// Gravity and the nominal arm.
        load: LoadFrame,
        /// Columns of the joint's regressor row (4 per link, `4n` the payload's).
        columns: Vec<usize>,
        /// Their coefficients.
        coefficients: Vec<f64>,
    },
}

impl TorqueSign {
    /// The torque `Σ_l coefficients_l · regressor_row[columns_l]` of [`TorqueSign::Learnt`],
    /// given the joint's row of the gravity-torque regressors at one measurement
    /// (`LoadFrame::regressors`); a column past the row's end counts as zero.
    pub fn learnt_torque(regressor_row: &[f64], columns: &[usize], coefficients: &[f64]) -> f64 {
        columns.iter().zip(coefficients).map(|(&c, k)| regressor_row.get(c).copied().unwrap_or(0.0) * k).sum()
    }

    /// Joint `joint`'s (0-based) row of the gravity-torque regressors of `load` at every row of
    /// `data`, in its order: what [`TorqueSign::learnt_torque`] takes.
    pub fn learnt_regressor_rows(load: &LoadFrame, joint: usize, data: &BoundSet<'_>) -> Result<Vec<Vec<f64>>, Error> {
        data.iter()
            .map(|(row, tool)| {
                let missing = || Error::new(ErrorKind::EffectJoint { joint: joint + 1, joint_count: row.q.len() });
                load.regressors(row, tool)?.into_iter().nth(joint).ok_or_else(missing)
            })
            .collect()
    }
}

/// Backlash of one joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BacklashTerm {
    /// 0-based joint.
    pub joint: usize,
    /// The torque whose sign selects the side.
    pub sign: TorqueSign,
    /// The sign is divided by this (its RMS on the training poses, 1 where it vanishes).
    pub scale: Vec<f64>,
    /// The half band, rad per unit of the scaled sign.
    pub theta: Vec<f64>,
}

fn sign(x: f64) -> f64 {
    loadsim::backlash_joint_regressor(&[x])[0]
}

impl BacklashTerm {
    /// Backlash of `joint` (1-based) whose side is set by `sign`, scaled on the training rows.
    pub fn new(joint: usize, sign: TorqueSign, data: &BoundSet<'_>) -> Result<Self, Error> {
        let mut model = Self { joint, sign, scale: vec![1.0], theta: vec![0.0] };
        let raw: Vec<Vec<f64>> = data.iter().map(|(row, tool)| model.features(row, tool)).collect::<Result<_, _>>()?;
        model.scale = rms_scales(&raw);
        Ok(model)
    }

    /// [`BacklashTerm::new`] where `torques` holds what [`BacklashTerm::torque`] gives at each
    /// training row: a caller that tries many learnt torques on the same rows computes the
    /// regressors once ([`TorqueSign::learnt_torque`]) instead of once a torque.
    pub fn with_torques(joint: usize, sign: TorqueSign, torques: &[f64]) -> Self {
        let mut model = Self { joint, sign, scale: vec![1.0], theta: vec![0.0] };
        let raw: Vec<Vec<f64>> = torques.iter().map(|&t| vec![model.feature_of(t)]).collect();
        model.scale = rms_scales(&raw);
        model
    }

    /// The feature at a row where the joint's torque is `torque`.
    pub fn feature_of(&self, torque: f64) -> f64 {
        sign(torque) / self.scale[0]
    }

    /// The torque of the joint at one row, whose sign is the feature.
    pub fn torque(&self, row: &Measurement, tool: usize) -> Result<f64, Error> {
        let j = self.joint;
        let missing = || Error::new(ErrorKind::EffectJoint { joint: j + 1, joint_count: row.q.len() });
        match &self.sign {
            TorqueSign::Measured => match &row.torques_nm {
                Some(tau) => tau.get(j).copied().ok_or_else(missing),
                None => Err(Error::new(ErrorKind::EffectNeedsColumn {
                    line: row.line,
                    effect: "backlash",
                    column: "tau1_nm",
                })),
            },
            TorqueSign::Stated { load, dynamics } => {
                let payload = Payload::at_tool(row.payload_kg);
                let torque =
                    loadsim::static_torque(&load.base_model, dynamics, &row.q, tool, &payload).map_err(Error::load)?;
                torque.get(j).copied().ok_or_else(missing)
            }
            TorqueSign::Learnt { load, columns, coefficients } => {
                let regressors = load.regressors(row, tool)?;
                let row = regressors.get(j).ok_or_else(missing)?;
                Ok(TorqueSign::learnt_torque(row, columns, coefficients))
            }
        }
    }
}

impl Regressor for BacklashTerm {
    fn directions(&self) -> Vec<Direction> {
        vec![Direction::Joint(self.joint)]
    }

    fn features(&self, row: &Measurement, tool: usize) -> Result<Vec<f64>, Error> {
        Ok(vec![self.feature_of(self.torque(row, tool)?)])
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        vec![format!("joint {} half band", self.joint + 1)]
    }
}

impl EffectTerm for BacklashTerm {
    fn label(&self) -> String {
        let source = match self.sign {
            TorqueSign::Measured => "measured torque",
            TorqueSign::Stated { .. } => "static torque of the mass model",
            TorqueSign::Learnt { .. } => "torque learnt from the data",
        };
        format!("backlash:{} (sign of the {source})", self.joint + 1)
    }

    fn joints(&self) -> Vec<usize> {
        vec![self.joint + 1]
    }

    fn check(&self, cursor: &Cursor<'_>, n: usize, tools: usize) -> Result<(), EffectFault> {
        cursor.joint("joint", 0, "joint".into(), self.joint, n)?;
        cursor.count("scale", self.scale.len(), 1)?;
        cursor.count("theta", self.theta.len(), 1)?;
        match &self.sign {
            TorqueSign::Measured => {}
            TorqueSign::Stated { load, dynamics } => {
                cursor.load(load, n, tools)?;
                dynamics.validate(n).map_err(|_| {
                    let kind = FaultKind::Count { what: "links", found: dynamics.links.len(), expected: n };
                    cursor.fault("dynamics", 0, "sign.dynamics".into(), kind)
                })?;
            }
            TorqueSign::Learnt { load, columns, coefficients } => {
                cursor.load(load, n, tools)?;
                if let Some(k) = columns.iter().position(|&c| c > 4 * n) {
                    let kind = FaultKind::Index { index: columns[k], limit: 4 * n + 1 };
                    return Err(cursor.fault("columns", 0, format!("columns[{k}]"), kind));
                }
                cursor.count("coefficients", coefficients.len(), columns.len())?;
                cursor.finite("coefficients", coefficients, false)?;
            }
        }
        cursor.finite("scale", &self.scale, true)
    }

    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize)) {
        add("joint", 1);
        add("scale", 1);
        match &self.sign {
            TorqueSign::Measured => {}
            TorqueSign::Stated { .. } => {
                add("base_model", 1);
                add("gravity_m_per_s2", 1);
            }
            TorqueSign::Learnt { .. } => {
                add("base_model", 1);
                add("gravity_m_per_s2", 1);
                add("columns", 1);
                add("coefficients", 1);
            }
        }
    }
}

impl NewEffect for BacklashTerm {
    const ARGUMENTS: &'static [Argument] = &[Argument::Joint];

    /// The sign of the measured torque where every row has one, of the robot's static torque
    /// otherwise (its mass model, or a stand-in).
    fn build(spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        let joint = spec.joint_index()?;
        let sign = if has_torques(data.rows()) {
            TorqueSign::Measured
        } else {
            let dynamics = context.robot.dynamics.clone().unwrap_or_else(|| stand_in_dynamics(context.robot));
            TorqueSign::Stated { load: context.load_frame(data)?, dynamics }
        };
        BacklashTerm::new(joint, sign, data)
    }

    /// `δq_j = b_j sign(τ_j)`: the sign of the stated (or stand-in) static torque, first among the
    /// joint's candidates; with measured torques also their sign, fourth. A sign that never
    /// changes over the rows (the weight on a vertical column, whatever the masses) makes `b_j` a
    /// constant joint offset, which the geometry already holds: the diagnosis drops
    /// such a candidate, as every candidate whose features never change
    /// ([`IdentifiedEffect::features_constant`]). A learnt side is the diagnosis's own (module
    /// `learnt_side`).
    fn joint_candidates(context: &CandidateContext<'_>, joint: usize) -> Result<Vec<CandidateModel>, Error> {
        let stated = TorqueSign::Stated { load: context.load.clone(), dynamics: context.dynamics.clone() };
        let mut out = vec![CandidateModel {
            only_if_nonzero: true,
            ..CandidateModel::plain(IdentifiedEffect::Backlash(BacklashTerm::new(joint, stated, context.data)?), 0)
        }];
        if context.measured {
            let measured = BacklashTerm::new(joint, TorqueSign::Measured, context.data)?;
            out.push(CandidateModel {
                only_if_nonzero: true,
                ..CandidateModel::plain(IdentifiedEffect::Backlash(measured), 3)
            });
        }
        Ok(out)
    }
}
