//! The candidate explanations of a residual, each an effect of [`effects`] (one definition
//! per effect: the fit identifies exactly what the diagnosis scores), written as extra columns of
//! the linearised problem: compliance from the gravity-torque regressors and, where the data has
//! them, from measured torques; backlash with the sign of the stated (or stand-in) static torque,
//! of the measured torque, or of a torque learnt from the data inside each fold (module
//! `learnt_side`); a Fourier series of each moving joint's own angle; thermal growth; drift.
//!
//! Every column is a left twist per unit of one parameter, in the calibrated model's reference
//! frame (the tracker). Gravity is known only in the robot's base frame, so the scalar regressors
//! (torques, their signs) come from the nominal model in the base frame, and the twists from the
//! calibrated model.

use super::design::Design;
use effects::{
    Backlash, ComplianceTerm, ComplianceTorque, EffectContext, GearPeriodic, IdentifiedEffect, JointCompliance,
    LoadFrame, Thermal, TimeDrift, TorqueSign, has_torques, stand_in_dynamics,
};
use errors::Error;
use measurements::MeasurementSet;
use poe::LocalPoe;
use rayon::prelude::*;
use robot::RobotDescription;
use serde::{Deserialize, Serialize};

/// An effect a verdict can name (the SPEC's `verdict.effect`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    /// Joint compliance under gravity and payload.
    JointCompliance,
    /// Backlash following the sign of the static torque.
    Backlash,
    /// A smooth periodic error of a joint's own angle (gear or encoder), of any order.
    GearPeriodic,
    /// Thermal growth of the links with `temp_c`.
    Thermal,
    /// Drift of the robot's placement with `t_s`.
    TimeDrift,
    /// Nothing beats the noise floor.
    None,
    /// Structure remains that no candidate explains.
    Unknown,
}

impl Effect {
    /// The SPEC name.
    pub fn name(self) -> &'static str {
        match self {
            Effect::JointCompliance => "joint_compliance",
            Effect::Backlash => "backlash",
            Effect::GearPeriodic => "gear_periodic",
            Effect::Thermal => "thermal",
            Effect::TimeDrift => "time_drift",
            Effect::None => "none",
            Effect::Unknown => "unknown",
        }
    }
}

/// One candidate: an effect on some joints, as weighted columns of the linearised problem.
#[derive(Debug, Clone)]
pub(crate) struct Candidate {
    pub effect: Effect,
    /// 1-based joints the candidate involves (empty for thermal and drift).
    pub joints: Vec<usize>,
    /// One column per parameter: `rows_per_pose × poses` weighted values.
    pub columns: Vec<Vec<f64>>,
    /// The prior standard deviation of each parameter, if not the default (module `pool`).
    pub prior_sd: Option<f64>,
    /// For a Fourier series: the orders it may take; its columns are `cos q, sin q, cos 2q, …`.
    pub orders: Option<Vec<u32>>,
    /// The effect as the fit models it (its parameters at zero): the columns are its regressor.
    pub model: IdentifiedEffect,
}

/// What the candidates are built with.
#[derive(Debug, Clone)]
pub(crate) struct Settings<'a> {
    /// 0-based joints that move: only they get a Fourier series.
    pub moving: &'a [usize],
    /// The orders a series may take (its columns run to the largest).
    pub orders: &'a [u32],
    /// Prior standard deviation of each scaled Fourier parameter, rad.
    pub series_sd: f64,
}

/// What a learnt backlash side of one joint is learnt from (module `learnt_side`).
#[derive(Debug, Clone)]
pub(crate) struct SideSource {
    /// 0-based joint.
    pub joint: usize,
    /// Index of the joint's gravity-regressor compliance candidate.
    pub compliance: usize,
    /// Its terms (the regressors whose combination is the learnt torque).
    pub terms: Vec<ComplianceTerm>,
    /// The gravity frame, for the learnt torque's definition.
    pub load: LoadFrame,
}

