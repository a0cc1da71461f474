//! Cross-validation of a fitted GP's hyperparameters on other data, each fold with its own targets:
//! what a GP with these kernels and scaling maps, conditioned on a fold's training rows, predicts
//! at the fold's held-out rows.
//!
//! Holding the hyperparameters fixed across the folds is the standard approximation (R&W Section
//! 5.4.2 does the same for its leave-one-out): searching them again in each fold would repeat the
//! whole search per fold. With them fixed, the prediction of a block `I` of rows from the other
//! rows `T` is, in closed form by blocks (as [`ExactGp::leave_groups_out`]), with `P = K⁻¹` the
//! inverse of the covariance of every row (noise and jitter included):
//! `μ_I = K_IT K_TT⁻¹ y_T = −(P_II)⁻¹ P_IT y_T`, for any targets `y_T`. So each fold may bring its
//! own targets (in cross-validation of a model with stages, each fold's first stage leaves its own
//! residuals), and one factorisation of `K` per kernel serves every fold: `n³/3` flops for the
//! factor and `2n³/3` for `P`, then `O(|I|³ + |I| n)` per fold and output, where refitting each fold
//! would factor its `|T| × |T|` matrix again.

use dense::product;
use faer::prelude::Solve;
use faer::{Accum, Mat, MatRef, Side};
use rayon::prelude::*;

use crate::Error;
use crate::cholesky::Factor;
use crate::config::{GpConfig, Parallelism};
use crate::exact::ExactGp;
use crate::gram::training_covariance;

/// One fold: the rows it holds out and the targets of the others.
#[derive(Debug, Clone, Copy)]
pub struct FoldTargets<'a> {
    /// The held-out rows (indices into the inputs), each once.
    pub held_out: &'a [usize],
    /// `n × m` outputs, in the GP's original units, that the fold's training rows are conditioned
    /// on (the held-out rows' entries are not read).
    pub y: MatRef<'a, f64>,
}

