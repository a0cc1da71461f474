//! The two-step calibration of the paper (Jing, Tao, Yang, Shimada): geometric identification of a
//! local POE model with the selected non-geometric effects, then a Gaussian process on the
//! remaining pose error; `--effects auto` chooses the effects through the diagnosis.
//!
//! The crate holds the fit ([`fit()`], [`FitOptions`], [`FitReport`]), the plausibility checks
//! that run before it ([`PlausibilityOptions`]), the prior toward the nominal geometry
//! ([`choose_prior`], [`NominalPriorOptions`]), `--effects auto` ([`choose_effects`],
//! [`effects_of`]; with a GP, its held-out prediction with the GP on top, [`PredictedWithGp`]) and the measuring sessions that choose what a drift or a thermal growth is
//! beyond the span it was fitted on ([`sessions()`], [`SessionOptions`], [`SpanChoice`]), and the
//! payload groups that choose what a compliance or a link deflection is beyond the payloads it
//! was fitted on ([`payload_groups`], [`PayloadOptions`], [`PayloadChoice`]). Every other item is named by the crate that owns it, not re-exported here:
//! `errors` (the one `Error`), `robot` (`RobotDescription`), `measurements` (the CSV,
//! `MeasurementSet`, `OutputFile`), `model` (`CalibratedModel`, `Method`, `evaluate`, the model
//! file), `effects`, `diagnose`, `campaign` (simulated data) and `cell` (inverse, `compensate`,
//! URDF export, `register`, `plan`). There is no prelude: a type has one path, and a dependent's
//! `Cargo.toml` lists the crates it uses.
//!
//! ```
//! use campaign::{Perturbation, joint_ranges, paper_effects, simulate, simulated_cell};
//! use model::Method;
//! use pipeline::FitOptions;
//!
//! # fn main() -> Result<(), errors::Error> {
//! let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots");
//! let robot = robot::RobotDescription::read(&fixtures.join("irb4400.ron"))?;
//! let cell = simulated_cell(&robot, &Perturbation::default(), 1)?;
//! let config = loadsim::GeneratorConfig { sample_count: 60, seed: 1, ..Default::default() };
//! let data = simulate(&cell, &paper_effects(), &joint_ranges(&robot), &config, false)?;
//! let (model, report) = pipeline::fit(&robot, &data, Method::Poe, &FitOptions::default())?;
//! assert_eq!(model.method, Method::Poe);
//! assert!(model::evaluate(&model, &model.bind(&data)?)?.summary.mean_position_error_mm < 1.0, "{report:?}");
//! # Ok(())
//! # }
//! ```
#![deny(missing_docs)]

mod auto;
mod clusters;
mod error_kind;
mod fit;
mod fit_options;
mod fit_prior;
mod gp_folds;
mod payloads;
mod plausibility;
mod rule_choice;
mod sessions;

pub use auto::{AutoChoice, choose as choose_effects, effects_of};
pub use clusters::{BranchJoint, Cluster, HeightSplit};
pub use error_kind::ErrorKind;
pub use fit::{FitReport, FitWarning, fit};
pub use fit_options::{EffectOptions, FitOptions};
pub use fit_options::{PayloadOptions, SessionOptions};
pub use fit_prior::{NominalPriorOptions, PriorCandidate, PriorChoice, choose as choose_prior};
pub use gp_folds::{ArcWithGp, FallbackGpChoice, PredictedWithGp};
pub use payloads::{PayloadChoice, PayloadErrors, payload_groups};
pub use plausibility::{PlausibilityOptions, PlausibilityReport};
pub use sessions::{SpanChoice, SpanErrors, sessions};
