//! The flows of `fit`, `eval`, `predict`, `compensate`, `simulate` and `diagnose`, run by the `calib` binary
//! and by the Python package (`crates/python`) alike: the same library calls in the same order, so
//! that a number in Python equals the CLI's to the last bit. Each front end reads its inputs its
//! own way (flags and files, or keyword arguments and arrays) and prints or returns what these
//! give; the refusals here are the library's, and each front end names its own flags in its own.

use campaign::ErrorKind;
use campaign::{GeneratorConfig, Perturbation, Remount, TorqueSensorNoise};
use cell::{CompensateOptions, CompensationSummary, Solved, TargetFile, TargetFrame};
use diagnose::{DiagnoseOptions, Diagnosis};
use effects::EffectSelection;
use errors::Error;
use measurements::{BoundSet, InputFiles, MeasurementSet};
use model::{CalibratedModel, EvalReport, Evaluation, GpChoice, Method, PoseError, PredictedPose, WrappedJoint};
use pipeline::{FitOptions, FitReport};
use robot::RobotDescription;
use std::path::{Path, PathBuf};

/// What `calib fit`'s flags (the Python `fit`'s keyword arguments) set over the fit options, as
/// they go over `--options`.
#[derive(Debug, Default)]
pub struct FitOverrides {
    /// `--effects`: the effects identified with the geometry.
    pub effects: Option<EffectSelection>,
    /// `--force`: the plausibility checks warn instead of refusing.
    pub force: bool,
    /// `--gp`: the GP of the -gp methods.
    pub gp: Option<GpChoice>,
    /// `--inputs`: measured signals the GP takes beside the joints (checked names).
    pub inputs: Option<Vec<String>>,
}

/// The refusal of GP inputs for a method without a GP.
#[derive(Debug)]
pub struct InputsWithoutGp(pub Method);

impl std::fmt::Display for InputsWithoutGp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the inputs are the GP's: method {} has no GP", self.0)
    }
}

impl FitOverrides {
    /// `options` with these set over them, for `method`; GP inputs are refused for a method
    /// without a GP.
    pub fn apply(self, options: &mut FitOptions, method: Method) -> Result<(), InputsWithoutGp> {
        if let Some(selection) = self.effects {
            options.effects.selection = selection;
        }
        if self.force {
            options.plausibility.force = true;
        }
        if let Some(choice) = self.gp {
            options.residual_gp.method = choice;
        }
        if let Some(inputs) = self.inputs {
            if !method.uses_gp() {
                return Err(InputsWithoutGp(method));
            }
            options.residual_gp.inputs = inputs;
        }
        Ok(())
    }
}

/// The fit and the writing of its model, timed as the phases `fit` and `write` (the caller's
/// `timings::record` collects them, with any phase of its own such as the reading).
pub fn fit_and_write<T>(
    robot: &RobotDescription,
    data: &MeasurementSet,
    method: Method,
    options: &FitOptions,
    write: impl FnOnce(&CalibratedModel) -> Result<T, Error>,
) -> Result<(CalibratedModel, FitReport, T), Error> {
    let (model, report) = timings::phase("fit", || pipeline::fit(robot, data, method, options))?;
    let written = timings::phase("write", || write(&model))?;
    Ok((model, report, written))
}

/// `data` with angles a turn away from the model's fitted range taken into it (as `calib register`
/// takes them), and the joints that were.
pub fn wrapped(model: &CalibratedModel, data: MeasurementSet) -> (MeasurementSet, Vec<WrappedJoint>) {
    let (rows, wrapped) = model::wrapped(model, &data.rows);
    (MeasurementSet { rows, ..data }, wrapped)
}

/// `eval`'s result: the rows evaluated (wrapped into the fitted range), each row's error, the
/// report and what is said beside it.
#[derive(Debug)]
pub struct Evaluated {
    pub data: MeasurementSet,
    pub evaluation: Evaluation,
    pub report: EvalReport,
    pub notices: EvalNotices,
}

