//! Pose planning (`calib plan`): which of many candidate joint configurations to
//! measure, and in which order.
//!
//! [`plan()`] makes the identification of `poe`'s local POE model best determined: the
//! D-optimal (log det of the information of the column-scaled identification Jacobian, on the
//! directions the candidates can determine) or I-optimal (mean predicted variance of the tool
//! point) choice, greedy with rank-k updates of every candidate's predicted variance and Fedorov
//! exchanges (`design`); then exchanges that lower the expected held-out error of a
//! least-squares fit when the error the geometry cannot model is a Gaussian process over the
//! joints (`bias`, `bias_trial`); then every moving joint's range covered (`coverage`). The
//! report predicts the parameters' uncertainty and the error for the chosen count and a few
//! others, so the user sees when more poses stop paying. `unmodelled_setting` takes the
//! unmodelled error from a calibrated model's own held-out error (`calib plan --model`).
//!
//! Candidates come from a measurement-shaped CSV ([`file_candidates`]; other columns kept and
//! written back unchanged by [`write_chosen_rows`]) or are drawn within the robot file's joint
//! limits ([`generated_candidates`]). Every function returns `errors::Error`.
//!
//! ```
//! # let fixture = |name: &str| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name);
//! let robot = robot::RobotDescription::read(&fixture("irb4400.ron"))?;
//! // 400 configurations within the joint limits; choose 30 of them for a full-pose calibration.
//! let set = planning::generated_candidates(&robot, None, 400, 7)?;
//! let options = planning::PlanOptions { unmodelled_mm: 0.0, ..Default::default() };
//! let chosen = planning::plan(&set.model, &set.candidates, 30, true, &options)?;
//! assert_eq!(chosen.order.len(), 30);
//! // The predicted error shrinks as poses are added, and the chosen count is among the checkpoints.
//! let at_30 = chosen.report.checkpoints.iter().find(|c| c.poses == 30).expect("the chosen count");
//! assert!(at_30.chosen);
//! # Ok::<(), errors::Error>(())
//! ```
#![deny(missing_docs)]

mod bias;
mod bias_trial;
mod candidates;
mod coverage;
mod design;
mod information;
mod plan;
mod unmodelled_setting;

pub use candidates::{CandidateSet, file_candidates, generated_candidates, write_chosen_rows, write_generated_rows};
pub use coverage::AxisCoverage;
pub use design::Criterion;
pub use information::Candidate;
pub use plan::{Checkpoint, Plan, PlanOptions, PlanReport, measuring_order, plan};
pub use unmodelled_setting::{UnmodelledFrom, UnmodelledGiven, UnmodelledSetting, per_axis_from_mean};
