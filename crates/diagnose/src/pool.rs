//! Every column the diagnosis may use, assembled once, with the Gram matrix of each fold's rows:
//! a fold's fit is then a small regularised solve, whatever subset of columns a candidate takes.
//!
//! The fit of a fold is the maximum a posteriori step of the linearised problem (module `design`)
//! under a Gaussian prior on every parameter, `min ‖y − X β‖² + Σ_c (β_c / τ_c)²` (Tikhonov
//! regularisation read as a prior: Hansen, *Rank-Deficient and Discrete Ill-Posed Problems*, 1998,
//! ch. 5; Kaipio & Somersalo, *Statistical and Computational Inverse Problems*, 2005, §3.3). In a
//! direction the fold's rows determine well the prior does nothing; in one they hardly see (a
//! joint that barely moves, a tool seen from one side) the step stays near zero instead of
//! following the noise and throwing held-out poses far off, which is what made cross-validated
//! errors heavy-tailed. The residuals `y` are in units of the residual scale of the geometric
//! fit, so the prior's strength is relative to what the data say.

use super::design::{Design, Weights};
#[cfg(test)]
use super::statistics::mean;
use crate::ErrorKind;
use errors::Error;
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{Accum, Mat, MatRef, Par, Side};
use lie::Vector6;
use poe::LocalPoe;
use rayon::prelude::*;

/// One fold's weighted rows `X_f`, targets `y_f`, Gram matrix `X_fᵀ X_f` and `X_fᵀ y_f`.
type FoldProducts = (Mat<f64>, Vec<f64>, Mat<f64>, Vec<f64>);

/// Per set of new columns and fold: their products with every column up to them, and with the
/// targets.
type CrossProducts = (Vec<Vec<Mat<f64>>>, Vec<Vec<Vec<f64>>>);

/// The prior standard deviation of each column's parameter.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PriorOptions {
    /// Prior standard deviation of each translation parameter of the local frames between joints
    /// (joint 2 on), about the nominal model (the robot file), m. 1 mm: the tolerances a serial
    /// arm is built to (the simulated arm's perturbation, `campaign::Perturbation`;
    /// Nubiola & Bonev 2013 measure an uncalibrated IRB 1600 at 0.97 mm mean): no fold can put a
    /// link further from its drawing than that without rows that say so. Centred on the nominal,
    /// not on the fit to every row, so that a fold's prior holds nothing of the rows it is scored
    /// on, and so that a kinematic parameter that absorbed an effect in that fit can give it back.
    pub kinematic_m: f64,
    /// The same for each rotation parameter, rad. 1 mrad, as above.
    pub kinematic_rad: f64,
    /// Prior standard deviation of the placement of joint 1 in the tracker frame and of each tool
    /// (nothing is known about them beforehand), about the fit to every row, m and rad: 1, i.e.
    /// free, but enough to keep a direction no row sees (the orientation of a point tool) at zero.
    pub placement: f64,
    /// Prior standard deviation of each effect parameter, as the RMS tool displacement it causes
    /// over the data, m. 5 mm: larger than any effect a calibrated arm shows (the blind check's
    /// effects reach 4 mm), so it only holds what the data cannot see.
    pub effect_m: f64,
    /// Prior standard deviation of each Fourier coefficient of a periodic joint error, rad.
    /// 1 mrad: above the transmission error of any precision reducer (RV and harmonic drives
    /// specify ≤ 1 arcmin, 0.29 mrad, of lost motion and transmission error) and of any joint
    /// encoder, so a coefficient the data determine is not shrunk; but over part of a turn most
    /// combinations of harmonics are seen by no pose, and without this bound a series reaches
    /// 20 mm at a pose at the edge of the range (the UR10's home pose).
    pub series_rad: f64,
}

impl Default for PriorOptions {
    fn default() -> Self {
        Self { kinematic_m: 1e-3, kinematic_rad: 1e-3, placement: 1.0, effect_m: 5e-3, series_rad: 1e-3 }
    }
}

/// A block of further columns (weighted rows) and the prior standard deviation of their
/// parameters (`None`: [`PriorOptions::effect_m`] of tool displacement).
pub(crate) type Block<'a> = (&'a [Vec<f64>], Option<f64>);

/// The prior of the kinematic columns: mean and precision of each.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct KinematicPrior {
    /// Prior mean of each parameter (a left twist from the fit to every row).
    pub mean: Vec<f64>,
    /// Prior precision `1/τ²` of each parameter.
    pub precision: Vec<f64>,
}

