//! The calibrated model: its parts in order (base, POE geometry, effects, residual GP), the prediction
//! with its coverage (training range, joint limits), the model file (RON) with its checks, and the
//! evaluation of a model on measurements.
#![deny(missing_docs)]

mod calibrated;
mod compensation;
mod eval_report;
mod evaluate;
pub mod geometric;
mod joint_limits;
mod method;
mod metrics;
mod model_check;
mod model_file;
mod model_parts;
mod training_range;
pub use evaluate::{Evaluation, evaluate, tool_indices};

pub use calibrated::{CalibratedModel, ExtrapolationWarning, PredictedPose, pose_error};
pub use compensation::{
    Compensation, CompensationOptions, CompensationReport, GpChoice, GpFitReport, GpModel, ResidualFrame, ResidualSet,
    UnknownGpChoice,
};
pub use eval_report::{CoverageSplit, EvalReport, ORIENTATIONS_NOT_EVALUATED};
pub use joint_limits::{BeyondLimitsWarning, beyond_limits, stored_limits};
pub use method::{Method, UnknownMethod};
pub use metrics::{ErrorSummary, PoseError};
pub use model_file::{SCHEMA_VERSION, model_text, parse_model, read_model, write_model};
pub use model_parts::Part;
pub use training_range::{OutOfRangeWarning, TrainingRange};
