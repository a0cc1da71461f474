//! The robot-cell side: poses to joint targets through a calibrated model (inverse kinematics), a
//! program's targets rewritten so the calibrated robot reaches them (`compensate`), and the model's
//! geometry exported as a URDF.
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
//!     residual_gp: None,
//!     training_range: None,
//!     joint_limits: Vec::new(),
//! };
//! // Joint values that reach five poses the model predicts, from seeds 0.02 rad off.
//! let rows = &data.rows[..5];
//! let predicted = model.predict(rows, &[0; 5])?;
//! let targets: Vec<cell::PoseTarget> = rows
//!     .iter()
//!     .zip(&predicted)
//!     .map(|(row, p)| cell::PoseTarget {
//!         seed: row.q.iter().map(|q| q + 0.02).collect(),
//!         pose: p.pose,
//!         orientation: true,
//!         payload_kg: 0.0,
//!         tool: 0,
//!     })
//!     .collect();
//! let solved = cell::solve_targets(&model, &targets, None, &cell::InverseOptions::default())?;
//! assert!(solved.iter().all(|s| s.residual_m < 1e-6));
//! # Ok::<(), errors::Error>(())
//! ```
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
