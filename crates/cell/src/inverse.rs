//! Inverse kinematics of a calibrated model (the paper's future work: compensation of the inverse
//! kinematics): joint values at which the *whole* model — geometry, effects and GP, with the
//! row's payload — reaches a pose.
//!
//! Newton's method on the model's own prediction ([`CalibratedModel::predict`]), with the
//! geometric tool-point Jacobian of the kinematics as the direction: `J Δq = e`, `e` the point
//! error and `log(R* Rᵀ)`, solved by an SVD pseudo-inverse and capped per step. The effects and the
//! GP are smooth and small against the geometry, so the iteration contracts fast (two to four steps
//! to 1e-10 m). Rows are solved together: one prediction per iteration for all rows still open,
//! then each row's step in parallel; each row's result is independent of the others.

use errors::Error;
use lie::{SE3, Vector3};
use measurements::{BoundSet, Measurement};
use model::CalibratedModel;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Tuning of the inverse kinematics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct InverseOptions {
    /// Most Newton steps per row.
    pub max_iterations: usize,
    /// A row stops once its point is this close to the target, m (and its rotation within
    /// `rotation_tolerance_rad`): 0.1 nm, the last digits double precision gives on a 3 m arm.
    pub position_tolerance_m: f64,
    /// See `position_tolerance_m`, rad.
    pub rotation_tolerance_rad: f64,
    /// A row that stopped further than this is refused (no convergence), m: 1 µm, a tenth of
    /// what the best trackers resolve.
    pub accept_position_m: f64,
    /// See `accept_position_m`, rad.
    pub accept_rotation_rad: f64,
    /// Largest change of any joint in one step, rad (m for prismatic joints): keeps a step from a
    /// poor seed on the seed's branch.
    pub max_step: f64,
    /// Smallest singular value of the tool-point Jacobian (m/rad for the point rows, 1 for the
    /// rotation rows) accepted at the solution. Below it the row is refused as singular: a
    /// millimetre there needs joint changes of order 0.1 rad between the joints that align.
    /// 0.01 is a fifth of the floor the simulator keeps identification poses above (0.05).
    pub min_singular_value: f64,
    /// Singular values below this fraction of the largest are left out of the pseudo-inverse.
    pub rcond: f64,
}

impl Default for InverseOptions {
    fn default() -> Self {
        Self {
            max_iterations: 30,
            position_tolerance_m: 1e-10,
            rotation_tolerance_rad: 1e-10,
            accept_position_m: 1e-6,
            accept_rotation_rad: 1e-6,
            max_step: 0.1,
            min_singular_value: 0.01,
            rcond: 1e-9,
        }
    }
}

/// What a row asks for: a pose in the tracker frame from a seed configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseTarget {
    /// The configuration to start from (the nominal joint values, or the given seed).
    pub seed: Vec<f64>,
    /// `tracker_from_tool` to reach.
    pub pose: SE3,
    /// Whether the orientation counts too (otherwise the point only).
    pub orientation: bool,
    /// Payload at the tool, kg.
    pub payload_kg: f64,
    /// The model's tool index.
    pub tool: usize,
    /// The measured signals the model takes as inputs, as the target's row gives them (empty for
    /// a model that takes none).
    pub inputs: measurements::Inputs,
}

/// Why a row was not compensated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TargetStatus {
    /// Reached.
    Ok,
    /// Reached, but outside a joint's limits.
    OutsideLimits {
        /// 1-based joint.
        joint: usize,
        /// Its value, rad (m).
        value: f64,
        /// Its limits.
        limits: (f64, f64),
        /// Whether the joint turns (degrees in the message) or slides (metres).
        revolute: bool,
    },
    /// Not reached within the iterations.
    NoConvergence {
        /// Steps taken.
        iterations: usize,
        /// Point error left, m.
        position_m: f64,
        /// Rotation error left, rad (zero when the orientation does not count).
        rotation_rad: f64,
    },
    /// At (or too near) a singular configuration.
    Singular {
        /// The Jacobian's smallest singular value there.
        smallest: f64,
        /// The floor ([`InverseOptions::min_singular_value`]).
        floor: f64,
    },
}

