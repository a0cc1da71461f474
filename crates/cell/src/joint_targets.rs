//! `calib compensate`: a robot program's targets rewritten so that the calibrated robot reaches
//! what the program means ("filtering", as vendors' absolute-accuracy options and offline
//! programming tools do it).
//!
//! A targets file holds either joint targets — a program taught on the nominal model, meaning the
//! poses the nominal model reaches there — or tool poses (`x_mm`… and optionally an orientation)
//! with seed joint values, in the tracker frame or the base frame ([`robot::base_frame`]).
//!
//! A program taught on the nominal model means poses in the cell, and a tracker cannot say where
//! the nominal base is: we take the nominal model placed on the calibrated one as a base-and-tool
//! calibration would place it (the `base-tool` fit, on the calibrated model's own predictions at
//! fixed configurations). The intended pose of a joint target is that model's pose there, so
//! compensation removes what no placement of base and tool can, and the program's error before
//! compensation is the error a user with a registered cell would see.

use crate::inverse::{InverseOptions, PoseTarget, Solved, TargetStatus, solve_targets};
use errors::{Error, ErrorKind};
use lie::{SE3, SO3};
use measurements::{BoundSet, Cells, ColumnMap, MeasurementSet};
use model::CalibratedModel;
use poe::LocalPoe;
use poe::identify::{IdentificationOptions, Observation, Scope, Target};
use robot::RobotDescription;
use robot::{NominalTolerance, check_nominal, in_base_frame, tracker_from_base};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;
use std::str::FromStr;

/// The frame of pose targets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TargetFrame {
    /// The tracker frame, as measurements are.
    #[default]
    Tracker,
    /// The robot's base frame (the calibrated model's, `robot`'s `base_frame.rs`).
    Base,
}

impl FromStr for TargetFrame {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "tracker" => Ok(TargetFrame::Tracker),
            "base" => Ok(TargetFrame::Base),
            other => Err(format!("unknown frame '{other}': expected base or tracker")),
        }
    }
}

/// Everything `compensate` can be tuned by.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CompensateOptions {
    /// The inverse kinematics.
    pub inverse: InverseOptions,
    /// How far the robot description may be from the model.
    pub nominal: NominalTolerance,
    /// Configurations the nominal model is placed on the calibrated one at: 200, like a
    /// calibration campaign, drawn away from limits and singularities.
    pub registration_configurations: usize,
    /// Seed of those configurations.
    pub registration_seed: u64,
}

impl Default for CompensateOptions {
    fn default() -> Self {
        Self {
            inverse: InverseOptions::default(),
            nominal: NominalTolerance::default(),
            registration_configurations: 200,
            registration_seed: 0,
        }
    }
}

/// A targets file: its rows, and every cell as written to pass the unused ones on.
#[derive(Debug, Clone)]
pub struct TargetFile {
    /// The rows: joint values (nominal or seed), and for pose targets the pose.
    pub set: MeasurementSet,
    /// The cells as written.
    pub cells: Cells,
}

impl TargetFile {
    /// Whether the rows are poses (with seeds) rather than joint targets.
    pub fn poses(&self) -> bool {
        self.set.positions_measured
    }
}

/// Reads a targets file for `model`: the measurement CSV with joint columns and optionally
/// positions and orientations. An orientation is refused without a position, or where the model
/// was fitted on positions only (its orientation is not calibrated).
pub fn read_targets(path: &Path, model: &CalibratedModel, columns: ColumnMap) -> Result<TargetFile, Error> {
    let options = model.read_options(columns);
    let (set, cells) = measurements::read_configurations_with_cells(path, &options)?;
    if set.full_pose && !(set.positions_measured && model.full_pose) {
        let names = ["qw", "rx_deg", "rx_rad"];
        let mapped = |name: &str| {
            set.format.mapped_columns.iter().find(|(spec, _)| spec == name).map_or(name.to_owned(), |(_, h)| h.clone())
        };
        let column = names.iter().find_map(|n| cells.header.iter().position(|h| *h == mapped(n))).map_or(1, |i| i + 1);
        return Err(Error::at_line(
            set.source.clone(),
            1,
            column,
            ErrorKind::TargetOrientation { without_position: !set.positions_measured },
        ));
    }
    Ok(TargetFile { set, cells })
}

/// The nominal model placed on the calibrated one by a base-and-tool fit, and how far it stays.
#[derive(Debug, Clone)]
pub struct RegisteredNominal {
    /// The nominal kinematics, tracker frame, with the model's tools.
    pub model: LocalPoe,
    /// RMS distance of its tool points from the calibrated model's at the fit's configurations, m.
    pub rms_m: f64,
}

