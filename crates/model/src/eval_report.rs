//! What `calib eval --json` prints: one typed object with the SPEC's keys (`n`,
//! `mean_position_error_mm`, `rms_position_error_mm`, `max_position_error_mm`, and for
//! full-pose data and a model fitted on it `mean_rotation_error_mrad`) and what identifies the run.

use crate::Evaluation;
use crate::{CalibratedModel, ErrorSummary, ExtrapolationWarning, Method, PoseError};
use measurements::{BoundSet, FileFormat, MeasurementSet};
use serde::{Deserialize, Serialize};

/// What `eval` says when the data has orientations that a position-only model cannot be judged on.
pub const ORIENTATIONS_NOT_EVALUATED: &str =
    "the model was fitted on positions only: orientations in the data are not evaluated";

/// The evaluation of a model on one measurement file: `calib eval --json`. It reads back from that
/// JSON, and from the SPEC's older one (the error statistics with `method` and `full_pose`): a field
/// an older report lacks reads as empty (`robot`, `data`, the warnings, no coverage split) or, for
/// `format`, as SPEC v1's only dialect (`,` and a decimal point).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvalReport {
    /// The model's method.
    pub method: Method,
    /// The robot the model was fitted for.
    #[serde(default)]
    pub robot: String,
    /// The measurement file.
    #[serde(default)]
    pub data: String,
    /// Whether the rotation errors are given: the data has orientations and the model was
    /// fitted on them.
    pub full_pose: bool,
    /// The data has orientations but the model was fitted on positions only: they are not
    /// evaluated (see [`ORIENTATIONS_NOT_EVALUATED`]).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub orientations_not_evaluated: bool,
    /// The error statistics, at the top level of the object.
    #[serde(flatten)]
    pub errors: ErrorSummary,
    /// How the measurement file was written.
    #[serde(default)]
    pub format: FileFormat,
    /// The errors on the rows inside the model's coverage (every effect's joint within the
    /// angles it was fitted on) and on the others, apart: the model is on firm ground only on
    /// the first. `None` for a model without effects that record their angles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<CoverageSplit>,
    /// Effects used outside the joint angles they were fitted on.
    #[serde(default)]
    pub warnings: Vec<ExtrapolationWarning>,
    /// Inputs (joints, payload, temperature, time) outside the range the model was fitted on,
    /// for every model that records it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub out_of_range: Vec<crate::OutOfRangeWarning>,
    /// What the geometry's own uncertainty predicts on the rows that put a joint outside the
    /// range the model was fitted on, for every model that keeps it ([`crate::GeometrySigma`]);
    /// `None` where no row does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry_sigma: Option<crate::GeometrySigma>,
    /// Joints beyond the robot's limits, for every model that keeps them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub beyond_joint_limits: Vec<crate::BeyondLimitsWarning>,
    /// The errors on the rows whose every input (joints, payload, temperature, time) lies within
    /// the range the model was fitted on, and on the others, apart: for every model that records
    /// its range, when some row lies outside it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_split: Option<CoverageSplit>,
    /// Rows whose error lies far beyond the others' (a measurement error more likely than the
    /// model's), named beside the statistics, which keep them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub suspect_rows: Option<crate::SuspectRows>,
    /// Rows at which the model's σ is so far above the training rows' that it falls back to the
    /// geometry fitted alone ([`crate::SigmaFallback`]); `None` where there are none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_fallback: Option<crate::SigmaFallback>,
    /// Rows at which the GP's correction fades toward the geometry ([`crate::GpFade`]); `None`
    /// where there are none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gp_fade: Option<crate::GpFade>,
    /// Revolute joints whose angles some rows had wrapped by whole turns into the range the model
    /// was fitted on before it was applied ([`crate::wrapped`], as `calib register` does); empty
    /// where none was (and left out of the JSON).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub wrapped: Vec<crate::WrappedJoint>,
    /// The data looks measured from another tracker placement than the model's: one rigid motion
    /// of the predictions explains most of the error ([`crate::OtherPlacement`]); `None` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other_placement: Option<crate::OtherPlacement>,
}

/// The errors inside and outside a model's coverage.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CoverageSplit {
    /// Rows whose every effect is within the angles it was fitted on.
    pub inside: ErrorSummary,
    /// The other rows: there the effects fade out and the model falls back to the geometry.
    pub outside: ErrorSummary,
}

impl CoverageSplit {
    /// The errors of the rows `inside` holds for and of the others.
    fn of(
        data: &MeasurementSet,
        evaluation: &Evaluation,
        inside: impl Fn(usize, &measurements::Measurement) -> bool,
    ) -> Self {
        let (ins, outs): (Vec<_>, Vec<_>) =
            data.rows.iter().enumerate().zip(&evaluation.errors).partition(|((i, row), _)| inside(*i, row));
        let summary = |part: Vec<(_, &PoseError)>| {
            ErrorSummary::from_errors(&part.into_iter().map(|(_, e)| *e).collect::<Vec<_>>())
        };
        Self { inside: summary(ins), outside: summary(outs) }
    }
}

