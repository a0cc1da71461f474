//! Greedy forward selection of effects by cross-validated held-out error, each step accepted only
//! when its gain is significant by a test that heavy tails cannot hide.
//!
//! A candidate is a *term*: pool columns, and for a periodic error of a joint's own angle a
//! Fourier series whose order is chosen by an inner cross-validation on each fold's training rows
//! alone (nested cross-validation; Varma & Simon, *BMC Bioinformatics* 7:91, 2006): the held-out
//! error of a series never saw the rows it is scored on, not even through its order.

use super::candidates::Effect;
use super::pool::Pool;
use super::statistics::{mean, median, normal_quantile, signed_rank_z};
use effects::IdentifiedEffect;
use errors::Error;
use lie::Vector6;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// A candidate as the selection sees it.
#[derive(Debug, Clone)]
pub(crate) struct Term {
    /// The effect.
    pub effect: Effect,
    /// 1-based joints.
    pub joints: Vec<usize>,
    /// Pool columns (of the version learnt on every row); for a series `cos q, sin q, cos 2q, …`.
    pub columns: Vec<usize>,
    /// Where the columns are learnt from the data (a backlash side), each fold's own version,
    /// learnt without its rows.
    pub per_fold: Option<Vec<Vec<usize>>>,
    /// For a Fourier series, the orders it may take (ascending).
    pub orders: Option<Vec<u32>>,
    /// The effect as the fit models it (for a learnt side, the side learnt on every row).
    pub model: IdentifiedEffect,
}

/// How a model of the residual did on held-out rows.
#[derive(Debug, Clone)]
pub(crate) struct CrossValidated {
    /// Held-out residual per pose: position (m), then orientation (rad) for full-pose data.
    pub residuals: Vec<Vector6>,
    /// Held-out position error per pose, m.
    pub errors: Vec<f64>,
    /// The columns each fold's fit used.
    pub fold_columns: Vec<Vec<usize>>,
}

impl Term {
    /// The columns fold `f`'s fit uses.
    pub(crate) fn columns_for(&self, f: usize) -> &[usize] {
        self.per_fold.as_ref().and_then(|p| p.get(f)).map_or(&self.columns, |c| c)
    }
}

impl CrossValidated {
    fn new(residuals: Vec<Vector6>, fold_columns: Vec<Vec<usize>>) -> Self {
        let errors = residuals.iter().map(|r| r.fixed_rows::<3>(0).norm()).collect();
        Self { residuals, errors, fold_columns }
    }

    /// Mean held-out position error, m.
    pub(crate) fn mean_error(&self) -> f64 {
        mean(&self.errors)
    }
}

/// A term scored on top of some base.
#[derive(Debug, Clone)]
pub(crate) struct Scored {
    /// The held-out result of the base and the term.
    pub result: CrossValidated,
    /// For a series: the order the cross-validation curve of all folds prefers, the one a fit on
    /// every row should use.
    pub order: Option<u32>,
    /// For a series: the order each fold chose on its own training rows.
    pub fold_orders: Vec<u32>,
    /// For a series: each order it may take, with its mean held-out position error over every
    /// fold (m): the outer curve `order` was the minimum of.
    pub curve: Vec<(u32, f64)>,
}

/// One accepted step of the selection.
#[derive(Debug, Clone)]
pub(crate) struct Step {
    /// The term added.
    pub term: usize,
    /// Its score on top of the earlier steps.
    pub scored: Scored,
    /// The signed-rank statistic of its gain over the previous step.
    pub z: f64,
}

/// What the selection found.
#[derive(Debug, Clone)]
pub(crate) struct Selection {
    /// Kinematics alone.
    pub baseline: CrossValidated,
    /// Every term alone on top of the kinematics, in term order.
    pub single: Vec<Scored>,
    /// The accepted steps, in order.
    pub steps: Vec<Step>,
    /// The critical value each step's statistic had to pass.
    pub critical_z: f64,
}

impl Selection {
    /// The held-out result with every accepted step.
    pub(crate) fn last(&self) -> &CrossValidated {
        self.steps.last().map_or(&self.baseline, |s| &s.scored.result)
    }
}

