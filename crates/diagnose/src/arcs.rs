//! Folds that see gaps: the held-out error of the selected effects when a contiguous arc of one
//! moving joint's angles is left out, as a model fitted on the rest meets it.
//!
//! Random folds leave out rows at random; every held-out row then has training rows at nearly
//! the same angles, and the prediction says nothing of poses past the end of the fitted angles or
//! in a gap of them. Here each moving joint's rows are sorted by its angle and cut into `folds`
//! arcs of equal count (the first and last are the two ends of its range); each arc is predicted
//! by the fit of the others, as the fitted model predicts poses where it knows nothing: the series
//! of the held-out joint's own angle is faded whole there (the model fades it in any gap wider
//! than half its shortest period, and a prediction for poses off the training poses must not
//! count on a gap being narrow), another joint's series is applied with the coverage weight
//! [`effects::GearPeriodicTerm::held_and_weight`] computed from that fit's own training angles, and the pose
//! is blended to the geometry fitted alone by the product of those weights (the model's
//! `fallback` part). So the arcs measure how the geometry and the other effects carry into
//! angles the fit never saw.
//!
//! A backlash side learnt from the data is taken as learnt on every row here (its per-fold
//! versions belong to the random folds): the side is a sign per pose, and the arcs test the
//! amplitude fitted on the other arcs.

use super::design::Design;
use super::fold_residuals::FoldResiduals;
use super::pool::{Block, KinematicPrior, Pool, PriorOptions};
use super::selection::{Selection, Step, Term};
use effects::{AngleCoverage, GearOptions, IdentifiedEffect};
use errors::Error;
use lie::Vector6;
use measurements::MeasurementSet;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The held-out error when arcs of one joint's angles are left out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArcCheck {
    /// The 1-based joint whose arcs are left out.
    pub joint: usize,
    /// Mean held-out position error of the geometric model, mm.
    pub before_mm: f64,
    /// The same with the selected effects (faded where their fit's angles do not reach), mm.
    pub after_mm: f64,
    /// Largest held-out position error of the geometric model, mm.
    pub before_max_mm: f64,
    /// The same with the selected effects, mm.
    pub after_max_mm: f64,
}

/// Per pose, the arc fold of each of `moving`'s joints: rows sorted by the joint's angle, cut into
/// `folds` runs of equal count (ties kept together by the stable sort of equal angles).
pub(crate) fn arc_folds(data: &MeasurementSet, joint: usize, folds: usize) -> Vec<usize> {
    let n = data.rows.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| data.rows[a].q[joint].total_cmp(&data.rows[b].q[joint]));
    let mut fold = vec![0; n];
    for (position, &row) in order.iter().enumerate() {
        fold[row] = (position * folds / n.max(1)).min(folds - 1);
    }
    fold
}

/// What the arc checks are computed from.
pub(crate) struct ArcInputs<'a> {
    pub design: &'a Design,
    pub kinematic_prior: &'a KinematicPrior,
    pub prior: &'a PriorOptions,
    pub gear: &'a GearOptions,
    pub folds: usize,
}

/// Per moving joint, its arcs as folds and one pool over them that holds every selected step's
/// columns in full: the order curves take a series at each of its orders, the arc checks every
/// step at its chosen order. Both are column subsets of the same rows, whose Gram entries do not
/// depend on the other columns a pool holds (module `pool`), so one pool per joint serves both
/// with the numbers a pool of the subset alone would give.
pub(crate) struct ArcPools {
    /// Per joint of `moving`, in its order: the 0-based joint, each row's arc and the pool.
    joints: Vec<(usize, Vec<usize>, Pool)>,
    /// The kinematic columns (the first ones).
    kinematic: usize,
    /// Where each selected step's columns start in every pool.
    offsets: Vec<usize>,
    /// How many columns each step has in full.
    widths: Vec<usize>,
}

