//! The weighted least-squares problem both solvers iterate on (`solver.rs` with the paper's
//! pseudo-inverse, `levenberg.rs` with damping and a prior), its state, and what a solver returns.

use super::correction::{Corrected, PoseCorrection};
use super::prior::KinematicPrior;
use super::reduced::Reduced;
use super::residual::{ResidualStats, linearise_reduced, residuals};
use super::{DampingFallback, IdentificationOptions, IterationRecord, Observation, Termination};
use crate::{Error, LocalPoe};

pub(super) fn cost(y: &[f64]) -> f64 {
    y.iter().map(|v| v * v).sum()
}

/// The problem being solved: what is free, what is observed, how rows are weighted.
pub(super) struct Problem<'a> {
    pub observations: &'a [Observation],
    pub free: Vec<usize>,
    pub correction: Option<&'a dyn PoseCorrection>,
    pub options: &'a IdentificationOptions,
    /// The robust loss's weight of each observation's position and orientation rows (empty: 1).
    pub row_weights: Vec<[f64; 2]>,
    /// Each observation's stated noise relative to the options' sigmas, per residual component
    /// (module `stated_noise`; empty: 1).
    pub noise: Vec<[f64; 6]>,
    /// A prior on the kinematic parameters about its own centre (`prior.rs`); `None`: the
    /// options' prior about the start, if any.
    pub prior: Option<&'a KinematicPrior>,
}

/// A point of the parameter space: the model, the correction's θ, and the accumulated steps
/// (the deviation from the start, or from a [`KinematicPrior`]'s centre, that a prior penalises).
#[derive(Clone)]
pub(super) struct State {
    pub model: LocalPoe,
    pub theta: Vec<f64>,
    pub deviation: Vec<f64>,
}

impl Problem<'_> {
    pub(super) fn parameter_count(&self) -> usize {
        self.free.len() + self.correction.map_or(0, |c| c.parameter_count())
    }

    pub(super) fn corrected<'b>(&'b self, theta: &'b [f64]) -> Option<Corrected<'b>> {
        self.correction.map(|correction| Corrected { correction, theta })
    }

    /// The state after a step of every parameter (free kinematic ones first).
    pub(super) fn step(&self, state: &State, step: &[f64]) -> State {
        let layout = state.model.layout();
        let mut full = vec![0.0; layout.len()];
        for (&index, &value) in self.free.iter().zip(step) {
            full[index] = value;
        }
        let mut model = state.model.clone();
        model.apply_update(&full);
        let theta = state.theta.iter().zip(&step[self.free.len()..]).map(|(t, s)| t + s).collect();
        let deviation = state.deviation.iter().zip(step).map(|(d, s)| d + s).collect();
        State { model, theta, deviation }
    }

    /// The weighted residual of a state and its errors.
    pub(super) fn residuals(&self, state: &State) -> Result<(Vec<f64>, ResidualStats), Error> {
        let weights = super::residual::Weights { robust: &self.row_weights, noise: &self.noise };
        residuals(&state.model, self.observations, self.corrected(&state.theta), weights, self.options)
    }

    /// The weighted Jacobian (free columns, then the correction's) and residual, reduced to their
    /// QR triangle, and the errors.
    pub(super) fn linearise(&self, state: &State) -> Result<(Reduced, ResidualStats), Error> {
        linearise_reduced(
            &state.model,
            self.observations,
            &self.free,
            self.corrected(&state.theta),
            super::residual::Weights { robust: &self.row_weights, noise: &self.noise },
            self.options,
        )
    }
}

pub(super) fn record(stats: ResidualStats, step_norm: f64, cost: f64) -> IterationRecord {
    IterationRecord { rms_position_m: stats.rms_position_m, rms_rotation_rad: stats.rms_rotation_rad, step_norm, cost }
}

/// What a solver returns to [`identify_with_correction`].
pub(super) struct Solved {
    pub state: State,
    /// The last linearisation, reduced.
    pub a: Reduced,
    pub iterations: Vec<IterationRecord>,
    pub termination: Termination,
    pub final_cost: f64,
    pub gradient_cosine: f64,
    pub held_at_prior: Vec<usize>,
    /// Where the pseudo-inverse iteration handed over to damped steps, if it did.
    pub damping_fallback: Option<DampingFallback>,
}
