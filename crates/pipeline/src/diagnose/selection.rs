//! Greedy forward selection of effects by cross-validated held-out error, each step accepted only
//! when its gain is significant.

use super::candidates::Candidate;
use super::design::Design;
use super::statistics::{mean, normal_quantile, paired_t};
use lie::Vector6;
use rayon::prelude::*;

/// How a model of the residual did on held-out rows.
#[derive(Debug, Clone)]
pub(crate) struct CrossValidated {
    /// Held-out residual per pose: position (m), then orientation (rad) for full-pose data.
    pub residuals: Vec<Vector6>,
    /// Held-out position error per pose, m.
    pub errors: Vec<f64>,
    /// Number of extra (non-kinematic) parameters.
    pub parameters: usize,
}

impl CrossValidated {
    fn new(residuals: Vec<Vector6>, parameters: usize) -> Self {
        let errors = residuals.iter().map(|r| r.fixed_rows::<3>(0).norm()).collect();
        Self { residuals, errors, parameters }
    }

    /// Mean held-out position error, m.
    pub(crate) fn mean_error(&self) -> f64 {
        mean(&self.errors)
    }

    /// Mean squared held-out error inflated by `1 + 2p/m` (m residual rows, p extra parameters):
    /// between two explanations that cross-validate alike, the smaller one wins.
    fn penalised(&self, rows: usize) -> f64 {
        let mse = self.errors.iter().map(|e| e * e).sum::<f64>() / self.errors.len().max(1) as f64;
        mse * (1.0 + 2.0 * self.parameters as f64 / rows.max(1) as f64)
    }
}

/// Cross-validates the kinematics plus the columns of `chosen`.
pub(crate) fn cross_validate(
    design: &Design,
    candidates: &[Candidate],
    chosen: &[usize],
    folds: &[usize],
    fold_count: usize,
) -> CrossValidated {
    let columns: Vec<Vec<f64>> = chosen.iter().flat_map(|&c| candidates[c].columns.iter().cloned()).collect();
    let parameters = columns.len();
    CrossValidated::new(design.cross_validate(&columns, folds, fold_count), parameters)
}

/// One accepted step of the selection.
#[derive(Debug, Clone)]
pub(crate) struct Step {
    /// The candidate added.
    pub candidate: usize,
    /// Held-out result with it and every earlier step.
    pub result: CrossValidated,
    /// The paired t statistic of the gain over the previous step.
    pub t: f64,
}

/// What the selection found.
#[derive(Debug, Clone)]
pub(crate) struct Selection {
    /// Kinematics alone.
    pub baseline: CrossValidated,
    /// Every candidate alone on top of the kinematics, in candidate order.
    pub single: Vec<CrossValidated>,
    /// The accepted steps, in order.
    pub steps: Vec<Step>,
    /// The critical t value each step had to pass.
    pub critical_t: f64,
}

/// How strict the selection is.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SelectionOptions {
    /// Family-wise false-alarm rate of one step (Bonferroni over the candidates tried).
    pub significance: f64,
    /// A step must also lower the mean held-out error by at least this fraction.
    pub min_relative_gain: f64,
    /// At most this many effects are combined.
    pub max_effects: usize,
}

impl Default for SelectionOptions {
    fn default() -> Self {
        Self { significance: 0.01, min_relative_gain: 0.03, max_effects: 3 }
    }
}

/// Greedy forward selection: at each step every remaining candidate is cross-validated together
/// with those already chosen; the best by penalised held-out error is kept when its paired gain
/// over the current model is significant and large enough.
pub(crate) fn select(
    design: &Design,
    candidates: &[Candidate],
    folds: &[usize],
    fold_count: usize,
    options: &SelectionOptions,
) -> Selection {
    let rows = design.rows_per_pose * design.poses();
    let baseline = cross_validate(design, candidates, &[], folds, fold_count);
    let critical_t = normal_quantile(1.0 - options.significance / candidates.len().max(1) as f64);
    let mut chosen: Vec<usize> = Vec::new();
    let mut steps: Vec<Step> = Vec::new();
    let mut single = Vec::new();
    while chosen.len() < options.max_effects {
        let current = steps.last().map_or(&baseline, |s| &s.result).clone();
        let remaining: Vec<usize> = (0..candidates.len()).filter(|c| !chosen.contains(c)).collect();
        let results: Vec<CrossValidated> = remaining
            .par_iter()
            .map(|&c| {
                let mut with = chosen.clone();
                with.push(c);
                cross_validate(design, candidates, &with, folds, fold_count)
            })
            .collect();
        if chosen.is_empty() {
            single = results.clone();
        }
        let Some((best, result)) =
            remaining.iter().zip(results).min_by(|(_, a), (_, b)| a.penalised(rows).total_cmp(&b.penalised(rows)))
        else {
            break;
        };
        let current_sq: Vec<f64> = current.errors.iter().map(|e| e * e).collect();
        let new_sq: Vec<f64> = result.errors.iter().map(|e| e * e).collect();
        let t = paired_t(&current_sq, &new_sq);
        let gain = 1.0 - result.mean_error() / current.mean_error().max(f64::MIN_POSITIVE);
        if !(t > critical_t && gain >= options.min_relative_gain) {
            break;
        }
        chosen.push(*best);
        steps.push(Step { candidate: *best, result, t });
    }
    Selection { baseline, single, steps, critical_t }
}