/// One candidate before it is numbered: the effect, its columns, its prior, its series orders.
type Built = (IdentifiedEffect, Vec<Vec<f64>>, Option<f64>, Option<Vec<u32>>);
/// One joint's candidates, and where among them its gravity-regressor compliance is (with its
/// terms), for the learnt backlash side.
type JointCandidates = (Vec<Built>, Option<(usize, Vec<ComplianceTerm>)>);

/// The weighted columns of an effect's regressor at every measurement.
pub(crate) fn columns_of(
    design: &Design,
    effect: &IdentifiedEffect,
    model: &LocalPoe,
    data: &MeasurementSet,
) -> Result<Vec<Vec<f64>>, Error> {
    let k = design.rows_per_pose;
    let tools: Vec<usize> = data.rows.iter().map(|r| r.tool).collect();
    let twists = effect.parameter_twists(model, &data.rows, &tools)?;
    Ok(twists
        .iter()
        .map(|per_row| {
            let mut column = vec![0.0; k * per_row.len()];
            for (i, twist) in per_row.iter().enumerate() {
                design.twist_rows(i, twist, &mut column[i * k..(i + 1) * k]);
            }
            column
        })
        .collect())
}

/// Builds every candidate the data can support: compliance (gravity-torque regressors, and
/// measured torques where the data has them), backlash with a stated or measured side, and a
/// Fourier series per moving joint; thermal growth when the temperature varies by more than
/// 0.2 K; drift when time varies. Also returns, per joint with gravity torque, what its learnt
/// backlash side is learnt from (it is learnt inside each fold, once the pool exists).
pub(crate) fn build_candidates(
    robot: &RobotDescription,
    model: &LocalPoe,
    data: &MeasurementSet,
    design: &Design,
    settings: &Settings<'_>,
) -> Result<(Vec<Candidate>, Vec<SideSource>), Error> {
    let n = robot.joint_count();
    let tools: Vec<usize> = data.rows.iter().map(|r| r.tool).collect();
    // The nominal arm in the base frame, where gravity is known, with the calibrated tools placed
    // on its flange (the payload hangs from them).
    let load = EffectContext {
        robot,
        kinematics: model,
        gear: effects::GearOptions::default(),
        hold_beyond_span: effects::HOLD_BEYOND_SPAN,
    }
    .load_frame(&data.rows, &tools)?;
    let dynamics = robot.dynamics.clone().unwrap_or_else(|| stand_in_dynamics(robot));
    let measured = has_torques(&data.rows);
    let nonzero = |columns: &[Vec<f64>]| columns.iter().flatten().any(|v| v.abs() > 1e-12);
    let columns = |effect: &IdentifiedEffect| columns_of(design, effect, model, data);
    let mut candidates = Vec::new();
    let mut sides = Vec::new();
    let mut push = |effect: IdentifiedEffect, columns: Vec<Vec<f64>>, prior_sd: Option<f64>, orders| {
        candidates.push(Candidate {
            effect: effect_of(&effect),
            joints: effect.joints(),
            columns,
            prior_sd,
            orders,
            model: effect,
        });
        candidates.len() - 1
    };
    let longest = settings.orders.iter().copied().max().unwrap_or(1);
    // Each joint's candidates are independent: built in parallel, then numbered in joint order,
    // so the candidate list (and everything after it) is the same on any number of threads.
    let per_joint: Vec<JointCandidates> = (0..n)
        .into_par_iter()
        .map(|j| -> Result<JointCandidates, Error> {
            let mut built: Vec<Built> = Vec::new();
            let mut side = None;
            // Compliance: δq_j = c_j τ_j, τ_j = Y_j(q) π + payload torque, π unknown: one column per
            // entry of Y's row j (the products c_j π_l), and one for the payload (c_j itself).
            let gravity = ComplianceTorque::GravityRegressor(load.clone());
            let compliance = JointCompliance::new(gravity, &[j], &data.rows, &tools)?;
            let terms = compliance.terms.clone();
            let compliance = IdentifiedEffect::JointCompliance(compliance);
            let compliance_columns = columns(&compliance)?;
            // Backlash: δq_j = b_j sign(τ_j), the sign from the robot's mass model or a stand-in.
            let stated = TorqueSign::Stated { load: load.clone(), dynamics: dynamics.clone() };
            let stated = IdentifiedEffect::Backlash(Backlash::new(j, stated, &data.rows, &tools)?);
            let stated_columns = columns(&stated)?;
            if nonzero(&stated_columns) {
                built.push((stated, stated_columns, None, None));
            }
            if !compliance_columns.is_empty() {
                // A balancer or an unknown mass moves the torque's zero: the side is also learnt.
                side = Some((built.len(), terms));
                built.push((compliance, compliance_columns, None, None));
            }
            if measured {
                // Measured torques (SPEC `tauN_nm`): δq_j = c_j τ_j with τ_j the measured torque as
                // the gravity regressors explain it (the sensor's noise left out, as the fit does),
                // and the band's side from the measured torque's sign.
                let compliance = JointCompliance::modelled(load.clone(), &[j], &data.rows, &tools)?;
                if !compliance.terms.is_empty() {
                    let effect = IdentifiedEffect::JointCompliance(compliance);
                    let effect_columns = columns(&effect)?;
                    built.push((effect, effect_columns, None, None));
                }
                let backlash = IdentifiedEffect::Backlash(Backlash::new(j, TorqueSign::Measured, &data.rows, &tools)?);
                let backlash_columns = columns(&backlash)?;
                if nonzero(&backlash_columns) {
                    built.push((backlash, backlash_columns, None, None));
                }
            }
            // A series of the joint's angle: a revolute joint's only (on a linear axis the period
            // of a screw or rack is a length, which this series has no parameter for).
            if settings.moving.contains(&j) && robot.joints[j].kind == robot::JointType::Revolute {
                let gear = IdentifiedEffect::GearPeriodic(GearPeriodic::new(j, (1..=longest).collect(), &data.rows)?);
                let gear_columns = columns(&gear)?;
                built.push((gear, gear_columns, Some(settings.series_sd), Some(settings.orders.to_vec())));
            }
            Ok((built, side))
        })
        .collect::<Result<_, _>>()?;
    for (j, (built, side)) in per_joint.into_iter().enumerate() {
        let indices: Vec<usize> = built
            .into_iter()
            .map(|(effect, columns, prior_sd, orders)| push(effect, columns, prior_sd, orders))
            .collect();
        if let Some((at, terms)) = side {
            sides.push(SideSource { joint: j, compliance: indices[at], terms, load: load.clone() });
        }
    }
    if let Some(temps) = data.rows.iter().map(|r| r.temp_c).collect::<Option<Vec<f64>>>() {
        let (low, high) = temps.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| (a.min(t), b.max(t)));
        if high - low > 0.2 {
            // One expansion coefficient for the whole arm: every link but the tracker-to-base
            // placement grows by α ΔT.
            let thermal = IdentifiedEffect::Thermal(Thermal::new(&data.rows, effects::HOLD_BEYOND_SPAN)?);
            let thermal_columns = columns(&thermal)?;
            push(thermal, thermal_columns, None, None);
        }
    }
    if let Some(times) = data.rows.iter().map(|r| r.t_s).collect::<Option<Vec<f64>>>() {
        let mean = times.iter().sum::<f64>() / data.rows.len() as f64;
        if times.iter().any(|t| (t - mean).abs() > 1.0) {
            let drift = IdentifiedEffect::TimeDrift(TimeDrift::new(&data.rows, effects::HOLD_BEYOND_SPAN)?);
            let drift_columns = columns(&drift)?;
            push(drift, drift_columns, None, None);
        }
    }
    Ok((candidates, sides))
}

/// The verdict name of an effect.
fn effect_of(effect: &IdentifiedEffect) -> Effect {
    match effect {
        IdentifiedEffect::JointCompliance(_) => Effect::JointCompliance,
        IdentifiedEffect::GearPeriodic(_) => Effect::GearPeriodic,
        IdentifiedEffect::Backlash(_) => Effect::Backlash,
        IdentifiedEffect::Thermal(_) => Effect::Thermal,
        IdentifiedEffect::TimeDrift(_) => Effect::TimeDrift,
    }
}