impl KinematicPrior {
    /// The prior of `fitted`'s local frames: joint 1's frame (which holds the tracker placement)
    /// and the tools free about `fitted`, every other frame about `nominal`'s (the step
    /// `log(N_i M_i⁻¹)` that takes the fitted frame `M_i` to the nominal `N_i` under the
    /// identification's left perturbation, module `poe::jacobian`).
    pub(crate) fn new(nominal: &LocalPoe, fitted: &LocalPoe, options: &PriorOptions) -> Self {
        let layout = fitted.layout();
        let mut mean = vec![0.0; layout.len()];
        let mut precision = vec![0.0; layout.len()];
        for index in 0..layout.len() {
            let (block, component) = layout.block_of(index);
            let sd = match block {
                poe::Block::Joint(i) if i > 0 => {
                    let to_nominal = (nominal.joints()[i].previous_from_joint_zero
                        * fitted.joints()[i].previous_from_joint_zero.inverse())
                    .log()
                    .to_vector();
                    mean[index] = to_nominal[component];
                    if component < 3 { options.kinematic_m } else { options.kinematic_rad }
                }
                _ => options.placement,
            };
            precision[index] = 1.0 / (sd * sd);
        }
        Self { mean, precision }
    }
}

/// The linear problem: weighted design columns, residual, prior, and the per-fold Gram matrices.
#[derive(Debug, Clone)]
pub(crate) struct Pool {
    /// Rows per pose: 3 or 6.
    k: usize,
    weights: Weights,
    /// Weighted design of each fold's rows (its poses in order, `k` rows each), one column per
    /// parameter.
    x: Vec<Mat<f64>>,
    /// Weighted residual of each fold's rows.
    y: Vec<Vec<f64>>,
    /// Prior precision `1/τ²` of each column.
    precision: Vec<f64>,
    /// Prior mean of each column's parameter (the nominal model's, for the local frames).
    prior_mean: Vec<f64>,
    /// Number of kinematic columns (the first ones).
    pub kinematic: usize,
    /// The fold of each pose.
    fold: Vec<usize>,
    /// Poses of each fold.
    fold_poses: Vec<Vec<usize>>,
    /// `Xᵀ X` and `Xᵀ y` over the rows of every fold but one (index `f`), every fold but a pair
    /// (index [`pair_index`]), and every fold (the last entry).
    gram: Vec<Mat<f64>>,
    xty: Vec<Vec<f64>>,
}

/// Where the Gram matrix without the folds `f < g` is kept: after the `folds` single ones.
fn pair_index(folds: usize, f: usize, g: usize) -> usize {
    folds + f * (2 * folds - f - 1) / 2 + (g - f - 1)
}

/// A Cholesky factor of an equilibrated system `D A D = L Lᵀ`; any leading block of `L` is the
/// factor of the same leading block of `D A D`, so nested column sets share one factorisation.
pub(crate) struct Factor {
    l: Mat<f64>,
    d: Vec<f64>,
}

impl Factor {
    /// Solves the leading `m × m` block of `A β = b` (`b` at least `m` long).
    pub(crate) fn solve_prefix(&self, m: usize, b: &[f64]) -> Vec<f64> {
        let mut z = Mat::<f64>::from_fn(m, 1, |i, _| b[i] * self.d[i]);
        let l = self.l.as_ref().submatrix(0, 0, m, m);
        solve_lower_triangular_in_place(l, z.as_mut(), Par::Seq);
        solve_upper_triangular_in_place(l.transpose(), z.as_mut(), Par::Seq);
        (0..m).map(|i| z[(i, 0)] * self.d[i]).collect()
    }

    /// Solves the whole system.
    pub(crate) fn solve(&self, b: &[f64]) -> Vec<f64> {
        self.solve_prefix(self.d.len(), b)
    }
}

