//! What a report holds: typed data, gathered by [`crate::Report::build`] and written by
//! [`crate::render_html`]. Every number here is one that the writer prints; none is recomputed
//! by the writer.

use diagnose::Diagnosis;
use model::{ErrorSummary, EvalReport};
use serde::Serialize;

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The robot: its name and joints.
    pub robot: RobotSummary,
    /// The test data.
    pub data: DataSummary,
    /// The training data, when it was given.
    pub training: Option<DataSummary>,
    /// The method, the effects and the GP.
    pub model: ModelSummary,
    /// `calib eval --json` on the test data, as it is: the report's "after" numbers are these.
    pub eval: EvalReport,
    /// The errors of the nominal model on the test data, its base and tools placed on the
    /// calibrated model ([`BeforeCalibration`]); `None` where the robot could not be placed.
    pub before: Option<BeforeCalibration>,
    /// The after-calibration errors with the 95th percentile, overall, per payload and per tool.
    pub after_groups: GroupedErrors,
    /// ISO 9283 position accuracy and repeatability.
    pub iso9283: crate::Iso9283,
    /// Every test row: where it is and its errors, file order.
    pub rows: Vec<RowError>,
    /// Each identified effect, as a curve over its joint's angle where it is one.
    pub effects: Vec<EffectView>,
    /// The GP's length scales per input, where the model has a GP.
    pub gp: Option<GpView>,
    /// What the user should know before trusting the numbers: the evaluation's.
    pub warnings: Vec<String>,
    /// The fit's own warnings, as the model file keeps them (`None`: a model written before they
    /// were kept).
    pub fit_warnings: Option<Vec<String>>,
    /// The diagnosis of the training data, when it was given.
    #[serde(skip)]
    pub diagnosis: Option<Diagnosis>,
}

/// The robot.
#[derive(Debug, Clone, Serialize)]
pub struct RobotSummary {
    /// Its name, as in the robot file.
    pub name: String,
    /// The robot file.
    pub file: String,
    /// Per joint: kind and limits (degrees or millimetres).
    pub joints: Vec<JointSummary>,
}

/// One joint of the robot.
#[derive(Debug, Clone, Serialize)]
pub struct JointSummary {
    /// `revolute` or `prismatic`.
    pub kind: &'static str,
    /// Lower and upper limit in the unit of [`JointSummary::unit`], if the robot file gives them.
    pub limits: Option<[f64; 2]>,
    /// `deg` or `mm`.
    pub unit: &'static str,
}

/// A measurement file.
#[derive(Debug, Clone, Serialize)]
pub struct DataSummary {
    /// The file.
    pub source: String,
    /// Number of rows.
    pub rows: usize,
    /// Whether the rows have orientations.
    pub full_pose: bool,
    /// Each payload with its row count, kg, ascending.
    pub payloads: Vec<(f64, usize)>,
    /// Each tool identifier with its row count (`""` is the default tool).
    pub tools: Vec<(String, usize)>,
    /// Per joint: smallest and largest value in the data, degrees (revolute) or mm (prismatic).
    pub joint_ranges: Vec<[f64; 2]>,
}

/// The model.
#[derive(Debug, Clone, Serialize)]
pub struct ModelSummary {
    /// The method (`poe-gp`, …).
    pub method: String,
    /// The model file.
    pub file: String,
    /// The model's parts in the order they apply.
    pub parts: Vec<String>,
    /// Whether it was fitted on full poses.
    pub full_pose: bool,
    /// The tool identifiers it knows.
    pub tools: Vec<String>,
}

/// The nominal model's errors on the test data.
#[derive(Debug, Clone, Serialize)]
pub struct BeforeCalibration {
    /// What "before" means here, in words.
    pub how: String,
    /// Its errors, grouped as the calibrated model's.
    pub groups: GroupedErrors,
}

/// The statistics of one set of errors, with the 95th percentile that [`ErrorSummary`] lacks.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ErrorStats {
    /// Mean, RMS, max, median (the same function as `calib eval`).
    pub summary: ErrorSummary,
    /// The 95th percentile of the position error, mm (nearest rank: the `⌈0.95 n⌉`-th smallest).
    pub p95_position_error_mm: f64,
}