impl EvalReport {
    /// The report of `evaluation`, the result of `model` on `bound` (bound to it).
    pub fn new(model: &CalibratedModel, bound: &BoundSet<'_>, evaluation: &Evaluation) -> Self {
        // The evaluation has walked the same rows: the σ cannot fail where it did not.
        let weights = model.sigma_weights(bound).ok().flatten();
        let data = bound.set();
        let held = |i: usize| weights.as_ref().is_none_or(|w| w[i].0 == 1.0);
        let sigma_fallback = match (&model.effect_uncertainty, &weights) {
            (Some(uncertainty), Some(weights)) => crate::SigmaFallback::of(&data.rows, weights, uncertainty),
            _ => None,
        };
        let covered = |i: usize, row: &measurements::Measurement| model.covers(row) && held(i);
        Self {
            method: model.method,
            robot: model.robot.clone(),
            data: data.source.clone(),
            full_pose: data.full_pose && model.full_pose,
            orientations_not_evaluated: data.full_pose && !model.full_pose,
            errors: evaluation.summary,
            format: data.format.clone(),
            coverage: (model.records_coverage() || sigma_fallback.is_some())
                .then(|| CoverageSplit::of(data, evaluation, covered)),
            warnings: model.extrapolation(&data.rows),
            out_of_range: model.outside_training_range(&data.rows),
            // The evaluation has walked the same rows with the same kinematics: it cannot fail here.
            geometry_sigma: model.geometry_sigma(bound).ok().flatten(),
            beyond_joint_limits: model.beyond_joint_limits(&data.rows),
            range_split: model
                .training_range
                .as_ref()
                .map(|range| CoverageSplit::of(data, evaluation, |_, row| range.contains(row)))
                .filter(|split| split.outside.n > 0),
            suspect_rows: suspects(model, data, evaluation, &held),
            sigma_fallback,
            // The evaluation has predicted the same rows with the same GP: it cannot fail here.
            gp_fade: model.gp_fade(&data.rows).ok().flatten(),
            wrapped: Vec::new(),
            other_placement: crate::OtherPlacement::of(
                &data.rows,
                &evaluation.poses,
                data.full_pose && model.full_pose,
                &crate::OtherPlacementOptions::default(),
            ),
        }
    }
}

/// The rows far beyond the others among those on the model's firm ground (inside its fitted
/// range and its effects' coverage, and not fallen back by σ): outside it a large error is the model's, not the data's.
/// The threshold is the one the fit names gross outliers of its training rows by.
fn suspects(
    model: &CalibratedModel,
    data: &MeasurementSet,
    evaluation: &Evaluation,
    held: &dyn Fn(usize) -> bool,
) -> Option<crate::SuspectRows> {
    let firm = |row: &measurements::Measurement| {
        model.covers(row) && model.training_range.as_ref().is_none_or(|range| range.contains(row))
    };
    let judged: Vec<usize> = (0..data.rows.len()).filter(|&i| firm(&data.rows[i]) && held(i)).collect();
    let threshold = poe::identify::RobustOptions::default().outlier_threshold;
    crate::suspect_rows::suspects_among(&data.rows, &evaluation.errors, &judged, threshold)
}

#[cfg(test)]
mod tests {
    use super::EvalReport;
    use crate::Method;

    /// `calib eval --json` as the first typed report and the SPEC's first binary wrote it: the error
    /// statistics, `method` and `full_pose`, nothing else.
    const OLDEST: &str = r#"{"n":3,"mean_position_error_mm":0.5,"rms_position_error_mm":0.6,
        "max_position_error_mm":0.9,"median_position_error_mm":0.4,"method":"poe-gp","full_pose":false}"#;

    #[test]
    fn the_oldest_eval_json_reads_with_empty_extras() {
        let report: EvalReport = serde_json::from_str(OLDEST).unwrap();
        assert_eq!((report.method, report.errors.n, report.errors.max_position_error_mm), (Method::PoeGp, 3, 0.9));
        assert!(report.robot.is_empty() && report.warnings.is_empty() && report.coverage.is_none());
        assert_eq!(report.format, measurements::FileFormat::default());
        assert_eq!(report.errors.mean_rotation_error_mrad, None);
    }

    #[test]
    fn a_report_reads_back_as_it_was_written() {
        let mut report: EvalReport = serde_json::from_str(OLDEST).unwrap();
        report.robot = "irb4400".into();
        report.errors.mean_rotation_error_mrad = Some(0.2);
        report.out_of_range.push(crate::OutOfRangeWarning {
            input: "temp_c".into(),
            unit: "°C",
            fitted: [20.0, 25.0],
            rows_outside: 1,
            rows: 3,
            first_line: 4,
        });
        let text = serde_json::to_string(&report).unwrap();
        assert_eq!(serde_json::from_str::<EvalReport>(&text).unwrap(), report, "{text}");
    }

    #[test]
    fn a_unit_no_report_writes_is_refused() {
        let text = OLDEST.replace(
            "\"full_pose\":false",
            "\"full_pose\":false,\"out_of_range\":[{\"input\":\"t_s\",\"unit\":\"furlong\",\"fitted\":[0,1],\"rows_outside\":1,\"rows\":3,\"first_line\":2}]",
        );
        let error = serde_json::from_str::<EvalReport>(&text).unwrap_err();
        assert!(error.to_string().contains("a unit"), "{error}");
    }
}