/// Places `robot`'s nominal model on `model` ([`CompensateOptions::registration_configurations`]).
/// A description that stays further than the nominal tolerance is refused: it is not this robot.
pub fn registered_nominal(
    model: &CalibratedModel,
    robot: &RobotDescription,
    file: &str,
    options: &CompensateOptions,
) -> Result<RegisteredNominal, Error> {
    let nominal = robot.nominal_model()?;
    if nominal.joint_count() != model.joint_count() {
        return Err(Error::in_file(
            file.to_owned(),
            ErrorKind::RobotJointCount { robot: nominal.joint_count(), model: model.joint_count() },
        ));
    }
    let config = loadsim::GeneratorConfig {
        sample_count: options.registration_configurations,
        seed: options.registration_seed,
        ..loadsim::GeneratorConfig::default()
    };
    let configurations =
        loadsim::sample_configurations(&nominal, 0, &campaign::joint_ranges(robot), &config).map_err(Error::load)?;
    let mut observations = Vec::new();
    for q in &configurations {
        for tool in 0..model.kinematics.tool_count() {
            let pose = model.kinematics.forward(q, tool).map_err(Error::kinematics)?;
            let target = if model.full_pose { Target::Pose(pose) } else { Target::Point(pose.translation()) };
            observations.push(Observation { q: q.clone(), tool, target, stated_sigma: None });
        }
    }
    let fitted = poe::identify::calibrate(&nominal, &observations, Scope::BaseTool, &IdentificationOptions::default())
        .map_err(Error::kinematics)?;
    let squares: f64 = observations
        .iter()
        .map(|o| {
            let reached = fitted.model.forward(&o.q, o.tool).map(|p| p.translation()).unwrap_or_default();
            let wanted = match o.target {
                Target::Pose(p) => p.translation(),
                Target::Point(p) => p,
            };
            (reached - wanted).norm_squared()
        })
        .sum();
    let rms_m = (squares / observations.len().max(1) as f64).sqrt();
    if rms_m > options.nominal.offset_m {
        return Err(Error::in_file(
            file.to_owned(),
            ErrorKind::RegistrationMismatch { rms_mm: rms_m * 1e3, limit_mm: options.nominal.offset_m * 1e3 },
        ));
    }
    Ok(RegisteredNominal { model: fitted.model, rms_m })
}

/// What `compensate` found, for the summary line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CompensationSummary {
    /// Rows read.
    pub rows: usize,
    /// Rows compensated.
    pub ok: usize,
    /// Rows refused for their limits, convergence, singularity.
    pub outside_limits: usize,
    /// See `outside_limits`.
    pub no_convergence: usize,
    /// See `outside_limits`.
    pub singular: usize,
    /// Mean distance the model puts the tool from the targets at the rows' own joint values, mm:
    /// the program's error before compensation (joint targets).
    pub before_mean_mm: f64,
    /// Largest Newton steps a row took.
    pub max_iterations: usize,
    /// RMS of the nominal model placed on the calibrated one, mm (joint targets).
    pub registration_rms_mm: Option<f64>,
}

/// The targets of every row as the inverse kinematics takes them.
pub fn pose_targets(
    model: &CalibratedModel,
    file: &TargetFile,
    robot: Option<(&RobotDescription, &str)>,
    frame: TargetFrame,
    options: &CompensateOptions,
) -> Result<(Vec<PoseTarget>, Option<RegisteredNominal>), Error> {
    targets_of(model, &model.bind(&file.set)?, file, robot, frame, options)
}

/// [`pose_targets`] of `file`'s rows bound to `model` (`bound`).
fn targets_of(
    model: &CalibratedModel,
    bound: &BoundSet<'_>,
    file: &TargetFile,
    robot: Option<(&RobotDescription, &str)>,
    frame: TargetFrame,
    options: &CompensateOptions,
) -> Result<(Vec<PoseTarget>, Option<RegisteredNominal>), Error> {
    let need_robot =
        || Error::at_line(file.set.source.clone(), 1, 1, ErrorKind::TargetsNeedRobot { poses: file.poses() });
    if !file.poses() {
        let (robot, robot_file) = robot.ok_or_else(need_robot)?;
        let registered = registered_nominal(model, robot, robot_file, options)?;
        let targets = bound
            .iter()
            .map(|(row, tool)| {
                Ok(PoseTarget {
                    seed: row.q.clone(),
                    pose: registered.model.forward(&row.q, tool).map_err(Error::kinematics)?,
                    orientation: model.full_pose,
                    payload_kg: row.payload_kg,
                    tool,
                    inputs: row.inputs.clone(),
                })
            })
            .collect::<Result<_, Error>>()?;
        return Ok((targets, Some(registered)));
    }
    let placement = match frame {
        TargetFrame::Tracker => SE3::identity(),
        TargetFrame::Base => {
            let (robot, robot_file) = robot.ok_or_else(need_robot)?;
            let nominal = robot.nominal_model()?;
            let in_base = in_base_frame(&model.kinematics, Some(&nominal));
            check_nominal(&in_base, &nominal, model.full_pose, &options.nominal, robot_file)?;
            tracker_from_base(&model.kinematics, Some(&nominal))
        }
    };
    let targets = bound
        .iter()
        .map(|(row, tool)| PoseTarget {
            seed: row.q.clone(),
            pose: placement * SE3::new(row.orientation.unwrap_or_else(SO3::identity), row.position),
            orientation: row.orientation.is_some(),
            payload_kg: row.payload_kg,
            tool,
            inputs: row.inputs.clone(),
        })
        .collect();
    Ok((targets, None))
}

