//! Rows of an evaluation far beyond the rest: a test row that every model misses by
//! ten times the spread of the others is more likely an error of the measurement than of the
//! model, and its error alone can set the evaluation's maximum. `eval` keeps every number as
//! measured and names such rows beside them, with the maximum and mean without them, so a user
//! sees both the worst row and what the model does on the others.
//!
//! The test is the one the fit applies to its training rows (`poe::identify::RobustOptions::
//! outlier_threshold` robust sigmas above the median), here on the evaluation's position errors,
//! and only among the rows on the model's firm ground (`EvalReport` passes those inside the
//! fitted range and the effects' coverage): outside it a large error is the model's own.

use crate::{ErrorSummary, PoseError};
use measurements::{Measurement, OutlierLine};
use serde::{Deserialize, Serialize};

/// Below this many rows the median and MAD of the errors say too little about their spread to
/// name a row as far beyond it (the same floor for every data set: 20 rows put the MAD's
/// standard error near a third of its value; Rousseeuw & Croux, JASA 1993, Table 1).
pub const MIN_ROWS: usize = 20;

/// The rows of an evaluation far beyond the others.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SuspectRows {
    /// The rows, by line, most sigmas first.
    pub rows: Vec<OutlierLine>,
    /// The threshold they are beyond, robust sigmas above the median position error.
    pub threshold_sigmas: f64,
    /// The statistics of every other row (judged or not).
    pub without: ErrorSummary,
}

fn median(sorted: &[f64]) -> f64 {
    let n = sorted.len();
    if n % 2 == 1 { sorted[n / 2] } else { 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]) }
}

/// Median and 1.4826 · MAD (the normal-consistent scale) of `values`.
fn robust_scale(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    let m = median(&v);
    let mut deviations: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
    deviations.sort_by(f64::total_cmp);
    (m, 1.4826 * median(&deviations))
}

/// The rows of `rows` (with their `errors`, in the same order) whose position error lies more
/// than `threshold_sigmas` robust sigmas above the median; `None` when there are none, fewer
/// than [`MIN_ROWS`] rows, or no spread to measure against.
pub fn suspect_rows(rows: &[Measurement], errors: &[PoseError], threshold_sigmas: f64) -> Option<SuspectRows> {
    let judged: Vec<usize> = (0..rows.len()).collect();
    suspects_among(rows, errors, &judged, threshold_sigmas)
}

/// [`suspect_rows`] judged among the rows `judged` (indices into `rows` and `errors`); the
/// statistics without them are of every other row of `errors`.
pub(crate) fn suspects_among(
    rows: &[Measurement],
    errors: &[PoseError],
    judged: &[usize],
    threshold_sigmas: f64,
) -> Option<SuspectRows> {
    if judged.len() < MIN_ROWS || rows.len() != errors.len() {
        return None;
    }
    let (median, sigma) = robust_scale(judged.iter().map(|&i| errors[i].position_mm));
    if !(sigma.is_finite() && sigma > 0.0) {
        return None;
    }
    let rotation = judged
        .iter()
        .map(|&i| errors[i].rotation_mrad)
        .collect::<Option<Vec<f64>>>()
        .map(|angles| robust_scale(angles.into_iter()))
        .filter(|(_, s)| *s > 0.0);
    let sigmas = |e: &PoseError| (e.position_mm - median) / sigma;
    let named: Vec<usize> = judged.iter().copied().filter(|&i| sigmas(&errors[i]) > threshold_sigmas).collect();
    if named.is_empty() {
        return None;
    }
    let mut lines: Vec<OutlierLine> = named
        .iter()
        .map(|&i| {
            OutlierLine::new(
                rows[i].line,
                errors[i].position_mm,
                sigmas(&errors[i]),
                errors[i].rotation_mrad,
                errors[i].rotation_mrad.zip(rotation).map(|(a, (m, s))| (a - m) / s),
            )
        })
        .collect();
    lines.sort_by(|a, b| b.position_sigmas.total_cmp(&a.position_sigmas));
    let others: Vec<PoseError> =
        errors.iter().enumerate().filter(|(i, _)| !named.contains(i)).map(|(_, e)| *e).collect();
    Some(SuspectRows { rows: lines, threshold_sigmas, without: ErrorSummary::from_errors(&others) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(n: usize) -> Vec<Measurement> {
        (0..n)
            .map(|i| Measurement { line: i as u64 + 2, ..Measurement::at(vec![0.0; 6], lie::Vector3::zeros()) })
            .collect()
    }

    fn errors(values: &[f64]) -> Vec<PoseError> {
        values.iter().map(|&p| PoseError { position_mm: p, rotation_mrad: None }).collect()
    }

    #[test]
    fn a_row_far_beyond_the_others_is_named_and_the_others_summarised_without_it() {
        // 40 rows spread 0.1 … 0.49 mm, one at 2.3 mm (UR10 B's odd line 429 under `poe-gp`).
        let mut values: Vec<f64> = (0..40).map(|i| 0.1 + 0.01 * f64::from(i)).collect();
        values.push(2.3);
        let found = suspect_rows(&rows(values.len()), &errors(&values), 10.0).expect("one row named");
        assert_eq!(found.rows.len(), 1);
        assert_eq!(found.rows[0].line, 42);
        assert!(found.rows[0].position_sigmas > 10.0);
        assert_eq!(found.without.n, 40);
        assert!((found.without.max_position_error_mm - 0.49).abs() < 1e-12);
    }

    #[test]
    fn a_wide_but_continuous_spread_names_nothing_and_few_rows_are_not_judged() {
        // Errors growing steadily (a model worse in one region) are not glitches.
        let values: Vec<f64> = (0..60).map(|i| 0.1 * 1.05_f64.powi(i)).collect();
        assert_eq!(suspect_rows(&rows(values.len()), &errors(&values), 10.0), None);
        let few = [0.1, 0.1, 0.1, 5.0];
        assert_eq!(suspect_rows(&rows(4), &errors(&few), 10.0), None);
    }
}
