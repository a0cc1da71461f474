//! Leave-one-out prediction of the exact GP in closed form (Rasmussen & Williams 2006, Section
//! 5.4.2, Eqs. 5.10–5.12): with `K` the training covariance (noise and jitter included) and
//! `α = K⁻¹ y`, the prediction of row `i` from the other rows, hyperparameters fixed, is
//! `μ₋ᵢ = yᵢ − αᵢ / [K⁻¹]ᵢᵢ` with variance `σ²₋ᵢ = 1 / [K⁻¹]ᵢᵢ`. One inverse of the Cholesky
//! factor (`n³/3` flops) gives every row's, where refitting without each row would cost `n⁴/3`.
//!
//! A GP that interpolates its training points has a training error near zero whatever it has
//! learned; its leave-one-out error is the error on a pose it has not seen, so it is the number to
//! read beside the training error, and its log predictive probability (Eq. 5.11) is a criterion
//! for choosing a kernel that sees overfitting, which the marginal likelihood of a kernel with
//! many length scales can miss at a few hundred poses.
//!
//! Where rows repeat an input (a pose measured twice), leaving one out keeps its twin, and the
//! prediction is the twin's value: [`ExactGp::leave_groups_out`] leaves a whole group out, in the
//! same closed form by blocks (R&W Section 5.4.2 row by row; Sundararajan & Keerthi 2001 for
//! blocks): for a block `I`, `μ_I = y_I − ([K⁻¹]_II)⁻¹ (K⁻¹ y)_I` with covariance `([K⁻¹]_II)⁻¹`.

use faer::prelude::Solve;
use faer::{Mat, Side};

use crate::Error;
use crate::exact::ExactGp;

/// Leave-one-out predictions of every training row, in the original output units.
#[derive(Debug, Clone)]
pub struct LeaveOneOut {
    /// `μ₋ᵢ`, `n × m`: the prediction of row `i` by the GP fitted on the other rows with the same
    /// hyperparameters.
    pub mean: Mat<f64>,
    /// `σ²₋ᵢ`, `n × m`: its predictive variance (noise included, as Eq. 5.10).
    pub variance: Mat<f64>,
    /// Per output, the leave-one-out log predictive probability of the normalised outputs summed
    /// over the rows (R&W Eq. 5.11), so that outputs of different units compare (for groups left
    /// out, each row's marginal density).
    pub log_predictive: Vec<f64>,
}

impl ExactGp {
    /// Every training row predicted from the others in closed form (R&W Eqs. 5.10–5.12), the
    /// hyperparameters kept: what the training error hides when the GP interpolates.
    pub fn leave_one_out(&self) -> Result<LeaveOneOut, Error> {
        let (n, m) = (self.y.nrows(), self.y.ncols());
        let par = self.parallelism.faer();
        let mut mean = Mat::zeros(n, m);
        let mut variance = Mat::zeros(n, m);
        let mut log_predictive_all = vec![0.0; m];
        for c in &self.components {
            let diagonal = c.inverse_diagonal(par);
            if let Some(row) = diagonal.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(Error::LeaveOneOutFailed { size: n, row, value: diagonal[row] });
            }
            let lp = c.log_predictive(&diagonal);
            for (k, &out) in c.outputs.iter().enumerate() {
                let (mu, s) = (self.outputs.mean[out], self.outputs.scale[out]);
                log_predictive_all[out] = lp[k];
                for (i, &kii) in diagonal.iter().enumerate() {
                    let normalised = self.y[(i, out)] - c.alpha[(i, k)] / kii;
                    mean[(i, out)] = normalised * s + mu;
                    variance[(i, out)] = s * s / kii;
                }
            }
        }
        Ok(LeaveOneOut { mean, variance, log_predictive: log_predictive_all })
    }
}

impl ExactGp {
    /// Every training row predicted from the rows outside its group, in closed form, the
    /// hyperparameters kept: `groups` is a partition of the rows (each once), a group the rows
    /// that one held-out measurement would take away together (repeats of one pose). With every
    /// group a single row, the same numbers as [`ExactGp::leave_one_out`].
    pub fn leave_groups_out(&self, groups: &[Vec<usize>]) -> Result<LeaveOneOut, Error> {
        let (n, m) = (self.y.nrows(), self.y.ncols());
        check_partition(groups, n)?;
        let par = self.parallelism.faer();
        let mut mean = Mat::zeros(n, m);
        let mut variance = Mat::zeros(n, m);
        let mut log_predictive_all = vec![0.0; m];
        let half_ln_2pi = 0.5 * (2.0 * std::f64::consts::PI).ln();
        for c in &self.components {
            let inverse = c.factor.inverse_lower(par);
            // [K⁻¹]ᵢⱼ from the columns of L⁻¹ (lower triangular).
            let entry = |i: usize, j: usize| (i.max(j)..n).map(|k| inverse[(k, i)] * inverse[(k, j)]).sum::<f64>();
            let mut lp = vec![0.0; c.outputs.len()];
            for group in groups {
                let g = group.len();
                let block = Mat::from_fn(g, g, |a, b| entry(group[a], group[b]));
                if g == 1 {
                    // A single row as in `leave_one_out`, to the bit.
                    let (i, kii) = (group[0], block[(0, 0)]);
                    if !(kii.is_finite() && kii > 0.0) {
                        return Err(Error::LeaveOneOutFailed { size: n, row: i, value: kii });
                    }
                    for (k, &out) in c.outputs.iter().enumerate() {
                        let (mu, s) = (self.outputs.mean[out], self.outputs.scale[out]);
                        let residual = c.alpha[(i, k)] / kii;
                        mean[(i, out)] = (self.y[(i, out)] - residual) * s + mu;
                        variance[(i, out)] = s * s / kii;
                        lp[k] += 0.5 * kii.ln() - 0.5 * residual * residual * kii - half_ln_2pi;
                    }
                    continue;
                }
                let covariance = block
                    .llt(Side::Lower)
                    .map_err(|_| Error::LeaveOneOutFailed { size: n, row: group[0], value: block[(0, 0)] })?
                    .solve(Mat::<f64>::identity(g, g));
                for (k, &out) in c.outputs.iter().enumerate() {
                    let (mu, s) = (self.outputs.mean[out], self.outputs.scale[out]);
                    for (a, &i) in group.iter().enumerate() {
                        let shift: f64 = (0..g).map(|b| covariance[(a, b)] * c.alpha[(group[b], k)]).sum();
                        let var = covariance[(a, a)];
                        if !(var.is_finite() && var > 0.0) {
                            return Err(Error::LeaveOneOutFailed { size: n, row: i, value: var });
                        }
                        mean[(i, out)] = (self.y[(i, out)] - shift) * s + mu;
                        variance[(i, out)] = s * s * var;
                        lp[k] += -0.5 * var.ln() - 0.5 * shift * shift / var - half_ln_2pi;
                    }
                }
            }
            for (k, &out) in c.outputs.iter().enumerate() {
                log_predictive_all[out] = lp[k];
            }
        }
        Ok(LeaveOneOut { mean, variance, log_predictive: log_predictive_all })
    }
}

/// Each of `0..n` in exactly one group.
fn check_partition(groups: &[Vec<usize>], n: usize) -> Result<(), Error> {
    let mut seen = vec![false; n];
    for &row in groups.iter().flatten() {
        if row >= n || seen[row] {
            return Err(Error::InvalidGroups { rows: n, row });
        }
        seen[row] = true;
    }
    match seen.iter().position(|s| !s) {
        Some(row) => Err(Error::InvalidGroups { rows: n, row }),
        None => Ok(()),
    }
}