impl TargetStatus {
    /// Whether the row was compensated.
    pub fn is_ok(&self) -> bool {
        matches!(self, TargetStatus::Ok)
    }
}

impl fmt::Display for TargetStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TargetStatus::Ok => write!(f, "ok"),
            TargetStatus::OutsideLimits { joint, value, limits: (lo, hi), revolute: true } => write!(
                f,
                "outside limits: joint {joint} at {:.3} deg, limits {:.3} to {:.3} deg",
                value.to_degrees(),
                lo.to_degrees(),
                hi.to_degrees()
            ),
            TargetStatus::OutsideLimits { joint, value, limits: (lo, hi), revolute: false } => {
                write!(f, "outside limits: joint {joint} at {value:.6} m, limits {lo:.6} to {hi:.6} m")
            }
            TargetStatus::NoConvergence { iterations, position_m, rotation_rad } => write!(
                f,
                "no convergence: {:.6} mm and {:.6} mrad left after {iterations} iterations",
                position_m * 1e3,
                rotation_rad * 1e3
            ),
            TargetStatus::Singular { smallest, floor } => {
                write!(
                    f,
                    "singular: the tool Jacobian's smallest singular value is {smallest:.3e} (at least {floor} needed)"
                )
            }
        }
    }
}

/// The joint values found for a row and how close the model gets there.
#[derive(Debug, Clone, PartialEq)]
pub struct Solved {
    /// Joint values, rad (m).
    pub q: Vec<f64>,
    /// Distance of the model's tool point from the target, m.
    pub residual_m: f64,
    /// Angle between the model's and the target orientation, rad, when it counts.
    pub residual_rad: Option<f64>,
    /// Newton steps taken.
    pub iterations: usize,
    /// Whether the row is to be used, or why not.
    pub status: TargetStatus,
}

/// Point and rotation error of `pose` against a target.
fn errors(target: &PoseTarget, pose: &SE3) -> (Vector3, Vector3) {
    let point = target.pose.translation() - pose.translation();
    let rotation =
        if target.orientation { (target.pose.rotation() * pose.rotation().inverse()).log() } else { Vector3::zeros() };
    (point, rotation)
}

/// The tool-point Jacobian (point rows, then rotation rows if the orientation counts).
fn jacobian(model: &CalibratedModel, q: &[f64], tool: usize, orientation: bool) -> Result<DMatrix<f64>, Error> {
    let full = loadsim::tool_point_jacobian(&model.kinematics, q, tool).map_err(Error::load)?;
    Ok(if orientation { full } else { full.rows(0, 3).into_owned() })
}

/// The Newton step of one row, capped at `max_step`.
fn step(
    jacobian: DMatrix<f64>,
    point: Vector3,
    rotation: Vector3,
    orientation: bool,
    options: &InverseOptions,
) -> DVector<f64> {
    let e = if orientation {
        DVector::from_iterator(6, point.iter().chain(rotation.iter()).copied())
    } else {
        DVector::from_iterator(3, point.iter().copied())
    };
    let svd = jacobian.svd(true, true);
    let largest = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let mut dq = svd.solve(&e, options.rcond * largest).unwrap_or_else(|_| DVector::zeros(e.len()));
    let biggest = dq.amax();
    if biggest > options.max_step {
        dq *= options.max_step / biggest;
    }
    dq
}

/// Solves every target; `limits` (SI, base first) refuses solutions outside them.
pub fn solve_targets(
    model: &CalibratedModel,
    targets: &[PoseTarget],
    limits: Option<&[(f64, f64)]>,
    options: &InverseOptions,
) -> Result<Vec<Solved>, Error> {
    let iterates = newton(model, targets, options)?;
    targets.par_iter().enumerate().map(|(i, target)| solved(model, target, &iterates, i, limits, options)).collect()
}

/// Each target's joint values, steps taken and last position and rotation errors.
struct Iterates {
    q: Vec<Vec<f64>>,
    iterations: Vec<usize>,
    residual: Vec<(Vector3, Vector3)>,
}

