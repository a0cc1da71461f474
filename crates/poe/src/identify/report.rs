//! What an identification reports.

use super::Redundancy;

/// The errors after one iteration (index 0: before the first).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationRecord {
    /// RMS tool position error, metres.
    pub rms_position_m: f64,
    /// RMS orientation error, radians, over the full-pose rows.
    pub rms_rotation_rad: Option<f64>,
    /// Norm of the parameter update taken to reach this iteration.
    pub step_norm: f64,
}

/// How an identification went and what the data could and could not determine.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentificationReport {
    /// Errors per iteration, the initial model first.
    pub iterations: Vec<IterationRecord>,
    /// Whether the cost stopped decreasing before the iteration limit.
    pub converged: bool,
    /// Number of parameters the identification was allowed to change.
    pub free_parameters: usize,
    /// Rank of the weighted identification Jacobian: the number of identifiable parameters.
    pub rank: usize,
    /// Singular values of the weighted identification Jacobian at the solution, descending.
    pub singular_values: Vec<f64>,
    /// Ratio of the largest to the smallest singular value kept.
    pub condition_number: f64,
    /// The directions the data cannot determine, in words.
    pub unidentifiable: Vec<Redundancy>,
}

impl IdentificationReport {
    /// Number of iterations taken (not counting the initial evaluation).
    pub fn iteration_count(&self) -> usize {
        self.iterations.len().saturating_sub(1)
    }
}