/// `xᵀ x`: its lower triangle multiplied, then mirrored. The product's SIMD kernels keep one
/// accumulator per entry and add a column pair's products in row order whatever the tile, the
/// triangle or the matrix's width, and `a·b = b·a` exactly; so the mirror is bit for bit the upper
/// triangle a full product would give, and an entry is the same in any pool over the same rows
/// that holds both its columns (test `a_gram_entry_does_not_depend_on_the_other_columns`).
fn gram(x: MatRef<'_, f64>) -> Mat<f64> {
    let n = x.ncols();
    let mut g = Mat::<f64>::zeros(n, n);
    triangular::matmul(
        g.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        x.transpose(),
        BlockStructure::Rectangular,
        x,
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
    for j in 0..n {
        for i in j + 1..n {
            g[(j, i)] = g[(i, j)];
        }
    }
    g
}

/// Each fold's weighted rows, targets and products (module doc); `column(c)` is pool column `c`
/// on every row.
///
/// One fold per task, each product sequential: the sums run in the same order on any number of
/// threads, so the pool (and the diagnosis) is the same serial or parallel.
fn fold_products<'a>(
    design: &Design,
    column: &(dyn Fn(usize) -> &'a [f64] + Sync),
    columns: usize,
    fold_poses: &[Vec<usize>],
) -> Vec<FoldProducts> {
    let k = design.rows_per_pose;
    fold_poses
        .par_iter()
        .map(|poses_f| {
            let rows_f: Vec<usize> = poses_f.iter().flat_map(|&i| (0..k).map(move |r| i * k + r)).collect();
            // Gathered a column at a time from contiguous columns: a closure per entry
            // (`Mat::from_fn`) was a fifth of the whole diagnosis on 400-column pools.
            let mut xf = Mat::<f64>::zeros(rows_f.len(), columns);
            for c in 0..columns {
                let source = column(c);
                for (target, &r) in xf.col_as_slice_mut(c).iter_mut().zip(&rows_f) {
                    *target = source[r];
                }
            }
            let yf: Vec<f64> = rows_f.iter().map(|&r| design.y[r]).collect();
            let ym = Mat::<f64>::from_fn(rows_f.len(), 1, |r, _| yf[r]);
            let g = gram(xf.as_ref());
            let mut b = Mat::<f64>::zeros(columns, 1);
            matmul(b.as_mut(), Accum::Replace, xf.transpose(), ym.as_ref(), 1.0, Par::Seq);
            (xf, yf, g, (0..columns).map(|c| b[(c, 0)]).collect::<Vec<f64>>())
        })
        .collect()
}

/// `Xᵀ X` and `Xᵀ y` over every fold but one, every fold but a pair (with `pairs`), and every
/// fold, in [`Pool::gram`]'s order, from each fold's own.
fn left_out_products(fold_gram: &[Mat<f64>], fold_xty: &[Vec<f64>], pairs: bool) -> (Vec<Mat<f64>>, Vec<Vec<f64>>) {
    let (folds, columns) = (fold_gram.len(), fold_xty.first().map_or(0, Vec::len));
    let mut gram_all = Mat::<f64>::zeros(columns, columns);
    let mut xty_all = vec![0.0; columns];
    for (g, b) in fold_gram.iter().zip(fold_xty) {
        gram_all += g;
        xty_all.iter_mut().zip(b).for_each(|(t, v)| *t += v);
    }
    let without = |out: &[usize]| {
        let mut g = gram_all.clone();
        let mut b = xty_all.clone();
        for &f in out {
            g -= &fold_gram[f];
            b.iter_mut().zip(&fold_xty[f]).for_each(|(t, v)| *t -= v);
        }
        (g, b)
    };
    let mut gram = Vec::new();
    let mut xty = Vec::new();
    let mut push = |(g, b): (Mat<f64>, Vec<f64>)| {
        gram.push(g);
        xty.push(b);
    };
    for f in 0..folds {
        push(without(&[f]));
    }
    if pairs {
        for f in 0..folds {
            for g in f + 1..folds {
                push(without(&[f, g]));
            }
        }
    }
    push((gram_all, xty_all));
    (gram, xty)
}

/// The prior precision of an effect parameter whose weighted column is `column`: `1/sd²`, or
/// [`PriorOptions::effect_m`] of RMS tool displacement.
fn effect_precision(column: &[f64], sd: Option<f64>, k: usize, w: f64, prior: &PriorOptions) -> f64 {
    if let Some(sd) = sd {
        return 1.0 / (sd * sd);
    }
    let poses = column.len() / k;
    let displacement_sq: f64 = (0..poses).map(|i| (0..3).map(|r| (column[i * k + r] * w).powi(2)).sum::<f64>()).sum();
    let rms = (displacement_sq / poses.max(1) as f64).sqrt();
    if rms > 0.0 { (rms / prior.effect_m).powi(2) } else { 1.0 }
}

impl Pool {
    /// The pool of `design`'s kinematic columns and `blocks` of further columns (weighted rows,
    /// `rows_per_pose × poses` each) with the prior standard deviation of their parameters (`None`:
    /// [`PriorOptions::effect_m`] of tool displacement), and `fold[i]` the fold of pose `i` in
    /// `0..folds`.
    pub(crate) fn new(
        design: &Design,
        kinematic_prior: &KinematicPrior,
        blocks: &[Block<'_>],
        fold: &[usize],
        folds: usize,
        prior: &PriorOptions,
    ) -> Self {
        Self::build(design, kinematic_prior, blocks, fold, folds, prior, true)
    }

    /// [`Pool::new`] without the Gram matrices of every fold but a pair: for callers that only
    /// leave out one fold at a time (the arcs), which then cost `folds + 1` Gram matrices instead
    /// of `folds (folds + 1) / 2 + 1`. Leaving out a pair is refused as a failed solve.
    pub(crate) fn single_folds(
        design: &Design,
        kinematic_prior: &KinematicPrior,
        blocks: &[Block<'_>],
        fold: &[usize],
        folds: usize,
        prior: &PriorOptions,
    ) -> Self {
        Self::build(design, kinematic_prior, blocks, fold, folds, prior, false)
    }

    fn build(
        design: &Design,
        kinematic_prior: &KinematicPrior,
        blocks: &[Block<'_>],
        fold: &[usize],
        folds: usize,
        prior: &PriorOptions,
        pairs: bool,
    ) -> Self {
        let k = design.rows_per_pose;
        let kinematic = design.kinematic.ncols();
        let extra: Vec<&Vec<f64>> = blocks.iter().flat_map(|b| b.0.iter()).collect();
        let extra_sd: Vec<Option<f64>> = blocks.iter().flat_map(|b| std::iter::repeat_n(b.1, b.0.len())).collect();
        let columns = kinematic + extra.len();
        let column = |c: usize| -> &[f64] {
            if c < kinematic { design.kinematic.col_as_slice(c) } else { extra[c - kinematic] }
        };
        let mut precision = kinematic_prior.precision.clone();
        let mut prior_mean = kinematic_prior.mean.clone();
        prior_mean.resize(columns, 0.0);
        for (column, sd) in extra.iter().zip(&extra_sd) {
            precision.push(effect_precision(column, *sd, k, design.weights.position_m, prior));
        }
        let mut fold_poses = vec![Vec::new(); folds];
        for (i, &f) in fold.iter().enumerate() {
            fold_poses[f].push(i);
        }
        let per_fold = fold_products(design, &column, columns, &fold_poses);
        let mut x = Vec::with_capacity(folds);
        let mut y = Vec::with_capacity(folds);
        let mut fold_gram = Vec::with_capacity(folds);
        let mut fold_xty = Vec::with_capacity(folds);
        for (xf, yf, g, b) in per_fold {
            x.push(xf);
            y.push(yf);
            fold_gram.push(g);
            fold_xty.push(b);
        }
        let (gram, xty) = left_out_products(&fold_gram, &fold_xty, pairs);
        Self {
            k,
            weights: design.weights,
            x,
            y,
            precision,
            prior_mean,
            kinematic,
            fold: fold.to_vec(),
            fold_poses,
            gram,
            xty,
        }
    }

    /// The folds whose rows Gram matrix `index` leaves out.
    fn left_out_of(&self, index: usize) -> Vec<usize> {
        let folds = self.folds();
        if index < folds {
            return vec![index];
        }
        if index + 1 == self.gram.len() {
            return vec![];
        }
        for f in 0..folds {
            for g in f + 1..folds {
                if pair_index(folds, f, g) == index {
                    return vec![f, g];
                }
            }
        }
        vec![]
    }

    /// Appends each set of `sets` of columns (weighted rows of every pose) in turn, their
    /// parameters with the prior standard deviation `sd` (`None`: [`PriorOptions::effect_m`] of
    /// tool displacement); returns each set's indices. Every Gram matrix is grown once (set by
    /// set, each would be copied at every size between).
    pub(crate) fn extend_sets(
        &mut self,
        sets: &[Vec<Vec<f64>>],
        sd: Option<f64>,
        prior: &PriorOptions,
    ) -> Vec<std::ops::Range<usize>> {
        let k = self.k;
        let first = self.x.first().map_or(0, |x| x.ncols());
        let mut ranges = Vec::with_capacity(sets.len());
        let mut end = first;
        for set in sets {
            ranges.push(end..end + set.len());
            end += set.len();
        }
        let total = end;
        let products = self.grow_rows(sets, &ranges, first, total);
        for index in 0..self.gram.len() {
            self.grow_gram(index, &ranges, first, &products);
        }
        for column in sets.iter().flatten() {
            self.precision.push(effect_precision(column, sd, k, self.weights.position_m, prior));
            self.prior_mean.push(0.0);
        }
        ranges
    }

    /// Appends the columns of `sets` (at `ranges`, after the `first` there are) to every fold's
    /// rows; returns per set and fold the products of its new columns with every column up to
    /// them (what `extend` of that set alone would multiply), and with the targets.
    fn grow_rows(
        &mut self,
        sets: &[Vec<Vec<f64>>],
        ranges: &[std::ops::Range<usize>],
        first: usize,
        total: usize,
    ) -> CrossProducts {
        let k = self.k;
        let mut cross: Vec<Vec<Mat<f64>>> = vec![Vec::with_capacity(self.folds()); sets.len()];
        let mut cross_y: Vec<Vec<Vec<f64>>> = vec![Vec::with_capacity(self.folds()); sets.len()];
        for f in 0..self.folds() {
            let poses = &self.fold_poses[f];
            let rows = poses.len() * k;
            let mut xf = Mat::<f64>::zeros(rows, total);
            for c in 0..first {
                xf.col_as_slice_mut(c).copy_from_slice(self.x[f].col_as_slice(c));
            }
            for (set, range) in sets.iter().zip(ranges) {
                for (l, column) in set.iter().enumerate() {
                    for (r, v) in xf.col_as_slice_mut(range.start + l).iter_mut().enumerate() {
                        *v = column[poses[r / k] * k + r % k];
                    }
                }
            }
            for (s, range) in ranges.iter().enumerate() {
                let m = range.len();
                let fresh = xf.as_ref().subcols(range.start, m);
                let mut block = Mat::<f64>::zeros(range.end, m);
                matmul(
                    block.as_mut(),
                    Accum::Replace,
                    xf.as_ref().subcols(0, range.end).transpose(),
                    fresh,
                    1.0,
                    Par::Seq,
                );
                let by: Vec<f64> =
                    (0..m).map(|l| fresh.col(l).iter().zip(&self.y[f]).map(|(a, b)| a * b).sum()).collect();
                cross[s].push(block);
                cross_y[s].push(by);
            }
            self.x[f] = xf;
        }
        (cross, cross_y)
    }

    /// Grows Gram matrix `index` from its `first` columns by the sets' products (`grow_rows`)
    /// over the folds it keeps, and its `Xᵀ y` alike.
    fn grow_gram(
        &mut self,
        index: usize,
        ranges: &[std::ops::Range<usize>],
        first: usize,
        (cross, cross_y): &CrossProducts,
    ) {
        let total = ranges.last().map_or(first, |r| r.end);
        let left_out = self.left_out_of(index);
        let mut g = Mat::<f64>::zeros(total, total);
        for c in 0..first {
            g.col_as_slice_mut(c)[..first].copy_from_slice(&self.gram[index].col_as_slice(c)[..first]);
        }
        // Each set writes its own columns (rows up to its end) and, mirrored, its own rows
        // left of it: no entry is written by two sets.
        for (s, range) in ranges.iter().enumerate() {
            let (old, m) = (range.start, range.len());
            let mut added_y = vec![0.0; m];
            for f in (0..self.folds()).filter(|f| !left_out.contains(f)) {
                for l in 0..m {
                    for r in 0..range.end {
                        let v = cross[s][f][(r, l)];
                        g[(r, old + l)] += v;
                        if r < old {
                            g[(old + l, r)] += v;
                        }
                    }
                    added_y[l] += cross_y[s][f][l];
                }
            }
            self.xty[index].extend(added_y);
        }
        self.gram[index] = g;
    }

    /// The weighted residual rows `y − X β` of the poses of fold `fold` (in their order).
    pub(crate) fn weighted_residual(&self, fold: usize, columns: &[usize], beta: &[f64]) -> Vec<f64> {
        let xf = &self.x[fold];
        let mut r = self.y[fold].clone();
        for (&c, b) in columns.iter().zip(beta) {
            for (v, x) in r.iter_mut().zip(xf.col_as_slice(c)) {
                *v -= x * b;
            }
        }
        r
    }

    /// Number of folds.
    pub(crate) fn folds(&self) -> usize {
        self.fold_poses.len()
    }

    /// Number of poses.
    pub(crate) fn poses(&self) -> usize {
        self.fold.len()
    }

    /// Poses of fold `f`.
    pub(crate) fn fold_poses(&self, f: usize) -> &[usize] {
        &self.fold_poses[f]
    }

    /// The kinematic columns' indices.
    pub(crate) fn kinematic_columns(&self) -> Vec<usize> {
        (0..self.kinematic).collect()
    }

    /// Factors the regularised normal equations of `columns` over every row but those of the
    /// folds in `left_out`; returns the factor and the right-hand side.
    pub(crate) fn factor(&self, left_out: &[usize], columns: &[usize]) -> Result<(Factor, Vec<f64>), Error> {
        let m = columns.len();
        let folds = self.folds();
        let index = match *left_out {
            [] => self.gram.len() - 1,
            [f] if f < folds => f,
            [f, g] if f < folds && g < folds && f != g && self.gram.len() > folds + 1 => {
                pair_index(folds, f.min(g), f.max(g))
            }
            _ => {
                return Err(Error::new(ErrorKind::DiagnoseSolve { left_out: left_out.to_vec(), columns: m, pivot: 0 }));
            }
        };
        let (gram, xty) = (&self.gram[index], &self.xty[index]);
        let mut a = Mat::<f64>::zeros(m, m);
        for (j, &cj) in columns.iter().enumerate() {
            let source = gram.col_as_slice(cj);
            for (target, &ci) in a.col_as_slice_mut(j).iter_mut().zip(columns) {
                *target = source[ci];
            }
        }
        let rhs: Vec<f64> = columns.iter().map(|&c| xty[c] + self.precision[c] * self.prior_mean[c]).collect();
        for (i, &c) in columns.iter().enumerate() {
            a[(i, i)] += self.precision[c];
        }
        // Jacobi equilibration: the factorisation's accuracy then does not depend on the columns'
        // units (metres of lever against newton-metres of torque).
        let d: Vec<f64> = (0..m).map(|i| 1.0 / a[(i, i)].max(f64::MIN_POSITIVE).sqrt()).collect();
        let mut scaled = a;
        for (j, &dj) in d.iter().enumerate() {
            for (v, &di) in scaled.col_as_slice_mut(j).iter_mut().zip(&d) {
                *v *= di * dj;
            }
        }
        let llt = scaled.llt(Side::Lower).map_err(|e| {
            let pivot = match e {
                faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } => index,
            };
            Error::new(ErrorKind::DiagnoseSolve { left_out: left_out.to_vec(), columns: m, pivot })
        })?;
        Ok((Factor { l: llt.L().to_owned(), d }, rhs))
    }

    /// The regularised fit of `columns` on every row outside the folds `left_out`.
    pub(crate) fn solve(&self, left_out: &[usize], columns: &[usize]) -> Result<Vec<f64>, Error> {
        let (factor, rhs) = self.factor(left_out, columns)?;
        Ok(factor.solve(&rhs))
    }

    /// The unweighted residuals (position m, then orientation rad) that the fits `betas` (each over
    /// `columns`, zero-padded beyond its length) leave at the poses of fold `fold`: one `Vec` per
    /// fit, in the order of [`Pool::fold_poses`].
    pub(crate) fn residuals(&self, fold: usize, columns: &[usize], betas: &[Vec<f64>]) -> Vec<Vec<Vector6>> {
        let k = self.k;
        let m = columns.len();
        let xf = &self.x[fold];
        let rows = xf.nrows();
        let b = Mat::<f64>::from_fn(m, betas.len(), |i, s| betas[s].get(i).copied().unwrap_or(0.0));
        let mut predicted = Mat::<f64>::zeros(rows, betas.len());
        // Columns that are a run of the pool's are read in place; others are copied next to each
        // other first. Either way the product sees the same matrix, so the same sums.
        let run = columns.first().filter(|&&first| columns.iter().enumerate().all(|(j, &c)| c == first + j));
        match run {
            Some(&first) => {
                let xs = xf.as_ref().subcols(first, m);
                matmul(predicted.as_mut(), Accum::Replace, xs, b.as_ref(), 1.0, Par::Seq);
            }
            None => {
                let mut xs = Mat::<f64>::zeros(rows, m);
                for (j, &c) in columns.iter().enumerate() {
                    xs.col_as_slice_mut(j).copy_from_slice(xf.col_as_slice(c));
                }
                matmul(predicted.as_mut(), Accum::Replace, xs.as_ref(), b.as_ref(), 1.0, Par::Seq);
            }
        }
        let y = &self.y[fold];
        (0..betas.len())
            .map(|s| {
                let p = predicted.col_as_slice(s);
                (0..rows / k)
                    .map(|pose| {
                        let mut residual = Vector6::zeros();
                        for r in 0..k {
                            let weight = if r < 3 { self.weights.position_m } else { self.weights.rotation_rad };
                            residual[r] = (y[pose * k + r] - p[pose * k + r]) * weight;
                        }
                        residual
                    })
                    .collect()
            })
            .collect()
    }

    /// The unweighted residual of every pose, each predicted by the fit of its fold's complement
    /// with the columns `columns_of(fold)`.
    pub(crate) fn cross_validate(&self, columns_of: &dyn Fn(usize) -> Vec<usize>) -> Result<Vec<Vector6>, Error> {
        let mut out = vec![Vector6::zeros(); self.poses()];
        for f in 0..self.folds() {
            let poses = self.fold_poses(f);
            if poses.is_empty() {
                continue;
            }
            let columns = columns_of(f);
            let beta = self.solve(&[f], &columns)?;
            let residuals = self.residuals(f, &columns, &[beta]);
            for (&i, r) in poses.iter().zip(&residuals[0]) {
                out[i] = *r;
            }
        }
        Ok(out)
    }

    /// Nested fits `base ++ series[..2h]` for every order `h` of `orders`, from one factorisation
    /// of `base ++ series[..longest]` (the columns are nested), scored on the poses of each fold
    /// of `validate`: per validated fold, per order, the residual of each pose.
    pub(crate) fn series_residuals(
        &self,
        left_out: &[usize],
        validate: &[usize],
        base: &[usize],
        series: &[usize],
        orders: &[u32],
    ) -> Result<Vec<Vec<Vec<Vector6>>>, Error> {
        let longest = orders.iter().map(|&h| 2 * h as usize).max().unwrap_or(0).min(series.len());
        let columns: Vec<usize> = base.iter().chain(&series[..longest]).copied().collect();
        let (factor, rhs) = self.factor(left_out, &columns)?;
        let betas: Vec<Vec<f64>> =
            orders.iter().map(|&h| factor.solve_prefix(base.len() + (2 * h as usize).min(longest), &rhs)).collect();
        Ok(validate.iter().map(|&v| self.residuals(v, &columns, &betas)).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::super::selection::{Term, select};
    use super::*;
    use crate::Effect;
    use lie::Vector3;
    use rand::{Rng, SeedableRng};

    /// A standard normal draw (Box–Muller).
    fn normal(rng: &mut rand_chacha::ChaCha8Rng) -> f64 {
        let (u, v): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random_range(0.0..1.0));
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// The shape of a real 7-axis campaign in a linear problem: four well-excited kinematic
    /// columns; two that only the jitter of joints held still excites (1e-3 of the others), except
    /// one pose each where that joint did move; an effect column worth 1.5 noise σ per row.
    fn heavy_tailed_shape(poses: usize) -> (Design, Vec<f64>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let rows = 3 * poses;
        let mut kinematic = Mat::<f64>::zeros(rows, 12);
        for r in 0..rows {
            for c in 0..4 {
                kinematic[(r, c)] = normal(&mut rng);
            }
            for c in 4..6 {
                let moved = (r / 3 == 7 && c == 4) || (r / 3 == 13 && c == 5);
                kinematic[(r, c)] = normal(&mut rng) * if moved { 1.0 } else { 1e-3 };
            }
        }
        let effect: Vec<f64> = (0..rows).map(|_| normal(&mut rng)).collect();
        let y: Vec<f64> = (0..rows)
            .map(|r| 0.5 * kinematic[(r, 0)] - 0.3 * kinematic[(r, 1)] + 1.5 * effect[r] + normal(&mut rng))
            .collect();
        let design = Design {
            rows_per_pose: 3,
            y,
            kinematic,
            points: vec![Vector3::zeros(); poses],
            // 0.1 mm per unit row: the effect's prior (`effect_m`, tool displacement) then holds
            // only what no row sees, as on real data.
            weights: Weights { position_m: 1e-4, rotation_rad: 1.0 },
        };
        (design, effect)
    }

    fn prior(sd: f64) -> KinematicPrior {
        KinematicPrior { mean: vec![0.0; 12], precision: vec![1.0 / (sd * sd); 12] }
    }

    fn errors(residuals: &[Vector6]) -> Vec<f64> {
        residuals.iter().map(|r| r.fixed_rows::<3>(0).norm()).collect()
    }

    #[test]
    fn a_prior_keeps_folds_from_extrapolating_along_directions_their_rows_do_not_see() {
        let (design, effect) = heavy_tailed_shape(200);
        let fold = super::super::fold_assignment(200, 5, 3);
        let blocks = [(std::slice::from_ref(&effect), None)];
        let options = PriorOptions::default();
        // Without a prior worth the name (τ = 1e6) the held-out pose that alone moved a "fixed"
        // joint is predicted from a fit that never saw it move: its error explodes.
        let loose = Pool::new(&design, &prior(1e6), &blocks, &fold, 5, &options);
        let loose_errors = errors(&loose.cross_validate(&|_| (0..12).collect()).unwrap());
        let (mean_loose, max_loose) = (mean(&loose_errors), loose_errors.iter().copied().fold(0.0, f64::max));
        assert!(max_loose > 30.0 * mean_loose, "mean {mean_loose}, max {max_loose}");
        // With τ = 1 per parameter those directions stay at the prior: no held-out pose is far off.
        let held = Pool::new(&design, &prior(1.0), &blocks, &fold, 5, &options);
        let held_errors = errors(&held.cross_validate(&|_| (0..12).collect()).unwrap());
        let (mean_held, max_held) = (mean(&held_errors), held_errors.iter().copied().fold(0.0, f64::max));
        assert!(max_held < 5.0 * mean_held && mean_held < mean_loose, "mean {mean_held}, max {max_held}");
    }

    #[test]
    fn the_signed_rank_selection_keeps_a_large_gain_that_heavy_tails_hide_from_a_t_test() {
        let (design, effect) = heavy_tailed_shape(200);
        let fold = super::super::fold_assignment(200, 5, 3);
        let blocks = [(std::slice::from_ref(&effect), None)];
        let loose = Pool::new(&design, &prior(1e6), &blocks, &fold, 5, &PriorOptions::default());
        let model = effects::IdentifiedEffect::Thermal(effects::ThermalTerm {
            reference_c: 20.0,
            scale: vec![1.0],
            theta: vec![0.0],
            fitted_span: None,
            beyond_span: effects::BeyondSpan::Hold,
        });
        let term = Term {
            effect: Effect::JointCompliance,
            joints: vec![2],
            columns: vec![12],
            per_fold: None,
            orders: None,
            model,
        };
        let selection = select(&loose, std::slice::from_ref(&term), &Default::default()).unwrap();
        assert_eq!(selection.steps.len(), 1, "the effect is kept despite the exploding poses");
        // The paired t on squared errors that used to decide sees mostly the two exploding poses.
        let before: Vec<f64> = selection.baseline.errors.iter().map(|e| e * e).collect();
        let after: Vec<f64> = selection.steps[0].scored.result.errors.iter().map(|e| e * e).collect();
        let d: Vec<f64> = before.iter().zip(&after).map(|(a, b)| a - b).collect();
        let m = mean(&d);
        let sd = (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (d.len() - 1) as f64).sqrt();
        let t = m / (sd / (d.len() as f64).sqrt());
        assert!(t < selection.critical_z, "t = {t}");
        assert!(selection.steps[0].z > selection.critical_z);
    }

    #[test]
    fn a_gram_entry_does_not_depend_on_the_other_columns() {
        // 701 rows: more than one block of the product's depth; widths that leave partial tiles.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let x = Mat::<f64>::from_fn(701, 45, |_, _| normal(&mut rng));
        let mut full = Mat::<f64>::zeros(45, 45);
        matmul(full.as_mut(), Accum::Replace, x.transpose(), x.as_ref(), 1.0, Par::Seq);
        let g = gram(x.as_ref());
        let bits = |m: &Mat<f64>, i: usize, j: usize| m[(i, j)].to_bits();
        for i in 0..45 {
            for j in 0..45 {
                assert_eq!(bits(&g, i, j), bits(&full, i, j), "({i}, {j}) against the full product");
            }
        }
        // A subset of the columns, in order: the same entries, whatever tiles they now fall in.
        let subset: Vec<usize> = (0..45).filter(|c| c % 3 != 1 || *c > 40).collect();
        let sub = gram(Mat::<f64>::from_fn(701, subset.len(), |r, c| x[(r, subset[c])]).as_ref());
        for (i, &a) in subset.iter().enumerate() {
            for (j, &b) in subset.iter().enumerate() {
                assert_eq!(bits(&sub, i, j), bits(&g, a, b), "columns ({a}, {b}) in the subset");
            }
        }
    }

    #[test]
    fn nested_prefix_solves_equal_direct_solves_of_the_leading_columns() {
        let (design, effect) = heavy_tailed_shape(60);
        let fold = super::super::fold_assignment(60, 5, 1);
        let blocks = [(std::slice::from_ref(&effect), None)];
        let pool = Pool::new(&design, &prior(1.0), &blocks, &fold, 5, &PriorOptions::default());
        let columns: Vec<usize> = (0..13).collect();
        let (factor, rhs) = pool.factor(&[1, 3], &columns).unwrap();
        for m in [4, 9, 13] {
            let nested = factor.solve_prefix(m, &rhs);
            let direct = pool.solve(&[3, 1], &columns[..m]).unwrap();
            for (a, b) in nested.iter().zip(&direct) {
                assert!((a - b).abs() < 1e-9 * (1.0 + b.abs()), "{m}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn a_factorisation_that_fails_is_an_error_not_a_zero_step() {
        let (design, mut effect) = heavy_tailed_shape(60);
        effect[5] = f64::NAN;
        let fold = super::super::fold_assignment(60, 5, 1);
        let blocks = [(std::slice::from_ref(&effect), None)];
        let pool = Pool::new(&design, &prior(1.0), &blocks, &fold, 5, &PriorOptions::default());
        let error = pool.solve(&[0], &(0..13).collect::<Vec<_>>()).unwrap_err();
        assert!(matches!(error.kind::<ErrorKind>(), Some(ErrorKind::DiagnoseSolve { columns: 13, .. })), "{error}");
        assert!(pool.solve(&[0], &(0..12).collect::<Vec<_>>()).is_ok(), "the kinematic columns alone are fine");
    }
}
