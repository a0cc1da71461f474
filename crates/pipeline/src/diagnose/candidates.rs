//! The candidate explanations of a residual: each unmodelled effect of `loadsim`, per joint (and
//! harmonic) where it acts on one joint, written as extra columns of the linearised problem.
//!
//! Every column is a left twist per unit of one parameter (module `loadsim::regressor`), in the
//! calibrated model's reference frame (the tracker). Gravity is known only in the robot's base
//! frame, so the scalar regressors (torques, their signs) come from the nominal model in the base
//! frame, and the twists from the calibrated model.

use super::design::Design;
use crate::effects::{
    Backlash, ComplianceTorque, EffectContext, GearPeriodic, IdentifiedEffect, JointCompliance, Thermal, TimeDrift,
    TorqueSign, has_torques, stand_in_dynamics,
};
use crate::{Error, MeasurementSet, RobotDescription};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// An effect a verdict can name (the SPEC's `verdict.effect`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    /// Joint compliance under gravity and payload.
    JointCompliance,
    /// Backlash following the sign of the static torque.
    Backlash,
    /// Periodic transmission error of a joint's gears.
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
    /// Harmonic order, for gear periodic error.
    pub harmonic: Option<u32>,
    /// One column per parameter: `rows_per_pose × poses` weighted values.
    pub columns: Vec<Vec<f64>>,
    /// The effect as the fit models it (its parameters at zero): the columns are its regressor.
    #[allow(dead_code)]
    pub model: IdentifiedEffect,
}