/// How strict the selection is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SelectionOptions {
    /// False-alarm rate of one step, shared among the candidates tried (Bonferroni).
    pub significance: f64,
    /// A step must also lower the median held-out error by at least this fraction (the median:
    /// a few poses thrown far off cannot hide a gain most poses show, nor fake one).
    pub min_relative_gain: f64,
    /// At most this many effects are combined.
    pub max_effects: usize,
    /// The orders a periodic error of a joint's own angle may take; each fold picks one by
    /// cross-validation on its training rows. Up to 48: the blind check draws harmonics up to 40,
    /// and a real UR10's joint errors need 24–32.
    pub series_orders: Vec<u32>,
    /// The order a fit on every row uses for a selected series minimises
    /// `(1 − w) · random folds + w · arcs`: its mean held-out error over the random folds, and
    /// over arcs of every other moving joint left out in turn (module `arcs`: order
    /// selection that also sees gaps). 0.5 weighs poses like the training poses and poses off
    /// them alike (no measurement chose it); 0 is the random folds alone, as before.
    pub arc_order_weight: f64,
}

impl Default for SelectionOptions {
    fn default() -> Self {
        Self {
            significance: 0.01,
            min_relative_gain: 0.03,
            max_effects: 4,
            series_orders: vec![1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 40, 48],
            arc_order_weight: 0.5,
        }
    }
}

pub(crate) fn argmin(values: &[f64]) -> usize {
    values.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1)).map_or(0, |(i, _)| i)
}

/// Scores `term` on top of `base` (the columns of each fold).
pub(crate) fn score(pool: &Pool, base: &[Vec<usize>], term: &Term) -> Result<Scored, Error> {
    let folds = pool.folds();
    let Some(orders) = &term.orders else {
        let fold_columns: Vec<Vec<usize>> =
            base.iter().enumerate().map(|(f, b)| b.iter().chain(term.columns_for(f)).copied().collect()).collect();
        let residuals = pool.cross_validate(&|f| fold_columns[f].clone())?;
        return Ok(Scored {
            result: CrossValidated::new(residuals, fold_columns),
            order: None,
            fold_orders: vec![],
            curve: vec![],
        });
    };
    let orders: Vec<u32> = orders.iter().copied().filter(|&h| 2 * h as usize <= term.columns.len()).collect();
    let inner_sum = inner_curves(pool, base, &term.columns, &orders)?;
    let mut fold_orders = Vec::with_capacity(folds);
    let mut outer_sum = vec![0.0; orders.len()];
    let mut residuals = vec![Vector6::zeros(); pool.poses()];
    let mut fold_columns = Vec::with_capacity(folds);
    for f in 0..folds {
        let pick = argmin(&inner_sum[f]);
        let chosen = orders[pick];
        fold_orders.push(chosen);
        // One factorisation gives the outer curve (for the order a fit on every row should use)
        // and the held-out residuals at the order the fold chose.
        let outer = pool.series_residuals(&[f], &[f], &base[f], &term.columns, &orders)?;
        for (sum, r) in outer_sum.iter_mut().zip(&outer[0]) {
            *sum += position_sum(r);
        }
        for (&i, r) in pool.fold_poses(f).iter().zip(&outer[0][pick]) {
            residuals[i] = *r;
        }
        fold_columns.push(base[f].iter().chain(&term.columns[..2 * chosen as usize]).copied().collect());
    }
    let rows = pool.poses().max(1) as f64;
    Ok(Scored {
        result: CrossValidated::new(residuals, fold_columns),
        order: Some(orders[argmin(&outer_sum)]),
        fold_orders,
        curve: orders.iter().zip(&outer_sum).map(|(&h, &sum)| (h, sum / rows)).collect(),
    })
}

/// The position error of residuals, summed.
fn position_sum(residuals: &[Vector6]) -> f64 {
    residuals.iter().map(|r| r.fixed_rows::<3>(0).norm()).sum::<f64>()
}

