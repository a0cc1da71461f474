//! The robot-cell side: poses to joint targets through a calibrated model (inverse kinematics), a
//! program's targets rewritten so the calibrated robot reaches them (`compensate`), and the model's
//! geometry exported as a URDF.
#![deny(missing_docs)]

mod inverse;
mod joint_targets;
mod urdf_export;
mod urdf_like;
mod urdf_text;

pub use inverse::{InverseOptions, PoseTarget, Solved, TargetStatus, solve_targets};
pub use joint_targets::{
    CompensateOptions, CompensationSummary, RegisteredNominal, TargetFile, TargetFrame, compensate, pose_targets,
    read_targets, registered_nominal, write_compensated,
};
pub use urdf_export::{
    AxisChange, PartError, TrainingErrors, UrdfExport, UrdfExportReport, UrdfTemplate, export_urdf, write_urdf,
};
