//! The log marginal likelihood of a zero-mean GP and its analytic gradient in log-parameters.
//!
//! For `m` output columns sharing one kernel (independent given the kernel),
//! `ln p(Y | X) = Σ_c [−½ y_cᵀ K⁻¹ y_c] − (m/2) ln |K| − (n m / 2) ln 2π` (R&W Eq. 2.30 summed over
//! columns) and `∂/∂θⱼ = ½ tr((A Aᵀ − m K⁻¹) ∂K/∂θⱼ)` with `A = K⁻¹ Y` (R&W Eq. 5.9).

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::cholesky::{Factor, factor_in_place};
use crate::config::Parallelism;
use crate::gram::{contract_gradient, training_covariance, training_covariance_with_cache};
use crate::kernel::Kernel;
use crate::points::Points;

/// The log marginal likelihood and, if asked for, its gradient in the kernel's log-parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LogMarginalLikelihood {
    /// `ln p(Y | X, θ)`, summed over output columns.
    pub value: f64,
    /// `∂ ln p / ∂ ln θⱼ` in [`Kernel::log_parameters`] order (empty when not requested).
    pub gradient: Vec<f64>,
}

/// The log marginal likelihood of `y` (n × m, one GP per column, all with `kernel`) at inputs `x`
/// (n × d), used as given: no standardisation, no jitter.
///
/// Fails with [`Error::CholeskyFailed`] when `K + σn² I` is not numerically positive definite.
pub fn log_marginal_likelihood(
    kernel: &Kernel,
    x: MatRef<'_, f64>,
    y: MatRef<'_, f64>,
    with_gradient: bool,
    parallelism: Parallelism,
) -> Result<LogMarginalLikelihood, Error> {
    if x.nrows() != y.nrows() {
        return Err(Error::RowCountMismatch { input_rows: x.nrows(), output_rows: y.nrows() });
    }
    kernel.validate(x.ncols())?;
    let points = Points::from_rows(x)?;
    check_finite_outputs(y)?;
    evaluate(kernel, &points, y, with_gradient, parallelism)
}

pub(crate) fn check_finite_outputs(y: MatRef<'_, f64>) -> Result<(), Error> {
    for j in 0..y.ncols() {
        for i in 0..y.nrows() {
            if !y[(i, j)].is_finite() {
                return Err(Error::NonFiniteData { row: i, column: j, in_outputs: true });
            }
        }
    }
    Ok(())
}

/// The work horse of [`log_marginal_likelihood`] on validated points.
pub(crate) fn evaluate(
    kernel: &Kernel,
    x: &Points,
    y: MatRef<'_, f64>,
    with_gradient: bool,
    parallelism: Parallelism,
) -> Result<LogMarginalLikelihood, Error> {
    let par = parallelism.faer();
    let (n, m) = (y.nrows(), y.ncols());
    let (evaluator, prepared) = kernel.prepare(x);
    let noise = kernel.noise_variance();
    let (k, cache) = if with_gradient {
        let (k, cache) = training_covariance_with_cache(&evaluator, &prepared, noise, parallelism);
        (k, Some(cache))
    } else {
        (training_covariance(&evaluator, &prepared, noise, parallelism), None)
    };
    let factor = factor_in_place(k, par).map(Factor::from_lower).map_err(|pivot| Error::CholeskyFailed {
        size: n,
        pivot,
        jitter_tried: 0.0,
    })?;
    let mut alpha = y.to_owned();
    factor.solve_in_place(alpha.as_mut(), par);
    let data_fit: f64 = (0..m).map(|c| (0..n).map(|i| y[(i, c)] * alpha[(i, c)]).sum::<f64>()).sum();
    let value = -0.5 * data_fit
        - 0.5 * m as f64 * factor.log_determinant()
        - 0.5 * (n * m) as f64 * (2.0 * std::f64::consts::PI).ln();
    let gradient = if let Some(cache) = cache {
        let mut w: Mat<f64> = factor.inverse_lower(par);
        let scale = -(m as f64);
        for j in 0..n {
            for i in j..n {
                w[(i, j)] *= scale;
            }
        }
        // W = A Aᵀ − m K⁻¹; only the lower triangle is read by the contraction.
        matmul(w.as_mut(), Accum::Add, alpha.as_ref(), alpha.transpose(), 1.0, par);
        contract_gradient(&evaluator, &prepared, w.as_ref(), &cache, noise, kernel.parameter_count() - 1, parallelism)
    } else {
        Vec::new()
    };
    Ok(LogMarginalLikelihood { value, gradient })
}
