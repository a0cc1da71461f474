//! The two-step calibration of the paper (Jing, Tao, Yang, Shimada): geometric identification of a
//! local POE model with the selected non-geometric effects, then a Gaussian process on the
//! remaining pose error; `--effects auto` chooses the effects through the diagnosis.
//!
//! `pipeline` is also the one crate a downstream user (the `calib` binary, xtask) needs: it
//! re-exports the public API of the crates it joins, so `pipeline::X` names every type of the SPEC.
#![deny(missing_docs)]

mod auto;
mod clusters;
mod fit;
mod fit_options;
mod fit_prior;
mod plausibility;

pub use clusters::{BranchJoint, Cluster, HeightSplit};
pub use fit::{FitReport, FitWarning, fit};
pub use fit_options::{EffectOptions, FitOptions};
pub use fit_prior::{NominalPriorOptions, PriorCandidate, PriorChoice, choose as choose_prior};
pub use plausibility::{PlausibilityOptions, PlausibilityReport};

pub use cell::*;
pub use errors::{ColumnMapFault, DecimalFault, EffectListFault, Error, ErrorKind, FileKind, Place};
pub use measurements::*;
pub use model::*;
pub use robot::*;

pub use ::diagnose;
/// The non-geometric effects (the `effects` crate), and the choice `--effects auto` makes of them.
pub mod effects {
    pub use crate::auto::{AutoChoice, choose, effects_of};
    pub use ::effects::*;
}
pub use campaign as simulated;
pub use diagnose::chart;
pub use model::geometric;
