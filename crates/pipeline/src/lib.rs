//! The two-step calibration of the paper (Jing, Tao, Yang, Shimada): geometric identification of a
//! local POE model, then a Gaussian process on the remaining pose error. Also the readers and
//! writers of the files the SPEC fixes: the measurement CSV, the robot RON, the model RON.
//!
//! This is the only library crate that touches files, and only through functions that take a
//! path or a reader from the caller.
#![deny(missing_docs)]

mod base_frame;
mod calibrated;
pub mod chart;
mod compensation;
pub mod diagnose;
pub mod effects;
mod error;
mod eval_report;
mod fit;
mod fit_options;
pub mod geometric;
mod input_files;
mod inverse;
mod joint_limits;
mod joint_targets;
mod measurements;
mod method;
mod metrics;
mod model_check;
mod model_file;
mod model_parts;
mod outliers;
mod output_file;
mod plausibility;
mod robot;
mod robot_check;
mod robot_dh;
mod ron_position;
pub mod simulated;
mod training_range;
mod urdf_chain;
mod urdf_export;
mod urdf_like;
mod urdf_mimic;
mod xml_outline;

pub use base_frame::{NominalTolerance, axis_changes, check_nominal, in_base_frame, tracker_from_base};
pub use calibrated::{CalibratedModel, ExtrapolationWarning, PredictedPose, pose_error};
pub use compensation::{
    Compensation, CompensationOptions, CompensationReport, GpChoice, GpFitReport, GpModel, ResidualFrame, ResidualSet,
    UnknownGpChoice,
};
pub use error::Error;
pub use eval_report::{CoverageSplit, EvalReport, ORIENTATIONS_NOT_EVALUATED};
pub use fit::{Evaluation, FitReport, FitWarning, evaluate, fit, tool_indices};
pub use fit_options::{EffectOptions, FitOptions};
pub use input_files::InputFiles;
pub use inverse::{InverseOptions, PoseTarget, Solved, TargetStatus, solve_targets};
pub use joint_limits::{BeyondLimitsWarning, beyond_limits, stored_limits};
pub use joint_targets::{
    CompensateOptions, CompensationSummary, RegisteredNominal, TargetFile, TargetFrame, compensate, pose_targets,
    read_targets, registered_nominal, write_compensated,
};
pub use measurements::{
    Cells, ColumnMap, ColumnMapFault, CsvColumns, Decimal, DecimalFault, Delimiter, Dialect, FileFormat, JointColumn,
    Measurement, MeasurementSet, MeasurementWriter, ReadOptions, parse_measurements, read_configurations,
    read_configurations_with_cells, read_measurements,
};
pub use method::{Method, UnknownMethod};
pub use metrics::{ErrorSummary, PoseError};
pub use model_file::{SCHEMA_VERSION, parse_model, read_model, write_model};
pub use model_parts::Part;
pub use outliers::{OutlierLine, list_lines};
pub use output_file::{FileKind, MAX_SYMLINKS, OutputFile, output_target, write_file};
pub use plausibility::{PlausibilityOptions, PlausibilityReport};
pub use robot::{FlangeDescription, FoldedJoint, JointDescription, JointType, MimicStage, RobotDescription};
pub use robot_dh::{DhTable, DhTableRow};
pub use training_range::{OutOfRangeWarning, TrainingRange};
pub use urdf_chain::{ChainEnds, ChainStep, StepMotion, UrdfChain, UrdfDocument};
pub use urdf_export::{
    AxisChange, PartError, TrainingErrors, UrdfExport, UrdfExportReport, UrdfTemplate, export_urdf, write_urdf,
};
pub use urdf_mimic::{ChainJoint, StepMimic};
