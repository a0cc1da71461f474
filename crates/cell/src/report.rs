//! What `calib register` reports (`--json`: [`RegisterReport`], additive to the SPEC's JSON).

use crate::register_options::{Refit, RegisterOptions};
use crate::registration::Registration;
use errors::Error;
use measurements::MeasurementSet;
use model::WrappedJoint;
use model::{
    BeyondLimitsWarning, CalibratedModel, ErrorSummary, ExtrapolationWarning, HeldoutSource, OutOfRangeWarning,
};
use serde::Serialize;
use std::fmt;

/// Whether the residual says the robot itself changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The residual is near the model's held-out error: the model carries over.
    Consistent,
    /// The residual is well above the model's held-out error: re-calibrate.
    RobotChanged,
    /// No held-out error of the model was given: nothing to judge against.
    Unknown,
}

/// Something the user should know about the registered model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RegisterWarning {
    /// The model's time-drift effect is a fixed twist of the old tracker frame and is kept as it was.
    DriftInOldFrame,
    /// Position-only data gave a new tool its point only: its orientation is that of the model's first tool.
    NewToolOrientationUnknown,
    /// The model was fitted on positions only, so it knows the flange's orientation only as far
    /// as its tool point shows it: a new or moved tool point is predicted with that orientation's
    /// error times the offset (millimetres for a 10 cm offset on the simulated IRB 4400).
    PositionModelToolPoint,
    /// The model was fitted on positions only: the data's orientations were not used.
    OrientationsIgnored,
}

impl fmt::Display for RegisterWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::DriftInOldFrame => {
                "the model's time_drift effect is a fixed twist of the old tracker frame and was kept unchanged: \
                 its prediction is not carried to the new frame"
            }
            Self::NewToolOrientationUnknown => {
                "position-only data fix a new tool's point only: its orientation is taken as the model's first \
                 tool's, and predicted orientations for it are not calibrated"
            }
            Self::PositionModelToolPoint => {
                "the model was fitted on positions only and knows the flange's orientation only as far as its tool \
                 point shows it: a new or moved tool point is predicted with that orientation's error times the \
                 offset; calibrate with full poses (or with this tool) to carry tools over"
            }
            Self::OrientationsIgnored => {
                "the model was fitted on positions only: the data's orientations were not used"
            }
        })
    }
}

/// A re-fitted tool.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegisteredTool {
    /// Its identifier (`""`: the default tool).
    pub name: String,
    /// Whether the model did not have it.
    pub new: bool,
    /// How far its point moved from the model tool it was measured against, mm.
    pub point_change_mm: f64,
    /// How far its orientation turned from that tool's, mrad.
    pub rotation_change_mrad: f64,
}

/// Where the tracker moved: `new_tracker_from_old_tracker`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameChange {
    /// Translation, mm.
    pub translation_mm: [f64; 3],
    /// Rotation vector, rad.
    pub rotation_rad: [f64; 3],
    /// Rotation angle, degrees.
    pub angle_deg: f64,
}

/// What `calib register` found (`--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegisterReport {
    /// Poses used.
    pub n: usize,
    /// Whether orientations were used (full-pose data and model).
    pub full_pose: bool,
    /// What was re-fitted.
    pub refit: Refit,
    /// Parameters re-fitted.
    pub parameters: usize,
    /// Residual rows (3 per position, 6 per pose).
    pub residual_rows: usize,
    /// Where the tracker moved (the identity where the base was not re-fitted).
    pub frame: FrameChange,
    /// The re-fitted tools.
    pub tools: Vec<RegisteredTool>,
    /// Levenberg–Marquardt iterations (of the last re-weighting).
    pub iterations: usize,
    /// The rotation rows' weight the fit ended with (variance-component estimate), m/rad.
    pub rotation_weight_m_per_rad: f64,
    /// The registered model's errors on the poses (every part of the model applied).
    pub residual: ErrorSummary,
    /// The mean position residual made unbiased for the fitted parameters, `× √(r / (r − p))`, mm:
    /// what it compares with a held-out error.
    pub residual_unbiased_mm: f64,
    /// The model's own held-out mean position error, mm: as given, else the fit's estimate in
    /// the model file.
    pub model_heldout_mm: Option<f64>,
    /// Where `model_heldout_mm` came from.
    pub heldout_from: Option<HeldoutFrom>,
    /// `residual_unbiased_mm / model_heldout_mm`.
    pub ratio: Option<f64>,
    /// The ratio above which the robot is said to have changed ([`RegisterOptions::changed_ratio`]).
    pub changed_ratio: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// Inputs of the poses outside the ranges the model was fitted on.
    pub out_of_range: Vec<OutOfRangeWarning>,
    /// Poses outside the joint angles an effect was fitted on.
    pub extrapolation: Vec<ExtrapolationWarning>,
    /// Poses beyond the robot's joint limits.
    pub beyond_joint_limits: Vec<BeyondLimitsWarning>,
    /// Joints whose angles were taken modulo 2π into the fitted range (the model was applied,
    /// and the coverage judged, at the wrapped angles).
    pub wrapped: Vec<WrappedJoint>,
    /// Other warnings.
    pub warnings: Vec<RegisterWarning>,
}

/// Where the held-out error judged against came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HeldoutFrom {
    /// `--heldout-mm`.
    Given,
    /// The fit's own estimate, kept in the model file.
    ModelFile(HeldoutSource),
}

/// A held-out error and where it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Heldout {
    pub mm: f64,
    pub from: HeldoutFrom,
}

/// What the registration re-fitted and found.
pub(crate) struct Fitted<'a> {
    pub refit: Refit,
    pub parameters: usize,
    pub fit: &'a Registration,
    pub tools: Vec<RegisteredTool>,
}

