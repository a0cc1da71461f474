//! The flows of `fit`, `eval`, `predict` and `compensate`, run by the `calib` binary and by the
//! Python package (`crates/python`) alike: the same library calls in the same order, so that a
//! number in Python equals the CLI's to the last bit. Each front end reads its inputs its own way
//! (flags and files, or keyword arguments and arrays) and prints or returns what these give; the
//! refusals here are the library's, each front end names its own flags in its own.

use cell::{CompensateOptions, CompensationSummary, Solved, TargetFile, TargetFrame};
use effects::EffectSelection;
use errors::Error;
use measurements::{BoundSet, MeasurementSet};
use model::{CalibratedModel, EvalReport, Evaluation, GpChoice, Method, PoseError, PredictedPose, WrappedJoint};
use pipeline::{FitOptions, FitReport};
use robot::RobotDescription;
use std::path::Path;

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

/// `eval`'s result: the rows evaluated (wrapped into the fitted range), each row's error and the
/// report.
#[derive(Debug)]
pub struct Evaluated {
    pub data: MeasurementSet,
    pub evaluation: Evaluation,
    pub report: EvalReport,
}

/// `eval`: `data` wrapped into the fitted range, bound once (joints checked, tools mapped) and
/// evaluated; a non-finite error refused (`model_file` names the model in the refusal).
pub fn evaluate(model: &CalibratedModel, model_file: &Path, data: MeasurementSet) -> Result<Evaluated, Refused> {
    let (data, wrapped) = wrapped(model, data);
    let bound = model.bind(&data)?;
    let evaluation = model::evaluate(model, &bound)?;
    let finite = |e: &PoseError| e.position_mm.is_finite() && e.rotation_mrad.is_none_or(f64::is_finite);
    if let Some((row, _)) = data.rows.iter().zip(&evaluation.errors).find(|(_, e)| !finite(e)) {
        return Err(Refused::non_finite(model_file, &data.source, row.line));
    }
    let report = EvalReport { wrapped, ..EvalReport::new(model, &bound, &evaluation) };
    Ok(Evaluated { data, evaluation, report })
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
