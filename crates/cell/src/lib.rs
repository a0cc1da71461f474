//! The robot-cell side: poses to joint targets through a calibrated model (inverse kinematics), a
//! program's targets rewritten so the calibrated robot reaches them (`compensate`), and the model's
//! geometry exported as a URDF.
//!
//! Every function returns `errors::Error`, the one error of the calibration crates (its message
//! names the file, line and column where there is one); the refusals only registration
//! raises are kinds of it (`errors::ErrorKind::TooFewPoses`, `PosesUndetermined`, …).
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
//!     robot_description: None,
//! };
//! // Joint values that reach five poses the model predicts, from seeds 0.02 rad off.
//! let bound = model.bind(data.subset(&[0, 1, 2, 3, 4]))?;
//! let rows = bound.rows();
//! let predicted = model.predict(&bound)?;
//! let targets: Vec<cell::PoseTarget> = rows
//!     .iter()
//!     .zip(&predicted)
//!     .map(|(row, p)| cell::PoseTarget {
//!         seed: row.q.iter().map(|q| q + 0.02).collect(),
//!         pose: p.pose,
//!         orientation: true,
//!         payload_kg: 0.0,
//!         tool: 0,
//!         inputs: Default::default(),
//!     })
//!     .collect();
//! let solved = cell::solve_targets(&model, &targets, None, &cell::InverseOptions::default())?;
//! assert!(solved.iter().all(|s| s.residual_m < 1e-6));
//! # Ok::<(), errors::Error>(())
//! ```
//!
//! Re-registration: carry a calibrated model to a moved tracker or a new tool from a
//! few measured poses (`calib register`). Choosing the poses worth measuring (`calib plan`) is
//! the crate `planning`.
//!
//! **Registration** ([`register()`]): the calibrated model predicts every pose in the frame it was
//! fitted in, all its parts applied; a new tracker frame `X` and tool changes `D_t` are fitted so
//! that the measured poses are `X · P_i · D_t` (closed-form start, then Levenberg–Marquardt), and
//! put into the model exactly (geometry, effects and GP carried along). The residual on the poses
//! is judged against the model's held-out error.

//!
//! ```
//! use cell::registration::{register_rows, RegistrationOptions, RegistrationRow, Unknowns};
//! use lie::{SE3, SO3, Vector3};
//!
//! // The tracker moved by `moved`: four predicted poses and where it now sees them.
//! let moved = SE3::new(SO3::exp(&Vector3::new(0.0, 0.0, 1.0)), Vector3::new(3.6, 0.0, 0.0));
//! let rows: Vec<RegistrationRow> = [[0.5, 0.0, 1.0], [0.0, 0.7, 0.8], [-0.4, 0.1, 1.2], [0.2, -0.6, 0.5]]
//!     .iter()
//!     .map(|&[x, y, z]| {
//!         let predicted = SE3::from_translation(Vector3::new(x, y, z));
//!         RegistrationRow { predicted, point: (moved * predicted).translation(), rotation: None, slot: None }
//!     })
//!     .collect();
//! let unknowns = Unknowns { frame: true, tools: 0, tool_rotations: false };
//! let fit = register_rows(&rows, unknowns, &RegistrationOptions::default()).unwrap();
//! assert!((fit.frame * moved.inverse()).log().to_vector().norm() < 1e-9);
//! ```
#![deny(missing_docs)]

mod inverse;
mod joint_targets;
mod model_text;
mod register;
mod register_options;
pub mod registration;
mod report;
mod urdf_export;
mod urdf_like;
mod urdf_text;

pub use inverse::{InverseOptions, PoseTarget, Solved, TargetStatus, solve_targets};
pub use joint_targets::{
    CompensateOptions, CompensationSummary, RegisteredNominal, TargetFile, TargetFrame, compensate, pose_targets,
    read_targets, registered_nominal, write_compensated,
};
/// Moved to `model` (shared with `calib eval` and `predict`); re-exported where it was.
pub use model::{WrappedJoint, wrapped};
pub use model_text::checked_model_text;
pub use register::{Registered, register};
pub use register_options::{Refit, RegisterOptions};
pub use report::{FrameChange, HeldoutFrom, RegisterReport, RegisterWarning, RegisteredTool, Verdict};
pub use urdf_export::{
    AxisChange, PartError, TrainingErrors, UrdfExport, UrdfExportReport, UrdfTemplate, export_urdf, write_urdf,
};