impl ArcPools {
    /// The pools of `moving`'s joints (0-based) for the selection's steps; `columns_of` gives a
    /// term's weighted columns and prior sd.
    pub(crate) fn new(
        inputs: &ArcInputs<'_>,
        data: &MeasurementSet,
        moving: &[usize],
        selection: &Selection,
        columns_of: &dyn Fn(usize) -> (Vec<Vec<f64>>, Option<f64>),
    ) -> Self {
        let kinematic = inputs.design.kinematic.ncols();
        let full: Vec<(Vec<Vec<f64>>, Option<f64>)> = selection.steps.iter().map(|s| columns_of(s.term)).collect();
        let widths: Vec<usize> = full.iter().map(|(c, _)| c.len()).collect();
        let offsets = widths
            .iter()
            .scan(kinematic, |next, &w| {
                let at = *next;
                *next += w;
                Some(at)
            })
            .collect();
        let blocks: Vec<Block<'_>> = full.iter().map(|(c, sd)| (c.as_slice(), *sd)).collect();
        // Each joint's pool on its own, side by side, collected in the joints' order.
        let joints = moving
            .par_iter()
            .map(|&joint| {
                let fold = arc_folds(data, joint, inputs.folds);
                let (design, prior, folds) = (inputs.design, inputs.kinematic_prior, inputs.folds);
                let pool = Pool::single_folds(design, prior, &blocks, &fold, folds, inputs.prior);
                (joint, fold, pool)
            })
            .collect();
        Self { joints, kinematic, offsets, widths }
    }

    /// Step `s`'s columns in the pools, its first `width`.
    fn columns(&self, s: usize, width: usize) -> std::ops::Range<usize> {
        self.offsets[s]..self.offsets[s] + width.min(self.widths[s])
    }

    /// How many of step `s`'s columns it takes at the order the fit on every row uses.
    fn at_its_order(&self, s: usize, step: &Step) -> usize {
        step.scored.order.map_or(self.widths[s], |h| (2 * h as usize).min(self.widths[s]))
    }
}

/// The arc check of every joint of `pools` for the selection's effects. Beside each check, its
/// folds: the blended residual each arc's fit leaves on every row (its training rows blended as
/// the fold's model would blend them, the series' coverage of their own angles).
pub(crate) fn arc_checks(
    inputs: &ArcInputs<'_>,
    pools: &ArcPools,
    data: &MeasurementSet,
    terms: &[Term],
    selection: &Selection,
) -> Result<Vec<(ArcCheck, Vec<FoldResiduals>)>, Error> {
    // The selected series, each at the order the fit on every row uses.
    let series: Vec<(usize, u32)> = selection
        .steps
        .iter()
        .filter_map(|step| match &terms[step.term].model {
            IdentifiedEffect::GearPeriodic(g) => step.scored.order.map(|h| (g.joint, h)),
            _ => None,
        })
        .collect();
    // The kinematics, then every selected step at its order.
    let kinematic = pools.kinematic;
    let all: Vec<usize> = (0..kinematic)
        .chain(selection.steps.iter().enumerate().flat_map(|(s, step)| pools.columns(s, pools.at_its_order(s, step))))
        .collect();
    // Each joint's arcs side by side, collected in the joints' order.
    pools
        .joints
        .par_iter()
        .map(|(joint, fold, pool)| {
            JointArcs { inputs, data, joint: *joint, fold, pool, all: &all, kinematic, series: &series }.check()
        })
        .collect()
}

/// One joint's arcs: its pool, and the columns and series of the selected steps.
struct JointArcs<'a> {
    inputs: &'a ArcInputs<'a>,
    data: &'a MeasurementSet,
    /// The 0-based joint whose arcs are left out.
    joint: usize,
    /// Each row's arc.
    fold: &'a [usize],
    pool: &'a Pool,
    /// The kinematic columns, then every selected step's at its order.
    all: &'a [usize],
    kinematic: usize,
    /// Each selected series' joint and order.
    series: &'a [(usize, u32)],
}