/// `eval`: `data` wrapped into the fitted range, bound once (joints checked, tools mapped) and
/// evaluated; a non-finite error refused. `model_name` names the model in the refusal; where
/// `from_file`, it is the file the model was read from, and the command a warning suggests names it.
pub fn evaluate(
    model: &CalibratedModel,
    model_name: &Path,
    from_file: bool,
    data: MeasurementSet,
) -> Result<Evaluated, Refused> {
    let (data, wrapped) = wrapped(model, data);
    let bound = model.bind(&data)?;
    let evaluation = model::evaluate(model, &bound)?;
    let finite = |e: &PoseError| e.position_mm.is_finite() && e.rotation_mrad.is_none_or(f64::is_finite);
    if let Some((row, _)) = data.rows.iter().zip(&evaluation.errors).find(|(_, e)| !finite(e)) {
        return Err(Refused::non_finite(model_name, &data.source, row.line));
    }
    let report = EvalReport { wrapped, ..EvalReport::new(model, &bound, &evaluation) };
    let notices = EvalNotices::of(&report, from_file.then_some(model_name));
    Ok(Evaluated { data, evaluation, report, notices })
}

/// What `eval` says beside its numbers, in the order every front end gives it: `calib eval` prints
/// each as `note: …` or `warning: …`, the Python package raises each as a warning. Built here once,
/// so that the two cannot drift apart.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EvalNotices {
    /// The joints wrapped by whole turns into the fitted range, then the orientations a
    /// position-only model leaves unjudged.
    pub notes: Vec<String>,
    /// What deserves caution: first what points at the data (another tracker placement, rows far
    /// beyond the others), then the rows beyond what the model was fitted on.
    pub warnings: Vec<String>,
}

impl EvalNotices {
    /// The notes and warnings of `report`; `model_file` (where the model was read from one) is
    /// named in the command the placement warning suggests, `MODEL` otherwise.
    pub fn of(report: &EvalReport, model_file: Option<&Path>) -> Self {
        let mut notes: Vec<String> = report.wrapped.iter().map(ToString::to_string).collect();
        if report.orientations_not_evaluated {
            notes.push(model::ORIENTATIONS_NOT_EVALUATED.to_owned());
        }
        let mut warnings: Vec<String> = Vec::new();
        if let Some(placement) = &report.other_placement {
            let text = placement.to_string();
            warnings.push(match model_file {
                Some(file) => text.replace("--model MODEL", &format!("--model {}", file.display())),
                None => text,
            });
        }
        warnings.extend(report.suspect_rows.iter().map(suspect_text));
        warnings.extend(report.warnings.iter().map(ToString::to_string));
        warnings.extend(report.out_of_range.iter().map(ToString::to_string));
        warnings.extend(report.geometry_sigma.iter().map(ToString::to_string));
        warnings.extend(report.beyond_joint_limits.iter().map(ToString::to_string));
        warnings.extend(report.sigma_fallback.iter().map(ToString::to_string));
        warnings.extend(report.gp_fade.iter().map(ToString::to_string));
        Self { notes, warnings }
    }
}

/// The warning about rows far beyond the others, with what the others give.
fn suspect_text(suspects: &model::SuspectRows) -> String {
    let w = &suspects.without;
    format!(
        "{} row(s) lie beyond {} robust sigmas of the other rows' errors: {}; a measurement error \
         (a tracker glitch, a row measured twice apart) more likely than the model's; without them: \
         mean {:.4} mm, max {:.4} mm (the numbers above keep them)",
        suspects.rows.len(),
        suspects.threshold_sigmas,
        measurements::list_lines(&suspects.rows),
        w.mean_position_error_mm,
        w.max_position_error_mm
    )
}

/// `predict`'s result: a pose per row, and what `predict` says beside them.
#[derive(Debug)]
pub struct Predicted {
    pub poses: Vec<PredictedPose>,
    /// The joints wrapped into the fitted range.
    pub notes: Vec<String>,
    /// Rows beyond what the model was fitted on, in the order the CLI prints them.
    pub warnings: Vec<String>,
}

/// `predict` on rows bound to the model (wrapped into the fitted range before, `wrapped` the
/// joints that were); a non-finite pose refused (`model_file` names the model in the refusal).
pub fn predict(
    model: &CalibratedModel,
    model_file: &Path,
    data: &BoundSet<'_>,
    wrapped: &[WrappedJoint],
) -> Result<Predicted, Refused> {
    let rows = data.rows();
    let poses = model.predict(data)?;
    let finite = |p: &PredictedPose| {
        let pose = p.pose;
        pose.translation().iter().chain(pose.rotation().matrix().iter()).all(|v| v.is_finite())
    };
    if let Some(row) = rows.iter().zip(&poses).find_map(|(row, p)| (!finite(p)).then_some(row)) {
        return Err(Refused::non_finite(model_file, &data.set().source, row.line));
    }
    let notes = wrapped.iter().map(ToString::to_string).collect();
    let mut warnings: Vec<String> = model.extrapolation(rows).iter().map(ToString::to_string).collect();
    warnings.extend(model.outside_training_range(rows).iter().map(ToString::to_string));
    warnings.extend(model.geometry_sigma(data)?.iter().map(ToString::to_string));
    warnings.extend(model.beyond_joint_limits(rows).iter().map(ToString::to_string));
    warnings.extend(model.sigma_fallback(data)?.iter().map(ToString::to_string));
    warnings.extend(model.gp_fade(rows)?.iter().map(ToString::to_string));
    Ok(Predicted { poses, notes, warnings })
}

