//! Posterior prediction of the exact GP (R&W Algorithm 2.1, Eqs. 2.25–2.26).

use dense::product;
use faer::{Accum, Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::exact::ExactGp;
use crate::gram::{cross_covariance, full_covariance, prior_variances};

/// What to compute besides the mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct PredictOptions {
    /// Compute the variance of each prediction.
    pub variance: bool,
    /// Compute the full posterior covariance between the query points, per output.
    pub full_covariance: bool,
    /// Add the white-noise variance, i.e. predict a new noisy observation `y*` rather than the
    /// latent `f*` (scikit-learn's `predict(return_std=True)` with a `WhiteKernel` does this).
    pub include_noise: bool,
}

impl Default for PredictOptions {
    fn default() -> Self {
        Self { variance: true, full_covariance: false, include_noise: false }
    }
}

/// Posterior at `n*` query points for `m` outputs, in the original output units.
#[derive(Debug, Clone)]
pub struct Prediction {
    /// Posterior mean, `n* × m`.
    pub mean: Mat<f64>,
    /// Posterior variance, `n* × m` (`0 × 0` when not requested).
    pub variance: Mat<f64>,
    /// Posterior covariance between the query points, one `n* × n*` matrix per output (empty when
    /// not requested).
    pub covariance: Vec<Mat<f64>>,
    /// Prior variance of the latent function, `k(x*, x*)`, `n* × m` (with the variance; `0 × 0`
    /// otherwise): [`Prediction::variance`] over it is the share of the prior uncertainty the
    /// training data leave at each query point (1 where they say nothing of it).
    pub prior_variance: Mat<f64>,
}

impl ExactGp {
    /// Posterior mean and variance (latent function, no noise) at the rows of `x` (n* × d).
    pub fn predict(&self, x: MatRef<'_, f64>) -> Result<Prediction, Error> {
        self.predict_with(x, &PredictOptions::default())
    }

    /// Posterior mean only: one cross-covariance and one product, no triangular solve.
    pub fn predict_mean(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
        let options = PredictOptions { variance: false, full_covariance: false, include_noise: false };
        Ok(self.predict_with(x, &options)?.mean)
    }

    /// Posterior at the rows of `x` (n* × d) with the quantities `options` asks for.
    pub fn predict_with(&self, x: MatRef<'_, f64>, options: &PredictOptions) -> Result<Prediction, Error> {
        let z = self.inputs.apply(x)?;
        let par = self.parallelism.faer();
        let (ns, m) = (z.len(), self.output_count());
        let mut mean = Mat::zeros(ns, m);
        let mut variance = if options.variance { Mat::zeros(ns, m) } else { Mat::zeros(0, 0) };
        let mut prior_variance = variance.clone();
        let mut covariance = if options.full_covariance { vec![Mat::zeros(0, 0); m] } else { Vec::new() };
        for c in &self.components {
            let (_, zp) = c.kernel.prepare(&z);
            // K(X, X*), n × n*.
            let mut ks = cross_covariance(&c.evaluator, &c.prepared, &zp, self.parallelism);
            // f̄* = K(X, X*)ᵀ α (R&W Eq. 2.25).
            let mut f = Mat::zeros(ns, c.outputs.len());
            product(f.as_mut(), Accum::Replace, ks.transpose(), c.alpha.as_ref(), 1.0, par);
            let noise = if options.include_noise { c.kernel.noise_variance() } else { 0.0 };
            let needs_v = options.variance || options.full_covariance;
            if needs_v {
                // V = L⁻¹ K(X, X*) (R&W Algorithm 2.1, line 5), in place.
                c.factor.solve_lower_in_place(ks.as_mut(), par);
            }
            let prior = if options.variance { prior_variances(&c.evaluator, &zp) } else { Vec::new() };
            let latent_variance: Vec<f64> = (0..prior.len())
                .map(|j| {
                    let vj = ks.col(j);
                    let explained: f64 = vj.iter().map(|v| v * v).sum();
                    // Round-off can make k** − vᵀv slightly negative at training points.
                    (prior[j] - explained).max(0.0) + noise
                })
                .collect();
            let latent_covariance = options.full_covariance.then(|| {
                // K** − VᵀV (R&W Eq. 2.26).
                let mut cov = full_covariance(&c.evaluator, &zp, self.parallelism);
                product(cov.as_mut(), Accum::Add, ks.transpose(), ks.as_ref(), -1.0, par);
                for i in 0..ns {
                    cov[(i, i)] += noise;
                }
                cov
            });
            for (k, &out) in c.outputs.iter().enumerate() {
                let (mu, s) = (self.outputs.mean[out], self.outputs.scale[out]);
                for i in 0..ns {
                    mean[(i, out)] = f[(i, k)] * s + mu;
                }
                if options.variance {
                    for (i, (v, p)) in latent_variance.iter().zip(&prior).enumerate() {
                        variance[(i, out)] = v * s * s;
                        prior_variance[(i, out)] = p * s * s;
                    }
                }
                if let Some(cov) = &latent_covariance {
                    covariance[out] = Mat::from_fn(ns, ns, |i, j| cov[(i, j)] * s * s);
                }
            }
        }
        Ok(Prediction { mean, variance, covariance, prior_variance })
    }

    /// The prior variance of every output at the rows of `x` (`n × m`, output units², noise
    /// excluded): [`Prediction::prior_variance`] without the cross-covariance and the solves the
    /// posterior needs, `O(n d)` instead of `O(n² N)`.
    pub fn prior_variance(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
        let z = self.inputs.apply(x)?;
        let mut prior_variance = Mat::zeros(z.len(), self.output_count());
        for c in &self.components {
            let (_, zp) = c.kernel.prepare(&z);
            let prior = prior_variances(&c.evaluator, &zp);
            for &out in &c.outputs {
                let s = self.outputs.scale[out];
                for (i, p) in prior.iter().enumerate() {
                    prior_variance[(i, out)] = p * s * s;
                }
            }
        }
        Ok(prior_variance)
    }
}