/// The row that puts the joints at `q` for `target`, on its target's model tool.
fn target_row(target: &PoseTarget, q: &[f64]) -> Measurement {
    Measurement {
        line: 0,
        q: q.to_vec(),
        position: Vector3::zeros(),
        orientation: None,
        payload_kg: target.payload_kg,
        tool: target.tool,
        temp_c: None,
        t_s: None,
        torques_nm: None,
        inputs: target.inputs.clone(),
        std: None,
    }
}

/// Newton steps from each target's seed, all open targets predicted together, until each is
/// within tolerance or out of iterations.
fn newton(model: &CalibratedModel, targets: &[PoseTarget], options: &InverseOptions) -> Result<Iterates, Error> {
    let mut it = Iterates {
        q: targets.iter().map(|t| t.seed.clone()).collect(),
        iterations: vec![0; targets.len()],
        residual: vec![(Vector3::zeros(), Vector3::zeros()); targets.len()],
    };
    let mut open: Vec<usize> = (0..targets.len()).collect();
    loop {
        // Made here from the targets, each row on its target's model tool.
        let rows =
            BoundSet::made_for_model("the targets", open.iter().map(|&i| target_row(&targets[i], &it.q[i])).collect());
        let poses = model.predict(&rows)?;
        let mut still = Vec::with_capacity(open.len());
        for (&i, predicted) in open.iter().zip(&poses) {
            it.residual[i] = errors(&targets[i], &predicted.pose);
            let (point, rotation) = it.residual[i];
            let done =
                point.norm() <= options.position_tolerance_m && rotation.norm() <= options.rotation_tolerance_rad;
            if !done && it.iterations[i] < options.max_iterations {
                still.push(i);
            }
        }
        open = still;
        if open.is_empty() {
            return Ok(it);
        }
        let steps: Vec<Result<DVector<f64>, Error>> = open
            .par_iter()
            .map(|&i| {
                let target = &targets[i];
                let j = jacobian(model, &it.q[i], target.tool, target.orientation)?;
                Ok(step(j, it.residual[i].0, it.residual[i].1, target.orientation, options))
            })
            .collect();
        for (&i, dq) in open.iter().zip(steps) {
            let dq = dq?;
            for (value, change) in it.q[i].iter_mut().zip(dq.iter()) {
                *value += change;
            }
            it.iterations[i] += 1;
        }
    }
}

/// Target `i`'s solution and its status: not converged, near a singularity, or (when `limits`
/// are given) outside them, in that order of precedence.
fn solved(
    model: &CalibratedModel,
    target: &PoseTarget,
    it: &Iterates,
    i: usize,
    limits: Option<&[(f64, f64)]>,
    options: &InverseOptions,
) -> Result<Solved, Error> {
    let (point, rotation) = it.residual[i];
    let status = if point.norm() > options.accept_position_m || rotation.norm() > options.accept_rotation_rad {
        TargetStatus::NoConvergence {
            iterations: it.iterations[i],
            position_m: point.norm(),
            rotation_rad: rotation.norm(),
        }
    } else {
        TargetStatus::Ok
    };
    let smallest = jacobian(model, &it.q[i], target.tool, target.orientation)?
        .singular_values()
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let status = if smallest < options.min_singular_value {
        TargetStatus::Singular { smallest, floor: options.min_singular_value }
    } else {
        status
    };
    let status = match (status, limits) {
        (TargetStatus::Ok, Some(limits)) => outside(&it.q[i], limits, model).unwrap_or(TargetStatus::Ok),
        (status, _) => status,
    };
    debug_assert_eq!(it.q[i].len(), model.joint_count());
    Ok(Solved {
        q: it.q[i].clone(),
        residual_m: point.norm(),
        residual_rad: target.orientation.then(|| rotation.norm()),
        iterations: it.iterations[i],
        status,
    })
}

/// The first joint outside its limits.
fn outside(q: &[f64], limits: &[(f64, f64)], model: &CalibratedModel) -> Option<TargetStatus> {
    let kinds = model.joint_kinds();
    q.iter().zip(limits).zip(kinds).enumerate().find_map(|(j, ((&value, &(lo, hi)), kind))| {
        (value < lo || value > hi).then_some(TargetStatus::OutsideLimits {
            joint: j + 1,
            value,
            limits: (lo, hi),
            revolute: kind == poe::JointKind::Revolute,
        })
    })
}