/// Errors overall, per payload and per tool.
#[derive(Debug, Clone, Serialize)]
pub struct GroupedErrors {
    /// Every row.
    pub all: ErrorStats,
    /// Per payload (kg), ascending.
    pub per_payload: Vec<(f64, ErrorStats)>,
    /// Per tool identifier.
    pub per_tool: Vec<(String, ErrorStats)>,
}

/// One test row.
#[derive(Debug, Clone, Serialize)]
pub struct RowError {
    /// Line in the data file.
    pub line: u64,
    /// Measured position in the tracker frame, m.
    pub position_m: [f64; 3],
    /// Joint values (rad or m).
    pub q: Vec<f64>,
    /// Payload, kg.
    pub payload_kg: f64,
    /// Tool identifier.
    pub tool: String,
    /// Position error after calibration, mm (as `calib eval`).
    pub after_mm: f64,
    /// Rotation error after calibration, mrad, for full-pose data and models.
    pub after_mrad: Option<f64>,
    /// Position error of the nominal model, mm.
    pub before_mm: Option<f64>,
    /// Whether the row is within the angles every effect was fitted on.
    pub inside_coverage: bool,
}

/// An identified effect.
#[derive(Debug, Clone, Serialize)]
pub struct EffectView {
    /// Its name in reports (`gear_periodic:2:12`).
    pub label: String,
    /// Its parameters by name, as identified (scaled: the effect's size at a typical training row),
    /// each with its unit (`effects::reported_parameters`: a prismatic joint's in mm).
    pub parameters: Vec<(String, f64, &'static str)>,
    /// The joint error over the joint's angle, for an effect that is a function of one joint's
    /// angle (a gear series); `None` otherwise.
    pub curve: Option<EffectCurve>,
}

/// A joint error as a function of the joint's angle.
#[derive(Debug, Clone, Serialize)]
pub struct EffectCurve {
    /// 1-based joint.
    pub joint: usize,
    /// Angles, degrees.
    pub angle_deg: Vec<f64>,
    /// The joint error the model applies there, µrad.
    pub error_urad: Vec<f64>,
    /// The standard deviation of what it leaves uncorrected there, µrad: zero on the fitted
    /// angles, growing to the series' RMS where it has faded out.
    pub sigma_urad: Vec<f64>,
    /// The joint's angles in the training data, degrees (empty without `--train`).
    pub training_deg: Vec<f64>,
    /// The joint's angles in the test data, degrees.
    pub test_deg: Vec<f64>,
    /// The arcs inside which the series is fitted (inside the fitted range, out of its gaps), degrees.
    pub fitted_deg: Vec<[f64; 2]>,
}

/// The GP's length scales.
#[derive(Debug, Clone, Serialize)]
pub struct GpView {
    /// `exact` or `sparse`.
    pub kind: String,
    /// Input names (`q1` … `q6`, `payload`, then each measured signal's column name).
    pub inputs: Vec<String>,
    /// The standard deviation of each input over the training rows (rad, m, kg, or a signal's
    /// own unit): a length scale of 1 is this much.
    pub input_scale: Vec<f64>,
    /// One entry per kernel.
    pub kernels: Vec<KernelScales>,
    /// The measured signals among the inputs (`calib fit --inputs`), with their units and the
    /// spans they were fitted on (unit and span absent where the model file keeps none).
    pub signals: Vec<model::InputSpan>,
}

/// The length scales of one kernel.
#[derive(Debug, Clone, Serialize)]
pub struct KernelScales {
    /// The output columns it serves (0–2 position, 3–5 rotation).
    pub outputs: Vec<usize>,
    /// Its family.
    pub family: String,
    /// Per input, in input standard deviations; one value repeated for an isotropic kernel.
    pub length_scales: Vec<f64>,
    /// Whether one length scale serves every input.
    pub isotropic: bool,
}