impl ExactGp {
    /// For each fold of `folds` over the rows of `x` (`n × d`, raw inputs), the posterior mean at
    /// its held-out rows (`|held_out| × m`, original units, in the order of `held_out`) of this
    /// GP's kernels, input standardisation and output normalisation conditioned on the fold's
    /// other rows and their targets, the hyperparameters held fixed. Only the kernels serving one
    /// of `outputs` are factored; the other outputs' columns are 0. The jitter escalates as
    /// `config.jitter` says, on the covariance of every row of `x`.
    pub fn held_out_with_fixed_hyperparameters(
        &self,
        x: MatRef<'_, f64>,
        folds: &[FoldTargets<'_>],
        outputs: &[usize],
        config: &GpConfig,
    ) -> Result<Vec<Mat<f64>>, Error> {
        let z = self.inputs.apply(x)?;
        let (n, m) = (z.len(), self.output_count());
        for fold in folds {
            if fold.y.nrows() != n {
                return Err(Error::RowCountMismatch { input_rows: n, output_rows: fold.y.nrows() });
            }
            if fold.y.ncols() != m {
                return Err(Error::InvalidConfig { field: "fold outputs", value: fold.y.ncols() as f64 });
            }
            let mut seen = vec![false; n];
            for &row in fold.held_out {
                if row >= n || seen[row] {
                    return Err(Error::InvalidGroups { rows: n, row });
                }
                seen[row] = true;
            }
        }
        let par = self.parallelism.faer();
        let mut out: Vec<Mat<f64>> = folds.iter().map(|f| Mat::zeros(f.held_out.len(), m)).collect();
        for c in self.components.iter().filter(|c| c.outputs.iter().any(|o| outputs.contains(o))) {
            let (evaluator, prepared) = c.kernel.prepare(&z);
            let k = training_covariance(&evaluator, &prepared, c.kernel.noise_variance(), self.parallelism);
            let (factor, _) = Factor::with_jitter(&k, &config.jitter, par)?;
            drop(k);
            let p = factor.inverse(par);
            // `P_IT y_T` of every fold and output at once: one product of `P` with every fold's
            // normalised targets, its held-out rows set to 0 (so that they add nothing), in place
            // of a sum over the training rows per held-out row (`|I| n` scalar steps per fold and
            // output, most of the time here at n = 2,773 and 70 folds).
            let served = c.outputs.len();
            let mut targets = Mat::<f64>::zeros(n, folds.len() * served);
            for (f, fold) in folds.iter().enumerate() {
                for (k, &output) in c.outputs.iter().enumerate() {
                    let (mu, s) = (self.outputs.mean[output], self.outputs.scale[output]);
                    let column = targets.col_as_slice_mut(f * served + k);
                    for (j, t) in column.iter_mut().enumerate() {
                        *t = (fold.y[(j, output)] - mu) / s;
                    }
                    for &i in fold.held_out {
                        column[i] = 0.0;
                    }
                }
            }
            let mut weighted = Mat::<f64>::zeros(n, targets.ncols());
            product(weighted.as_mut(), Accum::Replace, p.as_ref(), targets.as_ref(), 1.0, par);
            let solve = |(f, fold): (usize, &FoldTargets<'_>)| -> Result<Vec<Vec<f64>>, Error> {
                let held = fold.held_out;
                let h = held.len();
                if h == 0 {
                    return Ok(Vec::new());
                }
                let block = Mat::from_fn(h, h, |a, b| p[(held[a], held[b])]);
                let llt = block.llt(Side::Lower).map_err(|_| Error::LeaveOneOutFailed {
                    size: n,
                    row: held[0],
                    value: block[(0, 0)],
                })?;
                Ok((0..served)
                    .map(|k| {
                        let rhs = Mat::from_fn(h, 1, |a, _| weighted[(held[a], f * served + k)]);
                        let shift = llt.solve(rhs);
                        (0..h).map(|a| shift[(a, 0)]).collect()
                    })
                    .collect())
            };
            let solved: Vec<Result<Vec<Vec<f64>>, Error>> = match self.parallelism {
                Parallelism::Sequential => folds.iter().enumerate().map(solve).collect(),
                Parallelism::Rayon => folds.par_iter().enumerate().map(solve).collect(),
            };
            for ((mean, shifts), fold) in out.iter_mut().zip(solved).zip(folds) {
                for (k, shift) in shifts?.into_iter().enumerate() {
                    let out = c.outputs[k];
                    let (mu, s) = (self.outputs.mean[out], self.outputs.scale[out]);
                    for a in 0..fold.held_out.len() {
                        mean[(a, out)] = -shift[a] * s + mu;
                    }
                }
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Kernel, KernelChoice};

    fn data(n: usize) -> (Mat<f64>, Mat<f64>) {
        let x = Mat::from_fn(n, 2, |i, j| ((i * 7 + j * 3) % 11) as f64 * 0.3 + 0.01 * i as f64);
        let y = Mat::from_fn(n, 2, |i, j| (x[(i, 0)] + j as f64).sin() + 0.5 * x[(i, 1)].cos());
        (x, y)
    }

    fn config(standardise: bool) -> GpConfig {
        GpConfig { standardise_inputs: standardise, normalise_outputs: standardise, ..GpConfig::default() }
    }

    #[test]
    fn a_fold_is_predicted_as_the_gp_refitted_on_its_training_rows_with_the_same_hyperparameters() {
        let (x, y) = data(40);
        let kernel = Kernel::start(KernelChoice::default(), 2);
        // Identity maps, so that a GP fitted on the training rows alone has the same ones.
        let cfg = config(false);
        let gp = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), std::slice::from_ref(&kernel), &cfg).unwrap();
        // Other targets than the GP's own: each fold brings its own.
        let targets = Mat::from_fn(40, 2, |i, j| y[(i, j)] * 0.5 + 0.1 * (i % 3) as f64);
        let held: Vec<usize> = (5..17).collect();
        let folds = [FoldTargets { held_out: &held, y: targets.as_ref() }];
        let got = gp.held_out_with_fixed_hyperparameters(x.as_ref(), &folds, &[0, 1], &cfg).unwrap();
        let train: Vec<usize> = (0..40).filter(|i| !held.contains(i)).collect();
        let xt = Mat::from_fn(train.len(), 2, |a, j| x[(train[a], j)]);
        let yt = Mat::from_fn(train.len(), 2, |a, j| targets[(train[a], j)]);
        let xh = Mat::from_fn(held.len(), 2, |a, j| x[(held[a], j)]);
        let refit = ExactGp::fit_fixed(xt.as_ref(), yt.as_ref(), std::slice::from_ref(&kernel), &cfg).unwrap();
        let expected = refit.predict_mean(xh.as_ref()).unwrap();
        for a in 0..held.len() {
            for j in 0..2 {
                assert!((got[0][(a, j)] - expected[(a, j)]).abs() < 1e-8, "{a},{j}");
            }
        }
        // Had the held-out rows' own targets been seen, the prediction would be near them: it is not.
        let with_own = gp.predict_mean(xh.as_ref()).unwrap();
        let gap: f64 = (0..held.len()).map(|a| (got[0][(a, 0)] - with_own[(a, 0)]).abs()).sum();
        assert!(gap > 1e-3, "{gap}");
    }

    #[test]
    fn outputs_not_asked_for_are_zero_and_bad_folds_are_refused() {
        let (x, y) = data(30);
        let gp = ExactGp::fit(x.as_ref(), y.as_ref(), &config(true)).unwrap();
        let held = [1, 2, 3];
        let folds = [FoldTargets { held_out: &held, y: y.as_ref() }];
        let got = gp.held_out_with_fixed_hyperparameters(x.as_ref(), &folds, &[1], &config(true)).unwrap();
        assert!((0..3).all(|a| got[0][(a, 0)] == 0.0 && got[0][(a, 1)] != 0.0));
        let repeated = [1, 1];
        let bad = [FoldTargets { held_out: &repeated, y: y.as_ref() }];
        assert!(matches!(
            gp.held_out_with_fixed_hyperparameters(x.as_ref(), &bad, &[0], &config(true)),
            Err(Error::InvalidGroups { row: 1, .. })
        ));
        let short = Mat::<f64>::zeros(29, 2);
        let bad = [FoldTargets { held_out: &held, y: short.as_ref() }];
        assert!(gp.held_out_with_fixed_hyperparameters(x.as_ref(), &bad, &[0], &config(true)).is_err());
    }
}