impl JointArcs<'_> {
    /// The joint's check and its folds.
    fn check(&self) -> Result<(ArcCheck, Vec<FoldResiduals>), Error> {
        let mut before = Vec::with_capacity(self.data.rows.len());
        let mut after = Vec::with_capacity(self.data.rows.len());
        let mut folds = Vec::with_capacity(self.inputs.folds);
        for f in 0..self.inputs.folds {
            if !self.pool.fold_poses(f).is_empty() {
                folds.push(self.arc(f, &mut before, &mut after)?);
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64 * 1e3;
        let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max) * 1e3;
        let check = ArcCheck {
            joint: self.joint + 1,
            before_mm: mean(&before),
            after_mm: mean(&after),
            before_max_mm: max(&before),
            after_max_mm: max(&after),
        };
        Ok((check, folds))
    }

    /// Arc `f` held out: appends its poses' errors before and after to `before` and `after`;
    /// returns its fold.
    fn arc(&self, f: usize, before: &mut Vec<f64>, after: &mut Vec<f64>) -> Result<FoldResiduals, Error> {
        let (data, pool, all, fold) = (self.data, self.pool, self.all, self.fold);
        let poses = pool.fold_poses(f);
        let base = pool.solve(&[f], &all[..self.kinematic])?;
        let full = if all.len() == self.kinematic { base.clone() } else { pool.solve(&[f], all)? };
        let betas = [base, full];
        let residuals = pool.residuals(f, all, &betas);
        // Each series' coverage as its fit on this fold's training rows records it.
        let coverage: Vec<AngleCoverage> = self
            .series
            .iter()
            .map(|&(j, h)| {
                let angles: Vec<f64> = (0..data.rows.len())
                    .filter(|&i| fold[i] != f)
                    .filter_map(|i| data.rows[i].q.get(j).copied())
                    .collect();
                AngleCoverage::of(j, &(1..=h).collect::<Vec<u32>>(), &angles, self.inputs.gear)
            })
            .collect();
        // The training rows, blended as this fold's model blends them: each series by the
        // coverage of its own fit's angles.
        let mut fold_residuals = vec![Vector6::zeros(); data.rows.len()];
        let mut alone = vec![(Vector6::zeros(), 1.0); data.rows.len()];
        for g in (0..self.inputs.folds).filter(|&g| g != f) {
            let fitted = pool.residuals(g, all, &betas);
            for ((&i, b), a) in pool.fold_poses(g).iter().zip(&fitted[0]).zip(&fitted[1]) {
                let w: f64 = coverage.iter().map(|s| s.held_and_weight(data.rows[i].q[s.joint]).1).product();
                fold_residuals[i] = a * w + b * (1.0 - w);
                alone[i] = (*b, w);
            }
        }
        for ((&i, b), a) in poses.iter().zip(&residuals[0]).zip(&residuals[1]) {
            // A held-out arc of the joint's own angles is where its series knows nothing:
            // faded whole, whatever the width of the arc (the model fades it in a gap wider
            // than half its shortest period; an arc of a fifth of the rows may be narrower).
            let w: f64 = coverage
                .iter()
                .map(|g| if g.joint == self.joint { 0.0 } else { g.held_and_weight(data.rows[i].q[g.joint]).1 })
                .product();
            let blended: Vector6 = a * w + b * (1.0 - w);
            before.push(b.fixed_rows::<3>(0).norm());
            after.push(blended.fixed_rows::<3>(0).norm());
            fold_residuals[i] = blended;
            alone[i] = (*b, w);
        }
        Ok(FoldResiduals { held_out: poses.to_vec(), residuals: fold_residuals, alone })
    }
}

/// The mean of `value` over `arcs`; `None` without any.
pub(crate) fn mean_of(arcs: &[ArcCheck], value: impl Fn(&ArcCheck) -> f64) -> Option<f64> {
    (!arcs.is_empty()).then(|| arcs.iter().map(value).sum::<f64>() / arcs.len() as f64)
}