impl RegisterReport {
    pub(crate) fn new(
        registered: &CalibratedModel,
        data: &MeasurementSet,
        fitted: Fitted<'_>,
        heldout: Option<Heldout>,
        options: &RegisterOptions,
        wrapped: Vec<WrappedJoint>,
        warnings: Vec<RegisterWarning>,
    ) -> Result<Self, Error> {
        let Fitted { refit, parameters, fit, tools } = fitted;
        // A held-out error that is not a positive finite number is no reference.
        let heldout = heldout.filter(|h| h.mm.is_finite() && h.mm > 0.0);
        let heldout_mm = heldout.map(|h| h.mm);
        let evaluation = model::evaluate(registered, &registered.bind(data)?)?;
        let full_pose = data.full_pose && registered.full_pose;
        let residual_rows = data.rows.len() * if full_pose { 6 } else { 3 };
        let dof = residual_rows.saturating_sub(parameters).max(1) as f64;
        let residual_unbiased_mm = evaluation.summary.mean_position_error_mm * (residual_rows as f64 / dof).sqrt();
        let ratio = heldout_mm.map(|h| residual_unbiased_mm / h);
        let t = fit.frame.translation() * 1e3;
        let w = fit.frame.rotation().log();
        Ok(Self {
            n: data.rows.len(),
            full_pose,
            refit,
            parameters,
            residual_rows,
            frame: FrameChange {
                translation_mm: [t.x, t.y, t.z],
                rotation_rad: [w.x, w.y, w.z],
                angle_deg: w.norm().to_degrees(),
            },
            tools,
            iterations: fit.iterations,
            rotation_weight_m_per_rad: fit.rotation_weight_m_per_rad,
            residual: evaluation.summary,
            residual_unbiased_mm,
            model_heldout_mm: heldout_mm,
            heldout_from: heldout.map(|h| h.from),
            ratio,
            changed_ratio: options.changed_ratio,
            verdict: Verdict::of(ratio, options.changed_ratio),
            out_of_range: registered.outside_training_range(&data.rows),
            extrapolation: registered.extrapolation(&data.rows),
            beyond_joint_limits: registered.beyond_joint_limits(&data.rows),
            wrapped,
            warnings,
        })
    }

    /// The verdict in words, one line.
    pub fn verdict_line(&self) -> String {
        let from = match self.heldout_from {
            Some(HeldoutFrom::ModelFile(source)) => format!(", the fit's estimate: {source}"),
            _ => String::new(),
        };
        match (self.verdict, self.model_heldout_mm, self.ratio) {
            (Verdict::RobotChanged, Some(h), Some(r)) => format!(
                "the residual ({:.4} mm, unbiased) is {r:.2}× the model's held-out error ({h:.4} mm{from}), above \
                 {:.2}×: the robot itself has changed: re-calibrate",
                self.residual_unbiased_mm, self.changed_ratio
            ),
            (Verdict::Consistent, Some(h), Some(r)) => format!(
                "the residual ({:.4} mm, unbiased) is {r:.2}× the model's held-out error ({h:.4} mm{from}), within \
                 {:.2}×: the model carries over",
                self.residual_unbiased_mm, self.changed_ratio
            ),
            _ => format!(
                "the residual is {:.4} mm (unbiased); no held-out error of the model was given (--heldout-mm) and the \
                 model file holds none (written before it was kept, or a sparse GP), so whether the robot itself \
                 changed is unknown",
                self.residual_unbiased_mm
            ),
        }
    }

    /// Whether the poses lie outside what the model was fitted on.
    pub fn outside_coverage(&self) -> bool {
        !self.out_of_range.is_empty() || !self.extrapolation.is_empty()
    }

    /// The report as lines of text.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        let what = match (self.refit.base, self.refit.tools) {
            (true, true) => "base and tools",
            (true, false) => "base",
            (false, true) => "tools",
            (false, false) => "nothing",
        };
        lines.push(format!(
            "registered {what} on {} {} poses: {} parameters, {} residual rows, {} iterations",
            self.n,
            if self.full_pose { "full" } else { "position-only" },
            self.parameters,
            self.residual_rows,
            self.iterations
        ));
        if self.refit.base {
            let [x, y, z] = self.frame.translation_mm;
            lines.push(format!(
                "  tracker moved by ({x:.2}, {y:.2}, {z:.2}) mm and turned by {:.4} deg",
                self.frame.angle_deg
            ));
        }
        for tool in &self.tools {
            lines.push(format!(
                "  tool '{}'{}: point moved {:.3} mm, turned {:.3} mrad from the tool it was measured against",
                tool.name,
                if tool.new { " (new)" } else { "" },
                tool.point_change_mm,
                tool.rotation_change_mrad
            ));
        }
        let s = &self.residual;
        lines.push(format!(
            "  residual on the poses: mean {:.4} mm, rms {:.4} mm, max {:.4} mm{}",
            s.mean_position_error_mm,
            s.rms_position_error_mm,
            s.max_position_error_mm,
            s.mean_rotation_error_mrad.map_or(String::new(), |r| format!(", rotation mean {r:.4} mrad"))
        ));
        lines.push(format!("  {}", self.verdict_line()));
        if self.outside_coverage() {
            lines.push(
                "  the new poses lie outside the model's coverage (below): there its error is not what the fit measured"
                    .into(),
            );
        }
        lines.extend(self.wrapped.iter().map(|w| format!("  note: {w}")));
        lines.extend(self.out_of_range.iter().map(|w| format!("  warning: {w}")));
        lines.extend(self.extrapolation.iter().map(|w| format!("  warning: {w}")));
        lines.extend(self.beyond_joint_limits.iter().map(|w| format!("  warning: {w}")));
        lines.extend(self.warnings.iter().map(|w| format!("  warning: {w}")));
        lines
    }
}