/// Compensates every row of `file`: [`pose_targets`], then [`solve_targets`] within `robot`'s limits.
pub fn compensate(
    model: &CalibratedModel,
    file: &TargetFile,
    robot: Option<(&RobotDescription, &str)>,
    frame: TargetFrame,
    options: &CompensateOptions,
) -> Result<(Vec<Solved>, CompensationSummary), Error> {
    let bound = model.bind(&file.set)?;
    let (targets, registered) = targets_of(model, &bound, file, robot, frame, options)?;
    let limits = robot.map(|(r, _)| r.limits());
    let solved = solve_targets(model, &targets, limits.as_deref(), &options.inverse)?;
    let before = model.predict(&bound)?;
    let before_mean_mm = before
        .iter()
        .zip(&targets)
        .map(|(p, t)| (p.pose.translation() - t.pose.translation()).norm() * 1e3)
        .sum::<f64>()
        / targets.len().max(1) as f64;
    let count = |f: &dyn Fn(&TargetStatus) -> bool| solved.iter().filter(|s| f(&s.status)).count();
    let summary = CompensationSummary {
        rows: solved.len(),
        ok: count(&|s| s.is_ok()),
        outside_limits: count(&|s| matches!(s, TargetStatus::OutsideLimits { .. })),
        no_convergence: count(&|s| matches!(s, TargetStatus::NoConvergence { .. })),
        singular: count(&|s| matches!(s, TargetStatus::Singular { .. })),
        before_mean_mm,
        max_iterations: solved.iter().map(|s| s.iterations).max().unwrap_or(0),
        registration_rms_mm: registered.map(|r| r.rms_m * 1e3),
    };
    Ok((solved, summary))
}

/// Writes the compensated targets as CSV: `q1_rad … qN_rad` (`qK_m` for a prismatic joint;
/// empty for a refused row), every
/// input column as written (joint columns renamed `nominal_…`), `residual_mm`, `residual_mrad`
/// (empty without an orientation) and `status`.
pub fn write_compensated<W: Write>(writer: W, file: &TargetFile, solved: &[Solved]) -> Result<(), std::io::Error> {
    let mut out = csv::Writer::from_writer(writer);
    let joint_columns: Vec<usize> = file.set.joint_columns.iter().map(|c| c.column - 1).collect();
    let n = file.set.joint_count;
    // A prismatic joint's value is in metres (SI inside, as the reader takes `_m`): `q{k}_m`, so
    // that the output reads back as a measurement or targets file.
    let kind = |k: usize| file.set.joint_columns.get(k - 1).map(|c| c.kind);
    let mut header: Vec<String> = (1..=n)
        .map(|k| match kind(k) {
            Some(poe::JointKind::Prismatic) => format!("q{k}_m"),
            _ => format!("q{k}_rad"),
        })
        .collect();
    header.extend(
        file.cells
            .header
            .iter()
            .enumerate()
            .map(|(i, name)| if joint_columns.contains(&i) { format!("nominal_{name}") } else { name.clone() }),
    );
    // Each row's line in the targets file, last: version 2's columns keep their places.
    header.extend(["residual_mm", "residual_mrad", "status", "line"].map(String::from));
    out.write_record(&header)?;
    for ((cells, solved), row) in file.cells.rows.iter().zip(solved).zip(&file.set.rows) {
        let mut record: Vec<String> = if solved.status.is_ok() {
            solved.q.iter().map(|v| format!("{v:?}")).collect()
        } else {
            vec![String::new(); n]
        };
        record.extend(cells.iter().cloned());
        record.push(format!("{:.6}", solved.residual_m * 1e3));
        record.push(solved.residual_rad.map_or(String::new(), |r| format!("{:.6}", r * 1e3)));
        record.push(solved.status.to_string());
        record.push(row.line.to_string());
        out.write_record(&record)?;
    }
    out.flush()
}
