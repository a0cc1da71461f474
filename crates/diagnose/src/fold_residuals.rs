//! The cross-validation fold by fold, for a stage fitted on top of the selected effects: in each
//! fold, the residual that the fold's fit leaves on every row, its training rows' (what a stage
//! on top, the fit's GP, learns from) and its held-out rows' (what that stage must predict). The
//! fit's `--effects auto` conditions its GP on each fold's training residuals, the GP's
//! hyperparameters held fixed, and reports the held-out error after it.

use super::pool::Pool;
use errors::Error;
use lie::Vector6;
use measurements::Measurement;

/// One fold: the rows it holds out and the residual the fit of the other rows leaves on every row.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FoldResiduals {
    /// The held-out rows (indices into [`HeldoutFolds::rows`]).
    pub held_out: Vec<usize>,
    /// The residual (position m, then orientation rad for full-pose data) that the fit of the other
    /// rows leaves at every row: at the held-out rows its prediction error, at the others what a
    /// stage fitted on top learns from. For the arcs, blended toward the geometry where the fitted
    /// model fades its series, as [`crate::ArcCheck::after_mm`] is.
    pub residuals: Vec<Vector6>,
    /// For the arcs: the residual the geometry fitted alone on the other rows leaves on every
    /// row, and each row's weight of the effects (the rest is the geometry alone's): where the
    /// model fades its series, its GP blends to a GP of what the geometry alone leaves
    /// (`model::ResidualGp::fallback`), which learns from these. Empty for the random folds,
    /// whose rows the series cover.
    pub alone: Vec<(Vector6, f64)>,
}

/// The folds behind `heldout_after_selected_mm` (random) and `off_poses_after_mm` (arcs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HeldoutFolds {
    /// The rows the folds index: the diagnosis's data, gross outliers left out.
    pub rows: Vec<Measurement>,
    /// The random folds, with every selected effect at its fold's order.
    pub random: Vec<FoldResiduals>,
    /// Per moving joint (1-based), its arcs held out one at a time.
    pub arcs: Vec<(usize, Vec<FoldResiduals>)>,
}

/// The random folds of `pool` with the columns `fold_columns[f]` fitted without fold `f`.
pub(crate) fn random_folds(pool: &Pool, fold_columns: &[Vec<usize>]) -> Result<Vec<FoldResiduals>, Error> {
    let mut out = Vec::with_capacity(pool.folds());
    for (f, columns) in fold_columns.iter().enumerate() {
        let beta = pool.solve(&[f], columns)?;
        let mut residuals = vec![Vector6::zeros(); pool.poses()];
        for g in 0..pool.folds() {
            let fitted = pool.residuals(g, columns, std::slice::from_ref(&beta));
            for (&i, r) in pool.fold_poses(g).iter().zip(&fitted[0]) {
                residuals[i] = *r;
            }
        }
        out.push(FoldResiduals { held_out: pool.fold_poses(f).to_vec(), residuals, alone: Vec::new() });
    }
    Ok(out)
}
