//! The robot cell after a calibration (issue 26): carry a calibrated model to a moved tracker or
//! a new tool from a few measured poses (`calib register`), and choose the poses worth measuring
//! (`calib plan`).
//!
//! **Registration** ([`register()`]): the calibrated model predicts every pose in the frame it was
//! fitted in, all its parts applied; a new tracker frame `X` and tool changes `D_t` are fitted so
//! that the measured poses are `X · P_i · D_t` (closed-form start, then Levenberg–Marquardt), and
//! put into the model exactly (geometry, effects and GP carried along). The residual on the poses
//! is judged against the model's held-out error.
//!
//! **Planning** ([`plan()`]): D-optimal choice of poses for the identification (log det of the
//! information of the column-scaled identification Jacobian of `poe`, on the directions it can
//! determine), greedy with rank-k updates of every candidate's predicted variance and Fedorov
//! exchanges, then every moving joint's range covered, in the order to measure them.
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

mod candidates;
mod coverage;
mod design;
mod error;
mod information;
mod model_text;
mod plan;
mod register;
pub mod registration;
mod report;

pub use candidates::{CandidateSet, file_candidates, generated_candidates, write_chosen_rows, write_generated_rows};
pub use coverage::AxisCoverage;
pub use design::Criterion;
pub use error::Error;
pub use information::Candidate;
pub use model_text::checked_model_text;
pub use plan::{Checkpoint, Plan, PlanOptions, PlanReport, measuring_order, plan};
pub use register::{Refit, RegisterOptions, Registered, register};
pub use report::{FrameChange, RegisterReport, RegisterWarning, RegisteredTool, Verdict};
