//! The candidate explanations of a residual: each unmodelled effect of `loadsim`, per joint (and
//! harmonic) where it acts on one joint, written as extra columns of the linearised problem.
//!
//! Every column is a left twist per unit of one parameter (module `loadsim::regressor`), in the
//! calibrated model's reference frame (the tracker). Gravity is known only in the robot's base
//! frame, so the scalar regressors (torques, their signs) come from the nominal model in the base
//! frame, and the twists from the calibrated model.

use super::design::Design;
use crate::{Error, MeasurementSet, RobotDescription};
use lie::{Vector3, Vector6};
use loadsim::{LinkInertia, Payload, RobotDynamics};
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
}

/// A stand-in mass model where the robot file gives none, used only for the *sign* of the static
/// torque (backlash): each link a slender bar from its joint's axis point to the next one's, 50 kg
/// per metre, so that the torque's sign follows where the arm's weight lies, which depends on the
/// geometry far more than on the masses.
fn stand_in_dynamics(robot: &RobotDescription) -> RobotDynamics {
    let mut points: Vec<Vector3> = robot.joints.iter().map(|j| Vector3::from(j.point)).collect();
    points.push(Vector3::from(robot.flange.position));
    let links = points
        .windows(2)
        .map(|w| LinkInertia { mass_kg: 50.0 * (w[1] - w[0]).norm().max(0.05), com_m: ((w[0] + w[1]) * 0.5).into() })
        .collect();
    RobotDynamics {
        links,
        stiffness_nm_per_rad: vec![1.0; robot.joint_count()],
        counterbalance: None,
        gravity_m_per_s2: loadsim::FLOOR_GRAVITY_M_PER_S2,
    }
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

/// The side of the backlash band each pose is on, learnt from the data: the sign of the joint's
/// torque `τ = Y(q) π` with `π` unknown. It starts from the joint's fitted compliance deflection
/// (proportional to the torque), then alternates: given the signs, fit the band and flip every pose
/// whose residual the other side explains better; given the flipped signs, refit `π` by least
/// squares on them (a linear classifier over the torque regressors), so that the sign stays a
/// function of the torque and does not merely follow the noise.
fn learnt_torque_sign(
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
    let mut signs: Vec<f64> = torque(&design.fit_all(compliance_columns)).into_iter().map(sign).collect();
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
    }
    signs
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

/// Builds every candidate the data can support: compliance, backlash and gear error per joint;
/// thermal growth when the temperature varies by more than 0.2 K; drift when time varies.
pub(crate) fn build_candidates(
    robot: &RobotDescription,
    model: &LocalPoe,
    data: &MeasurementSet,
    design: &Design,
    options: &CandidateOptions,
) -> Result<Vec<Candidate>, Error> {
    let n = robot.joint_count();
    let k = design.rows_per_pose;
    let poses = data.rows.len();
    // The nominal arm in the base frame, carrying the calibrated tools (their offsets from the
    // last joint are what the payload hangs from).
    let mut base_model = robot.nominal_model()?;
    base_model.set_tools(model.tools().to_vec());
    let dynamics = robot.dynamics.clone().unwrap_or_else(|| stand_in_dynamics(robot));
    let gravity = Vector3::from(dynamics.gravity_m_per_s2);

    let mut twists_per_pose: Vec<Vec<lie::Twist>> = Vec::with_capacity(poses);
    let mut gravity_rows: Vec<nalgebra::DMatrix<f64>> = Vec::with_capacity(poses);
    let mut payload_torque: Vec<Vec<f64>> = Vec::with_capacity(poses);
    let mut static_torque: Vec<Vec<f64>> = Vec::with_capacity(poses);
    for row in &data.rows {
        twists_per_pose.push(model.spatial_twists(&row.q)?);
        gravity_rows.push(loadsim::gravity_regressor(&base_model, &row.q, &gravity)?);
        let payload = Payload::at_tool(row.payload_kg);
        payload_torque.push(loadsim::payload_gravity_torque(&base_model, &row.q, row.tool, &payload, &gravity)?);
        static_torque.push(loadsim::static_torque(&base_model, &dynamics, &row.q, row.tool, &payload)?);
    }
    // A column from a joint twist times a scalar per pose.
    let joint_column = |joint: usize, scalar: &dyn Fn(usize) -> f64| -> Vec<f64> {
        let mut column = vec![0.0; k * poses];
        for i in 0..poses {
            let twist = twists_per_pose[i][joint].to_vector() * scalar(i);
            design.twist_rows(i, &twist, &mut column[i * k..(i + 1) * k]);
        }
        column
    };
    let nonzero = |column: &Vec<f64>| column.iter().any(|v| v.abs() > 1e-12);

    let mut candidates = Vec::new();
    for j in 0..n {
        // Compliance: δq_j = c_j τ_j, τ_j = Y_j(q) π + payload torque, π unknown: one column per
        // entry of Y's row j (the products c_j π_l), and one for the payload (c_j itself).
        let mut scalars: Vec<Vec<f64>> =
            (0..4 * n).map(|l| (0..poses).map(|i| gravity_rows[i][(j, l)]).collect()).collect();
        scalars.push((0..poses).map(|i| payload_torque[i][j]).collect());
        scalars.retain(|s| s.iter().any(|v| v.abs() > 1e-12));
        let columns: Vec<Vec<f64>> = scalars.iter().map(|s| joint_column(j, &|i| s[i])).collect();
        // Backlash: δq_j = b_j sign(τ_j). The torque's sign comes from the robot's mass model
        // (or a stand-in), and, since a balancer or an unknown mass can move its zero, also from
        // the compliance fit of this joint: the fitted deflection is proportional to the torque
        // the data says the joint carries.
        let stated = joint_column(j, &|i| sign(static_torque[i][j]));
        if nonzero(&stated) {
            candidates.push(Candidate {
                effect: Effect::Backlash,
                joints: vec![j + 1],
                harmonic: None,
                columns: vec![stated],
            });
        }
        if !columns.is_empty() {
            let signs = learnt_torque_sign(design, &scalars, &columns, &|s: &[f64]| joint_column(j, &|i| s[i]));
            let learnt = joint_column(j, &|i| signs[i]);
            if nonzero(&learnt) {
                candidates.push(Candidate {
                    effect: Effect::Backlash,
                    joints: vec![j + 1],
                    harmonic: None,
                    columns: vec![learnt],
                });
            }
            candidates.push(Candidate {
                effect: Effect::JointCompliance,
                joints: vec![j + 1],
                harmonic: None,
                columns,
            });
        }
        for &h in &options.harmonics {
            let order = f64::from(h);
            let columns = vec![
                joint_column(j, &|i| (order * data.rows[i].q[j]).cos()),
                joint_column(j, &|i| (order * data.rows[i].q[j]).sin()),
            ];
            candidates.push(Candidate {
                effect: Effect::GearPeriodic,
                joints: vec![j + 1],
                harmonic: Some(h),
                columns,
            });
        }
    }
    if let Some(temps) = data.rows.iter().map(|r| r.temp_c).collect::<Option<Vec<f64>>>() {
        let mean = temps.iter().sum::<f64>() / poses as f64;
        let (low, high) = temps.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| (a.min(t), b.max(t)));
        if high - low > 0.2 {
            // One expansion coefficient for the whole arm: every link but the tracker-to-base
            // placement grows by α ΔT.
            let mut column = vec![0.0; k * poses];
            for (i, row) in data.rows.iter().enumerate() {
                let columns = loadsim::thermal_regressor(model, &row.q, row.tool, temps[i] - mean)?;
                let twist: Vector6 = columns.iter().skip(1).map(|c| c.twist).sum();
                design.twist_rows(i, &twist, &mut column[i * k..(i + 1) * k]);
            }
            candidates.push(Candidate {
                effect: Effect::Thermal,
                joints: vec![],
                harmonic: None,
                columns: vec![column],
            });
        }
    }
    if let Some(times) = data.rows.iter().map(|r| r.t_s).collect::<Option<Vec<f64>>>() {
        let mean = times.iter().sum::<f64>() / poses as f64;
        if times.iter().any(|t| (t - mean).abs() > 1.0) {
            let columns = (0..6)
                .map(|component| {
                    let mut column = vec![0.0; k * poses];
                    for (i, t) in times.iter().enumerate() {
                        let twist = loadsim::drift_regressor(t - mean)[component].twist;
                        design.twist_rows(i, &twist, &mut column[i * k..(i + 1) * k]);
                    }
                    column
                })
                .collect();
            candidates.push(Candidate { effect: Effect::TimeDrift, joints: vec![], harmonic: None, columns });
        }
    }
    Ok(candidates)
}