/// Inner cross-validation of a series over `columns` on top of `base` (each fold's): for outer
/// fold f, each other fold g in turn is validated by a fit on every fold but f and g. The pair
/// {f, g} has one training set, so one factorisation serves both f's and g's inner curves when
/// their bases agree. Returns per outer fold, per order, the summed position error.
fn inner_curves(pool: &Pool, base: &[Vec<usize>], columns: &[usize], orders: &[u32]) -> Result<Vec<Vec<f64>>, Error> {
    let folds = pool.folds();
    let mut inner_sum = vec![vec![0.0; orders.len()]; folds];
    for f in 0..folds {
        for g in f + 1..folds {
            if base[f] == base[g] {
                let both = pool.series_residuals(&[f, g], &[g, f], &base[f], columns, orders)?;
                for (outer, validated) in [(f, &both[0]), (g, &both[1])] {
                    for (sum, r) in inner_sum[outer].iter_mut().zip(validated) {
                        *sum += position_sum(r);
                    }
                }
            } else {
                for (outer, v) in [(f, g), (g, f)] {
                    let one = pool.series_residuals(&[f, g], &[v], &base[outer], columns, orders)?;
                    for (sum, r) in inner_sum[outer].iter_mut().zip(&one[0]) {
                        *sum += position_sum(r);
                    }
                }
            }
        }
    }
    Ok(inner_sum)
}

/// Greedy forward selection: at each step every remaining term is cross-validated on top of those
/// already chosen; the one with the lowest mean held-out error is kept when the signed-rank test
/// of its per-pose gain passes the Bonferroni-corrected critical value and the median error drops
/// by at least `min_relative_gain`.
pub(crate) fn select(pool: &Pool, terms: &[Term], options: &SelectionOptions) -> Result<Selection, Error> {
    let folds = pool.folds();
    let kinematic = pool.kinematic_columns();
    let baseline_columns = vec![kinematic; folds];
    let baseline = CrossValidated::new(pool.cross_validate(&|f| baseline_columns[f].clone())?, baseline_columns);
    let critical_z = normal_quantile(1.0 - options.significance / terms.len().max(1) as f64);
    let mut steps: Vec<Step> = Vec::new();
    let mut single = Vec::new();
    while steps.len() < options.max_effects {
        let current = steps.last().map_or(&baseline, |s| &s.scored.result);
        let taken =
            |t: &Term| steps.iter().any(|s| terms[s.term].effect == t.effect && terms[s.term].joints == t.joints);
        let remaining: Vec<usize> = (0..terms.len()).filter(|&t| !taken(&terms[t])).collect();
        let results: Vec<Scored> =
            remaining.par_iter().map(|&t| score(pool, &current.fold_columns, &terms[t])).collect::<Result<_, _>>()?;
        if steps.is_empty() {
            single = results.clone();
        }
        let Some((best, scored)) = remaining
            .iter()
            .zip(results)
            .min_by(|(_, a), (_, b)| a.result.mean_error().total_cmp(&b.result.mean_error()))
        else {
            break;
        };
        let z = signed_rank_z(&current.errors, &scored.result.errors);
        let gain = 1.0 - median(&scored.result.errors) / median(&current.errors).max(f64::MIN_POSITIVE);
        if !(z > critical_z && gain >= options.min_relative_gain) {
            break;
        }
        steps.push(Step { term: *best, scored, z });
    }
    Ok(Selection { baseline, single, steps, critical_z })
}

/// The held-out result of the kinematics with only the accepted steps `keep` (by position in
/// `selection.steps`), each fold keeping the columns (and series orders) it chose.
pub(crate) fn with_steps(
    pool: &Pool,
    terms: &[Term],
    selection: &Selection,
    keep: &[usize],
) -> Result<CrossValidated, Error> {
    let folds = pool.folds();
    let fold_columns: Vec<Vec<usize>> = (0..folds)
        .map(|f| {
            let mut columns = pool.kinematic_columns();
            for &s in keep {
                let step = &selection.steps[s];
                let term = &terms[step.term];
                let own = term.columns_for(f);
                let width = step.scored.fold_orders.get(f).map_or(own.len(), |&h| 2 * h as usize);
                columns.extend_from_slice(&own[..width]);
            }
            columns
        })
        .collect();
    let residuals = pool.cross_validate(&|f| fold_columns[f].clone())?;
    Ok(CrossValidated::new(residuals, fold_columns))
}