/// The selected series with a curve: (step, its joint, its orders that its columns reach), where
/// another joint moves.
fn series_with_curves(pools: &ArcPools, terms: &[Term], selection: &Selection) -> Vec<(usize, usize, Vec<u32>)> {
    selection
        .steps
        .iter()
        .enumerate()
        .filter_map(|(s, step)| {
            let term = &terms[step.term];
            let (Some(orders), IdentifiedEffect::GearPeriodic(gear)) = (&term.orders, &term.model) else {
                return None;
            };
            if !pools.joints.iter().any(|&(k, _, _)| k != gear.joint) {
                return None;
            }
            let orders = orders.iter().copied().filter(|&h| 2 * h as usize <= pools.widths[s]).collect();
            Some((s, gear.joint, orders))
        })
        .collect()
}

/// A series' orders and its mean held-out position error at each, m.
pub(crate) type OrderCurve = (Vec<u32>, Vec<f64>);

/// For each selected step that is a Fourier series of a joint's own angle, its mean held-out
/// position error (m) at each of its orders when arcs of every *other* moving joint are left out
/// in turn (the other selected steps at their chosen orders); `None` for other steps or where no
/// other joint moves. The series' own joint's arcs are left out of this: there the model fades
/// the series whole, whatever its order.
///
/// Each joint's pool (`ArcPools`) serves every series: each series' fits take the columns of the
/// other steps at their orders and its own at each of its orders.
pub(crate) fn order_curves(
    pools: &ArcPools,
    terms: &[Term],
    selection: &Selection,
) -> Result<Vec<Option<OrderCurve>>, Error> {
    let steps = &selection.steps;
    let curves = series_with_curves(pools, terms, selection);
    let mut sums: Vec<Vec<f64>> = curves.iter().map(|(_, _, orders)| vec![0.0; orders.len()]).collect();
    let mut counts = vec![0usize; curves.len()];
    // Each series' columns: the kinematics, the other steps at their orders, then this series in
    // full (the same for every joint's arcs).
    let columns: Vec<(Vec<usize>, Vec<usize>)> = curves
        .iter()
        .map(|&(s, _, _)| {
            let others = (0..steps.len()).filter(|&t| t != s);
            let base =
                (0..pools.kinematic).chain(others.flat_map(|t| pools.columns(t, pools.at_its_order(t, &steps[t]))));
            (base.collect(), pools.columns(s, pools.widths[s]).collect())
        })
        .collect();
    for (k, _, pool) in &pools.joints {
        if curves.iter().all(|(_, joint, _)| joint == k) {
            continue;
        }
        // Every (series, fold) pair's held-out residuals side by side, then summed in the
        // serial order, so the curve is the same to the bit.
        let pairs: Vec<(usize, usize)> = curves
            .iter()
            .enumerate()
            .filter(|(_, (_, joint, _))| joint != k)
            .flat_map(|(c, _)| (0..pool.folds()).map(move |f| (c, f)))
            .filter(|&(_, f)| !pool.fold_poses(f).is_empty())
            .collect();
        let residuals = pairs
            .par_iter()
            .map(|&(c, f)| {
                let (base, series) = &columns[c];
                pool.series_residuals(&[f], &[f], base, series, &curves[c].2)
            })
            .collect::<Result<Vec<_>, Error>>()?;
        for (&(c, f), residuals) in pairs.iter().zip(&residuals) {
            for (total, r) in sums[c].iter_mut().zip(&residuals[0]) {
                *total += r.iter().map(|v| v.fixed_rows::<3>(0).norm()).sum::<f64>();
            }
            counts[c] += pool.fold_poses(f).len();
        }
    }
    let mut out = vec![None; steps.len()];
    for ((c, (s, _, orders)), sum) in curves.into_iter().enumerate().zip(sums) {
        out[s] = Some((orders, sum.iter().map(|v| v / counts[c].max(1) as f64).collect()));
    }
    Ok(out)
}