/// A refusal of `eval` or `predict`: the library's, or a model that gives a non-finite pose.
#[derive(Debug)]
pub enum Refused {
    Error(Error),
    /// A value in the model file beyond any real range (the file's check accepts every finite
    /// number): refused, never a NaN printed as an answer. The message names the model, the row's
    /// line and the data.
    NonFinite(String),
}

impl Refused {
    pub fn non_finite(model: &Path, data: &str, line: u64) -> Self {
        Self::NonFinite(format!(
            "{}: the model predicts a non-finite pose for line {line} of {data}: a value in the model file is beyond any real range",
            model.display()
        ))
    }
}

impl From<Error> for Refused {
    fn from(error: Error) -> Self {
        Self::Error(error)
    }
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Error(error) => error.fmt(f),
            Self::NonFinite(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for Refused {}

/// `compensate`'s result: the targets read, each row solved, the summary, and the warnings on the
/// rows (beyond what the model was fitted on).
#[derive(Debug)]
pub struct CompensatedTargets {
    pub file: TargetFile,
    pub solved: Vec<Solved>,
    pub summary: CompensationSummary,
    pub warnings: Vec<String>,
}

/// `compensate`: the targets of `path` (headers mapped by `columns`) rewritten so that `model`
/// reaches what they mean; `robot` is the nominal description and the file it came from.
pub fn compensate(
    model: &CalibratedModel,
    path: &Path,
    columns: measurements::ColumnMap,
    robot: Option<(&RobotDescription, &str)>,
    frame: TargetFrame,
) -> Result<CompensatedTargets, Error> {
    let file = cell::read_targets(path, model, columns)?;
    let (solved, summary) = cell::compensate(model, &file, robot, frame, &CompensateOptions::default())?;
    let rows = &file.set.rows;
    let mut warnings: Vec<String> = model.extrapolation(rows).iter().map(ToString::to_string).collect();
    warnings.extend(model.outside_training_range(rows).iter().map(ToString::to_string));
    warnings.extend(model.beyond_joint_limits(rows).iter().map(ToString::to_string));
    Ok(CompensatedTargets { file, solved, summary, warnings })
}

/// `simulate`'s campaign shape, as its flags (the Python `simulate`'s keyword arguments) give it.
#[derive(Debug, Default)]
pub struct CampaignShape {
    /// Payloads, kg, one drawn per pose [default: the generator's].
    pub payloads: Option<Vec<f64>>,
    /// The joints that move, 1-based; the others sit at 0.
    pub moving_joints: Option<Vec<usize>>,
    /// The joints that do not move are drawn within ± this of 0, mrad.
    pub fixed_jitter_mrad: Option<f64>,
    /// The poses split into consecutive runs, one per payload.
    pub runs: bool,
    /// A run per payload with the probe remounted for each (implies `runs`).
    pub tool_per_payload: bool,
    /// Measured joint torques written.
    pub torques: bool,
    /// Standard deviation of the measured torques, N·m (with `torques`).
    pub torque_sigma_nm: Option<f64>,
}

/// A campaign shape refused; each front end names its own flags in the message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShapeFault {
    /// A moving joint numbered 0: they are numbered from 1.
    JointZero,
    /// A jitter of the joints that do not move, without moving joints.
    JitterWithoutMovingJoints,
    /// A jitter that is not a non-negative number.
    Jitter(f64),
    /// A torque sigma without torques.
    SigmaWithoutTorques,
    /// A torque sigma that is not a non-negative number.
    Sigma(f64),
}

impl CampaignShape {
    /// The generator's configuration for `rows` poses drawn from `seed`.
    pub fn config(self, rows: usize, seed: u64) -> Result<GeneratorConfig, ShapeFault> {
        let defaults = GeneratorConfig::default();
        let payloads_kg = self.payloads.unwrap_or_else(|| defaults.payloads_kg.clone());
        let mut moving_joints = Vec::new();
        for joint in self.moving_joints.into_iter().flatten() {
            if joint == 0 {
                return Err(ShapeFault::JointZero);
            }
            moving_joints.push(joint - 1);
        }
        moving_joints.sort_unstable();
        moving_joints.dedup();
        if self.fixed_jitter_mrad.is_some() && moving_joints.is_empty() {
            return Err(ShapeFault::JitterWithoutMovingJoints);
        }
        let jitter = self.fixed_jitter_mrad.unwrap_or(0.0);
        if !(jitter.is_finite() && jitter >= 0.0) {
            return Err(ShapeFault::Jitter(jitter));
        }
        if self.torque_sigma_nm.is_some() && !self.torques {
            return Err(ShapeFault::SigmaWithoutTorques);
        }
        if let Some(sigma) = self.torque_sigma_nm.filter(|s| !(s.is_finite() && *s >= 0.0)) {
            return Err(ShapeFault::Sigma(sigma));
        }
        let torque_sensor = self.torques.then(|| match self.torque_sigma_nm {
            Some(sigma_nm) => TorqueSensorNoise { sigma_nm, ..TorqueSensorNoise::default() },
            None => TorqueSensorNoise::default(),
        });
        Ok(GeneratorConfig {
            sample_count: rows,
            seed,
            payloads_kg,
            moving_joints,
            fixed_jitter_rad: jitter * 1e-3,
            payload_runs: self.runs || self.tool_per_payload,
            tool_per_run: self.tool_per_payload,
            torque_sensor,
            ..defaults
        })
    }
}

/// `simulate`: the campaign `config` describes on `robot` (read from `robot_file`) with `effects`,
/// written row by row as measurement CSV to `out` (`out_name` in messages); the number of rows.
/// A planar chain is refused where every joint moves: the generator draws poses where the tool
/// point moves in all three directions, which a planar chain has not, and would refuse them only
/// after a million draws as "too strict a threshold".
pub fn simulate(
    robot: &RobotDescription,
    robot_file: &str,
    effects: &campaign::Effects,
    config: &GeneratorConfig,
    full_pose: bool,
    out: impl std::io::Write,
    out_name: &str,
) -> Result<usize, Error> {
    simulate_day(robot, robot_file, effects, config, &campaign::Day::default(), full_pose, out, out_name)
}

/// [`simulate`] on `day` of the campaign: the cell drawn from `config`'s seed as on the first
/// day, then re-sighted, its clock and its draws moved to the day ([`campaign::Day::of`]).
#[allow(clippy::too_many_arguments)] // `simulate`'s arguments and the day
pub fn simulate_day(
    robot: &RobotDescription,
    robot_file: &str,
    effects: &campaign::Effects,
    config: &GeneratorConfig,
    day: &campaign::Day,
    full_pose: bool,
    out: impl std::io::Write,
    out_name: &str,
) -> Result<usize, Error> {
    if config.moving_joints.is_empty()
        && let Some(direction) = robot.planar_direction()
    {
        let joints = robot.joint_count();
        return Err(Error::in_file(robot_file.to_owned(), ErrorKind::PlanarChain { direction, joints }));
    }
    let cell = campaign::campaign_cell(robot, &Perturbation::default(), &Remount::default(), config)?;
    let (cell, config) = day.of(&cell, config);
    campaign::simulate_to_csv(&cell, effects, &campaign::joint_ranges(robot), &config, full_pose, out, out_name)
}

/// `diagnose`: the diagnosis of `data` for `robot` and, where `report` names a folder, the
/// markdown report with its plots written there (with the option that names the folder in
/// refusals, and the command's input files, which it never replaces); the report's path.
pub fn diagnose(
    robot: &RobotDescription,
    data: &MeasurementSet,
    options: &DiagnoseOptions,
    report: Option<(&Path, &'static str, &InputFiles)>,
) -> Result<(Diagnosis, Option<PathBuf>), Error> {
    let diagnosis = diagnose::diagnose(robot, data, options)?;
    let written = report
        .map(|(folder, option, inputs)| report::write_diagnosis_report(&diagnosis, folder, option, inputs))
        .transpose()?;
    Ok((diagnosis, written))
}
