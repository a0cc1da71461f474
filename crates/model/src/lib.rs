//! The calibrated model: its parts in order (base, POE geometry, effects, residual GP), the prediction
//! with its coverage (training range, joint limits), the model file (RON) with its checks, and the
//! evaluation of a model on measurements.
//!
//! ```
//! # let fixture = |name: &str| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name);
//! let robot = robot::RobotDescription::read(&fixture("irb4400.ron"))?;
//! let config = campaign::GeneratorConfig { sample_count: 60, seed: 1, ..Default::default() };
//! let (_, data) = campaign::simulate_campaign(
//!     &robot, &campaign::Effects::default(), &campaign::Perturbation::default(), &campaign::Remount::default(), &config, true,
//! )?;
//! let fit = model::geometric::fit_geometry(&robot.nominal_model()?, &data, poe::identify::Scope::Full, &Default::default())?;
//! let model = model::CalibratedModel {
//!     schema_version: model::SCHEMA_VERSION,
//!     robot: robot.name.clone(),
//!     method: model::Method::Poe,
//!     full_pose: true,
//!     tools: data.tools.clone(),
//!     kinematics: fit.model,
//!     effects: Vec::new(),
//!     fallback_kinematics: None,
//!     effect_uncertainty: None,
//!     geometry_uncertainty: None,
//!     residual_gp: None,
//!     training_range: None,
//!     joint_limits: Vec::new(),
//!     heldout: None,
//!     fit_warnings: None,
//!     robot_description: Some(robot.clone()),
//! };
//! // The data bound to the model once (joints checked, tools mapped), then passed as one value.
//! let bound = model.bind(&data)?;
//! let evaluation = model::evaluate(&model, &bound)?;
//! assert!(evaluation.summary.mean_position_error_mm < 0.01); // no noise, no effect: the geometry is all
//! # Ok::<(), errors::Error>(())
//! ```
#![deny(missing_docs)]

mod calibrated;
mod effect_sigma;
mod error_kind;
mod eval_report;
mod evaluate;
pub mod geometric;
mod geometry_sigma;
mod heldout;
mod joint_limits;
mod method;
mod metrics;
mod model_check;
mod model_file;
mod model_parts;
mod other_placement;
mod predictions;
mod repeats;
mod residual_gp;
mod suspect_rows;
mod training_range;
mod unit_name;
mod wrap;
pub use error_kind::ErrorKind;
pub use evaluate::{Evaluation, evaluate};
pub use predictions::write_predictions;

pub use calibrated::{CalibratedModel, ExtrapolationWarning, GpFade, PredictedPose, SigmaFallback};
pub use effect_sigma::EffectUncertainty;
pub use eval_report::{CoverageSplit, EvalReport, ORIENTATIONS_NOT_EVALUATED};
pub use geometry_sigma::{GeometrySigma, GeometryUncertainty};
pub use heldout::{HeldoutEstimate, HeldoutSource};
pub use joint_limits::{BeyondLimitsWarning, beyond_limits, stored_limits};
pub use method::{Method, UnknownMethod};
pub use metrics::{ErrorSummary, PoseError, pose_error};
pub use model_file::{SCHEMA_VERSION, model_text, parse_model, read_model, write_model};
pub use model_parts::Part;
pub use other_placement::{OtherPlacement, OtherPlacementOptions};
pub use repeats::{HeldoutOptions, RepeatGroups};
pub use residual_gp::{
    GpChoice, GpFadeRule, GpFitReport, GpModel, ResidualFrame, ResidualGp, ResidualGpOptions, ResidualGpReport,
    ResidualSet, UnknownGpChoice, gp_weight,
};
pub use suspect_rows::{SuspectRows, suspect_rows};
pub use training_range::{InputSpan, OutOfRangeWarning, TrainingRange};
pub use wrap::{WrappedJoint, wrapped};