/// The weighted columns of an effect's regressor at every measurement.
fn columns_of(
    design: &Design,
    effect: &IdentifiedEffect,
    model: &LocalPoe,
    data: &MeasurementSet,
    tools: &[usize],
) -> Result<Vec<Vec<f64>>, Error> {
    let k = design.rows_per_pose;
    let twists = effect.parameter_twists(model, &data.rows, tools)?;
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

/// The side of the backlash band each pose is on, learnt from the data: the sign of the joint's
/// torque `τ = Y(q) π` with `π` unknown. It starts from the joint's fitted compliance deflection
/// (proportional to the torque), then alternates: given the signs, fit the band and flip every pose
/// whose residual the other side explains better; given the flipped signs, refit `π` by least
/// squares on them (a linear classifier over the torque regressors), so that the sign stays a
/// function of the torque and does not merely follow the noise. Returns the torque's coefficients
/// over `scalars` (whose signs those are).
fn learnt_torque(
    design: &Design,
    scalars: &[Vec<f64>],
    compliance_columns: &[Vec<f64>],
    column_of: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<f64> {
    let poses = design.poses();
    let k = design.rows_per_pose;
    let torque = |theta: &[f64]| -> Vec<f64> {
        (0..poses).map(|i| scalars.iter().zip(theta).map(|(s, t)| s[i] * t).sum()).collect()
    };
    let mut coefficients = design.fit_all(compliance_columns);
    let mut signs: Vec<f64> = torque(&coefficients).into_iter().map(sign).collect();
    for _ in 0..5 {
        let column = column_of(&signs);
        let (band, residual) = design.fit_all_residual(std::slice::from_ref(&column));
        let b = band[0];
        let flipped: Vec<f64> = (0..poses)
            .map(|i| {
                let rows = i * k..(i + 1) * k;
                let now: f64 = residual[rows.clone()].iter().map(|r| r * r).sum();
                // Flipping the side moves the prediction by −2 b s_i c_i.
                let other: f64 = rows.map(|row| (residual[row] + 2.0 * b * column[row]).powi(2)).sum();
                if other < now { -signs[i] } else { signs[i] }
            })
            .collect();
        let y = nalgebra::DMatrix::from_fn(poses, scalars.len(), |i, l| scalars[l][i]);
        let norms: Vec<f64> = (0..scalars.len()).map(|l| y.column(l).norm().max(f64::MIN_POSITIVE)).collect();
        let scaled = nalgebra::DMatrix::from_fn(poses, scalars.len(), |i, l| y[(i, l)] / norms[l]);
        let Ok(pi) = scaled.svd(true, true).solve(&nalgebra::DVector::from_vec(flipped), 1e-10) else {
            break;
        };
        let pi: Vec<f64> = pi.iter().zip(&norms).map(|(p, n)| p / n).collect();
        let next: Vec<f64> = torque(&pi).into_iter().map(sign).collect();
        if next == signs {
            break;
        }
        signs = next;
        coefficients = pi;
    }
    coefficients
}

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Which candidates to build.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CandidateOptions {
    /// Harmonic orders of the gear periodic error tried on every joint.
    pub harmonics: Vec<u32>,
}

impl Default for CandidateOptions {
    fn default() -> Self {
        Self { harmonics: vec![1, 2, 3] }
    }
}

/// Builds every candidate the data can support: compliance (gravity-torque regressors, and
/// measured torques where the data has them), backlash and gear error per joint; thermal growth
/// when the temperature varies by more than 0.2 K; drift when time varies. Each is an
/// [`IdentifiedEffect`] of `crate::effects`, its columns that effect's regressor.
pub(crate) fn build_candidates(
    robot: &RobotDescription,
    model: &LocalPoe,
    data: &MeasurementSet,
    design: &Design,
    options: &CandidateOptions,
) -> Result<Vec<Candidate>, Error> {
    let n = robot.joint_count();
    let tools: Vec<usize> = data.rows.iter().map(|r| r.tool).collect();
    // The nominal arm in the base frame, where gravity is known, with the calibrated tools placed
    // on its flange (the payload hangs from them).
    let load = EffectContext { robot, kinematics: model }.load_frame(&data.rows, &tools)?;
    let dynamics = robot.dynamics.clone().unwrap_or_else(|| stand_in_dynamics(robot));
    let measured = has_torques(&data.rows);
    let nonzero = |columns: &[Vec<f64>]| columns.iter().flatten().any(|v| v.abs() > 1e-12);
    let columns = |effect: &IdentifiedEffect| columns_of(design, effect, model, data, &tools);
    let mut candidates = Vec::new();
    let mut push = |effect: IdentifiedEffect, harmonic: Option<u32>, columns: Vec<Vec<f64>>| {
        candidates.push(Candidate {
            effect: effect_of(&effect),
            joints: effect.joints(),
            harmonic,
            columns,
            model: effect,
        });
    };
    for j in 0..n {
        // Compliance: δq_j = c_j τ_j, τ_j = Y_j(q) π + payload torque, π unknown: one column per
        // entry of Y's row j (the products c_j π_l), and one for the payload (c_j itself).
        let gravity = ComplianceTorque::GravityRegressor(load.clone());
        let compliance = JointCompliance::new(gravity, &[j], &data.rows, &tools)?;
        let terms = compliance.terms.clone();
        let compliance = IdentifiedEffect::JointCompliance(compliance);
        let compliance_columns = columns(&compliance)?;
        // Backlash: δq_j = b_j sign(τ_j). The torque's sign comes from the robot's mass model
        // (or a stand-in), and, since a balancer or an unknown mass can move its zero, also from
        // the compliance fit of this joint: the fitted deflection is proportional to the torque
        // the data says the joint carries.
        let stated = TorqueSign::Stated { load: load.clone(), dynamics: dynamics.clone() };
        let stated = IdentifiedEffect::Backlash(Backlash::new(j, stated, &data.rows, &tools)?);
        let stated_columns = columns(&stated)?;
        if nonzero(&stated_columns) {
            push(stated, None, stated_columns);
        }
        if !compliance_columns.is_empty() {
            // The compliance terms' scaled regressors, pose by pose.
            let per_row: Vec<Vec<f64>> = data
                .rows
                .iter()
                .zip(&tools)
                .map(|(row, &tool)| compliance.features(row, tool))
                .collect::<Result<_, _>>()?;
            let scalars: Vec<Vec<f64>> = (0..terms.len()).map(|l| per_row.iter().map(|r| r[l]).collect()).collect();
            // The joint's bare twist: order 0's cosine feature is 1 on every row.
            let bare = IdentifiedEffect::GearPeriodic(GearPeriodic::new(j, vec![0], &data.rows)?);
            let joint_twists = bare.parameter_twists(model, &data.rows, &tools)?;
            let column_of = |s: &[f64]| -> Vec<f64> {
                let k = design.rows_per_pose;
                let mut column = vec![0.0; k * s.len()];
                for (i, value) in s.iter().enumerate() {
                    design.twist_rows(i, &(joint_twists[0][i] * *value), &mut column[i * k..(i + 1) * k]);
                }
                column
            };
            let scaled = learnt_torque(design, &scalars, &compliance_columns, &column_of);
            let learnt = TorqueSign::Learnt {
                load: load.clone(),
                columns: terms.iter().map(|t| t.column).collect(),
                coefficients: scaled.iter().zip(&terms).map(|(c, t)| c / t.scale).collect(),
            };
            let learnt = IdentifiedEffect::Backlash(Backlash::new(j, learnt, &data.rows, &tools)?);
            let learnt_columns = columns(&learnt)?;
            if nonzero(&learnt_columns) {
                push(learnt, None, learnt_columns);
            }
            push(compliance, None, compliance_columns);
        }
        if measured {
            // Measured torques (SPEC `tauN_nm`): δq_j = c_j τ_j with τ_j the measured torque as
            // the gravity regressors explain it (the sensor's noise left out, as the fit does),
            // and the band's side from the measured torque's sign.
            let compliance = JointCompliance::modelled(load.clone(), &[j], &data.rows, &tools)?;
            if !compliance.terms.is_empty() {
                let effect = IdentifiedEffect::JointCompliance(compliance);
                let effect_columns = columns(&effect)?;
                push(effect, None, effect_columns);
            }
            let backlash = IdentifiedEffect::Backlash(Backlash::new(j, TorqueSign::Measured, &data.rows, &tools)?);
            let backlash_columns = columns(&backlash)?;
            if nonzero(&backlash_columns) {
                push(backlash, None, backlash_columns);
            }
        }
        for &h in &options.harmonics {
            let gear = IdentifiedEffect::GearPeriodic(GearPeriodic::new(j, vec![h], &data.rows)?);
            let gear_columns = columns(&gear)?;
            push(gear, Some(h), gear_columns);
        }
    }
    if let Some(temps) = data.rows.iter().map(|r| r.temp_c).collect::<Option<Vec<f64>>>() {
        let (low, high) = temps.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| (a.min(t), b.max(t)));
        if high - low > 0.2 {
            // One expansion coefficient for the whole arm: every link but the tracker-to-base
            // placement grows by α ΔT.
            let thermal = IdentifiedEffect::Thermal(Thermal::new(&data.rows)?);
            let thermal_columns = columns(&thermal)?;
            push(thermal, None, thermal_columns);
        }
    }
    if let Some(times) = data.rows.iter().map(|r| r.t_s).collect::<Option<Vec<f64>>>() {
        let mean = times.iter().sum::<f64>() / data.rows.len() as f64;
        if times.iter().any(|t| (t - mean).abs() > 1.0) {
            let drift = IdentifiedEffect::TimeDrift(TimeDrift::new(&data.rows)?);
            let drift_columns = columns(&drift)?;
            push(drift, None, drift_columns);
        }
    }
    Ok(candidates)
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
