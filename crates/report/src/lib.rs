//! The calibration report: typed data in ([`Report`], gathered by [`Report::build`]
//! from a calibrated model, its robot and measurements), one self-contained HTML page out
//! ([`render_html`]: inline CSS and SVG, no script, readable offline and printable). The
//! diagnosis's figures and report folder ([`diagnosis_figures`], [`write_diagnosis_report`]) are
//! drawn by the same writer, so `calib report` and `calib diagnose --report` cannot drift apart.
//!
//! The after-calibration numbers are `calib eval --json`'s own: [`model::evaluate`] and
//! [`model::EvalReport`], embedded in the page as they serialise. Charts are drawn with
//! `plotters`' SVG backend. Errors are `errors::Error`, as in every calibration crate: a chart that
//! cannot be drawn is `errors::ErrorKind::Plot`.
//!
//! ```
//! use campaign::{Perturbation, joint_ranges, paper_effects, simulate, simulated_cell};
//! use model::Method;
//! use pipeline::FitOptions;
//! use robot::RobotDescription;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let robot = RobotDescription::read(std::path::Path::new(concat!(
//!     env!("CARGO_MANIFEST_DIR"),
//!     "/../../fixtures/robots/irb4400.ron"
//! )))?;
//! let cell = simulated_cell(&robot, &Perturbation::default(), 1)?;
//! let config = |seed| loadsim::GeneratorConfig { sample_count: 60, seed, ..Default::default() };
//! let train = simulate(&cell, &paper_effects(), &joint_ranges(&robot), &config(1), false)?;
//! let test = simulate(&cell, &paper_effects(), &joint_ranges(&robot), &config(2), false)?;
//! let (model, _) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default())?;
//! let inputs = report::ReportInputs {
//!     model: &model,
//!     model_file: "model.ron",
//!     robot: &robot,
//!     robot_file: "irb4400.ron",
//!     data: &test,
//!     training: Some(&train),
//! };
//! let report = report::Report::build(&inputs, None, &report::ReportOptions::default())?;
//! let html = report::render_html(&report)?;
//! assert!(html.starts_with("<!DOCTYPE html>") && html.contains(r#"<section id="iso9283">"#));
//! # Ok(())
//! # }
//! ```
#![deny(missing_docs)]

mod build;
mod content;
mod diagnosis;
mod figures;
mod folder;
mod html;
mod iso9283;

pub use build::{ReportInputs, ReportOptions};
pub use content::{
    BeforeCalibration, DataSummary, EffectCurve, EffectView, ErrorStats, GpView, GroupedErrors, JointSummary,
    KernelScales, ModelSummary, Report, RobotSummary, RowError,
};
pub use diagnosis::diagnosis_figures;
pub use folder::write_diagnosis_report;
pub use html::{SECTIONS, render_html};
pub use iso9283::{Iso9283, RepeatOptions};
