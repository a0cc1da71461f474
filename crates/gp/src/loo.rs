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

use faer::Mat;

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
    /// over the rows (R&W Eq. 5.11), so that outputs of different units compare.
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
