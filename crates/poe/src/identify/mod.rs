//! Identification of the local POE parameters from measurements (paper Section III-A-2).

mod correction;
mod levenberg;
mod normal;
mod options;
mod prior;
mod problem;
mod reduced;
mod redundancy;
mod registration;
mod report;
mod residual;
mod robust;
mod solver;
mod stated_noise;
mod termination;

pub use correction::PoseCorrection;
pub use options::{IdentificationOptions, Observation, ParameterMask, Solver, Target};
pub use prior::KinematicPrior;
pub use redundancy::Redundancy;
pub use registration::{kabsch, nearest_rotation, register};
pub use report::{DampingFallback, IdentificationReport, IterationRecord};
pub use residual::ResidualStats;
pub use robust::{KindScale, Loss, OutlierRow, RobustOptions, RobustReport, huber_loss, huber_weight, median};
pub use solver::{Identification, identify, identify_with_correction, identify_with_prior, posterior_covariance};
pub use stated_noise::{StatedNoise, StatedNoiseReport, StatedSigma};
pub use termination::Termination;

use crate::{Error, LocalPoe};

/// Which parameters a calibration identifies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// Only the base placement and the tools (12 parameters per tool pair, 9 with position-only
    /// data): the paper's base-tool baseline.
    BaseTool,
    /// Every local transform: the paper's POE calibration.
    Full,
}

/// Calibrates a nominal model from measurements with no initial guess: closed-form registration
/// of the measurement frame and tool offsets, a base-tool identification, then (for
/// [`Scope::Full`]) the full local POE identification. The report is the last stage's.
pub fn calibrate(
    nominal: &LocalPoe,
    observations: &[Observation],
    scope: Scope,
    options: &IdentificationOptions,
) -> Result<Identification, Error> {
    calibrate_placed(nominal, observations, scope, options).map(|(_, fit)| fit)
}

/// [`calibrate`], also returning the base-tool stage's model: the nominal model at its best base
/// and tool placement, the fair "before" of a calibration (the closed-form registration that
/// starts it can be far off where the flange orientations vary little).
pub fn calibrate_placed(
    nominal: &LocalPoe,
    observations: &[Observation],
    scope: Scope,
    options: &IdentificationOptions,
) -> Result<(LocalPoe, Identification), Error> {
    let registered = register(nominal, observations)?;
    let base_tool_mask = ParameterMask::base_tool(registered.layout());
    let base_tool = identify(&registered, observations, &base_tool_mask, options)?;
    let placed = base_tool.model.clone();
    let fit = match scope {
        Scope::BaseTool => base_tool,
        Scope::Full => {
            let mask = ParameterMask::all(base_tool.model.layout());
            identify(&base_tool.model, observations, &mask, options)?
        }
    };
    Ok((placed, fit))
}

/// [`calibrate_placed`] with the full identification under a prior about the base-tool stage's
/// model (the nominal geometry at its fitted base and tool placement): `prior` gives the
/// standard deviations of the links' local transforms, translation in metres and rotation in
/// radians ([`KinematicPrior::on_links`]); `None` is [`calibrate_placed`]. The base-tool stage
/// itself is fitted without the prior.
pub fn calibrate_placed_with_prior(
    nominal: &LocalPoe,
    observations: &[Observation],
    scope: Scope,
    prior: Option<(f64, f64)>,
    options: &IdentificationOptions,
) -> Result<(LocalPoe, Identification), Error> {
    let Some((translation_m, rotation_rad)) = prior.filter(|_| scope == Scope::Full) else {
        return calibrate_placed(nominal, observations, scope, options);
    };
    let registered = register(nominal, observations)?;
    let base_tool_mask = ParameterMask::base_tool(registered.layout());
    let base_tool = identify(&registered, observations, &base_tool_mask, options)?;
    let placed = base_tool.model.clone();
    let prior = KinematicPrior::on_links(placed.clone(), translation_m, rotation_rad);
    let mask = ParameterMask::all(placed.layout());
    let fit = identify_with_prior(&placed, observations, &mask, None, Some(&prior), options)?;
    Ok((placed, fit))
}

/// Error statistics of a model on observations (no identification).
pub fn evaluate(model: &LocalPoe, observations: &[Observation]) -> Result<ResidualStats, Error> {
    let weights = residual::Weights::default();
    residual::residuals(model, observations, None, weights, &IdentificationOptions::default()).map(|(_, s)| s)
}
