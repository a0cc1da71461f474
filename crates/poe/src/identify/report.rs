//! What an identification reports.

use super::{Redundancy, RobustReport, Termination};
use serde::Serialize;

/// The errors after one iteration (index 0: before the first).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IterationRecord {
    /// RMS tool position error, metres.
    pub rms_position_m: f64,
    /// RMS orientation error, radians, over the full-pose rows.
    pub rms_rotation_rad: Option<f64>,
    /// Norm of the parameter update taken to reach this iteration.
    pub step_norm: f64,
    /// The weighted cost (squared residual in noise units, plus the prior's term where there is
    /// one) after this iteration.
    pub cost: f64,
}

/// How an identification went and what the data could and could not determine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IdentificationReport {
    /// Errors per iteration, the initial model first.
    pub iterations: Vec<IterationRecord>,
    /// Whether a convergence criterion was met ([`Termination::converged`]).
    pub converged: bool,
    /// Why the iterations ended.
    pub termination: Termination,
    /// The weighted cost at the end.
    pub final_cost: f64,
    /// `max_j |a_jᵀ y| / (‖a_j‖ ‖y‖)` at the end: 0 at an exact stationary point.
    pub gradient_cosine: f64,
    /// Number of parameters the identification was allowed to change.
    pub free_parameters: usize,
    /// Number of residual rows.
    pub residual_rows: usize,
    /// Rank of the weighted identification Jacobian: the number of identifiable parameters.
    pub rank: usize,
    /// Singular values of the weighted identification Jacobian at the solution, descending.
    pub singular_values: Vec<f64>,
    /// Ratio of the largest to the smallest singular value kept.
    pub condition_number: f64,
    /// The directions the data cannot determine, in words (serialised as their sentences).
    #[serde(serialize_with = "sentences")]
    pub unidentifiable: Vec<Redundancy>,
    /// Correction parameters (indices into the correction's θ) that the data barely determines:
    /// their posterior standard deviation is more than half their prior's, so the prior holds
    /// them near their start (Levenberg–Marquardt with a prior only).
    pub held_at_prior: Vec<usize>,
    /// The pseudo-inverse solver only: where no step along its direction lowered the cost and
    /// Levenberg–Marquardt steps (without a prior) took over; `None` when they never did.
    pub damping_fallback: Option<DampingFallback>,
    /// What the robust loss did: the residuals' robust scales, the rows down-weighted, and the
    /// gross outliers named (left out under the Huber loss).
    pub robust: RobustReport,
    /// How the observations' stated σ weighted them (module `stated_noise`); `None` where none
    /// states one, or weighting is off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stated_noise: Option<super::StatedNoiseReport>,
}

/// Where the pseudo-inverse Gauss–Newton iteration handed over to damped steps.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DampingFallback {
    /// Gauss–Newton iterations accepted before the hand-over; the later ones are damped.
    pub after_iteration: usize,
    /// `max_j |a_jᵀ y| / (‖a_j‖ ‖y‖)` where the Gauss–Newton direction lowered nothing.
    pub gradient_cosine: f64,
}

impl std::fmt::Display for DampingFallback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "no step along the Gauss–Newton direction lowered the cost after iteration {} (gradient cosine {:.1e}): \
             Levenberg–Marquardt damping continued from there",
            self.after_iteration, self.gradient_cosine
        )
    }
}

impl IdentificationReport {
    /// Number of iterations taken (not counting the initial evaluation).
    pub fn iteration_count(&self) -> usize {
        self.iterations.len().saturating_sub(1)
    }

    /// Residual rows per identifiable parameter: below about 3 a fit follows the noise.
    pub fn redundancy(&self) -> f64 {
        self.residual_rows as f64 / self.rank.max(1) as f64
    }
}

fn sentences<S: serde::Serializer>(redundancies: &[Redundancy], serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(redundancies.iter().map(ToString::to_string))
}
