//! The log marginal likelihood of a zero-mean GP and its analytic gradient in log-parameters.
//!
//! For `m` output columns sharing one kernel (independent given the kernel),
//! `ln p(Y | X) = Σ_c [−½ y_cᵀ K⁻¹ y_c] − (m/2) ln |K| − (n m / 2) ln 2π` (R&W Eq. 2.30 summed over
//! columns) and `∂/∂θⱼ = ½ tr((A Aᵀ − m K⁻¹) ∂K/∂θⱼ)` with `A = K⁻¹ Y` (R&W Eq. 5.9).
//!
//! One evaluation with the gradient costs `n³` flops: the Cholesky factor (`n³/3`, by halves, see
//! [`FactorOptions`]), its inverse (`n³/3`) and `K⁻¹ = L⁻ᵀ L⁻¹` (`n³/3`, lower triangle only), all
//! in two `n × n` buffers that a search reuses from one evaluation to the next ([`LmlWorkspace`]).
//! `cargo xtask bench-gp --lml-floor 3000` times it against faer's matrix product doing `n³` flops.

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::triangular_inverse;
use faer::{Accum, Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::config::Parallelism;
use crate::gram::{contract_gradient, fill_training_lower};
use crate::kernel::{Evaluator, Kernel, Prepared};
use crate::points::Points;
use dense::{FactorOptions, cholesky_lower_in_place};
use dense::{solve_lower, solve_upper_transposed};

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
/// Allocates the two `n × n` buffers of the evaluation; a caller that evaluates many times keeps
/// them in an [`LmlWorkspace`] instead.
pub fn log_marginal_likelihood(
    kernel: &Kernel,
    x: MatRef<'_, f64>,
    y: MatRef<'_, f64>,
    with_gradient: bool,
    parallelism: Parallelism,
) -> Result<LogMarginalLikelihood, Error> {
    LmlWorkspace::default().log_marginal_likelihood(kernel, x, y, with_gradient, parallelism)
}

/// Refuses a NaN or infinite output, naming its row and column.
pub fn check_finite_outputs(y: MatRef<'_, f64>) -> Result<(), Error> {
    for j in 0..y.ncols() {
        for i in 0..y.nrows() {
            if !y[(i, j)].is_finite() {
                return Err(Error::NonFiniteData { row: i, column: j, in_outputs: true });
            }
        }
    }
    Ok(())
}

/// The two `n × n` buffers of an evaluation, kept from one evaluation to the next (as the
/// hyperparameter search does): at n = 3,000 they are 144 MB, and the page faults of allocating
/// them afresh cost as much as a tenth of the evaluation. Also holds what the value stage leaves
/// for the gradient stage (the factor, the weights, the prepared inputs).
#[derive(Debug)]
pub struct LmlWorkspace {
    options: FactorOptions,
    factor: Mat<f64>,
    inverse: Mat<f64>,
    /// The kernel's exponentials from the value stage, for the gradient stage
    /// ([`crate::gram::cache_len`]), where they fit in [`LmlWorkspace::cache_budget_bytes`].
    cache: Vec<f64>,
    /// [`crate::OptimiserConfig::kernel_cache_bytes`].
    cache_budget_bytes: usize,
    /// Set by a successful [`evaluate_value`], taken by [`evaluate_gradient`].
    last: Option<LastValue>,
}

pub(crate) type Workspace = LmlWorkspace;

#[derive(Debug)]
struct LastValue {
    kernel: Kernel,
    evaluator: Evaluator,
    prepared: Prepared,
    alpha: Mat<f64>,
    /// Whether `cache` holds this point's exponentials.
    cached: bool,
}

impl Default for LmlWorkspace {
    fn default() -> Self {
        Self {
            options: FactorOptions::default(),
            factor: Mat::new(),
            inverse: Mat::new(),
            cache: Vec::new(),
            cache_budget_bytes: crate::OptimiserConfig::default().kernel_cache_bytes,
            last: None,
        }
    }
}

impl LmlWorkspace {
    /// An empty workspace whose factorisations use `options` (validated here).
    pub fn with_options(options: FactorOptions) -> Result<Self, Error> {
        options.validate().map_err(|field| Error::InvalidConfig { field, value: 0.0 })?;
        Ok(Self { options, ..Self::default() })
    }

    /// The same workspace keeping at most `bytes` of the kernel's exponentials between the value
    /// and the gradient stage ([`crate::OptimiserConfig::kernel_cache_bytes`]; 0: none).
    pub fn with_cache_budget(self, bytes: usize) -> Self {
        Self { cache_budget_bytes: bytes, ..self }
    }

    /// [`log_marginal_likelihood`] in this workspace's buffers (grown or shrunk to `n × n` as
    /// needed); the result does not depend on what the workspace held before.
    pub fn log_marginal_likelihood(
        &mut self,
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
        let value = evaluate_value(self, kernel, &points, y, parallelism)?;
        let gradient = if with_gradient { evaluate_gradient(self, points.dim(), parallelism) } else { Vec::new() };
        Ok(LogMarginalLikelihood { value, gradient })
    }
}

/// The value stage: `K + σn² I = L Lᵀ` (`n³/3` flops) and `α = K⁻¹ Y`; the factor stays in the
/// workspace so that [`evaluate_gradient`] can follow without factoring again. A line search that
/// rejects a trial point pays only this stage.
pub(crate) fn evaluate_value(
    workspace: &mut Workspace,
    kernel: &Kernel,
    x: &Points,
    y: MatRef<'_, f64>,
    parallelism: Parallelism,
) -> Result<f64, Error> {
    let par = parallelism.faer();
    let (n, m) = (y.nrows(), y.ncols());
    workspace.last = None;
    let terms = kernel.terms(x.dim());
    let prepared = terms.prepare(x);
    let evaluator = terms.evaluator;
    if workspace.factor.nrows() != n {
        workspace.factor = Mat::zeros(n, n);
    }
    let cache = match crate::gram::cache_len(&evaluator, &prepared, workspace.cache_budget_bytes) {
        Some(len) => {
            workspace.cache.resize(len, 0.0);
            Some(workspace.cache.as_mut_slice())
        }
        None => None,
    };
    let cached = cache.is_some();
    let factor = &mut workspace.factor;
    fill_training_lower(factor.as_mut(), &evaluator, &prepared, evaluator.noise_variance, cache, parallelism);
    cholesky_lower_in_place(factor.as_mut(), &workspace.options, par).map_err(|pivot| Error::CholeskyFailed {
        size: n,
        pivot,
        jitter_tried: 0.0,
    })?;
    let log_determinant = 2.0 * (0..n).map(|i| factor[(i, i)].ln()).sum::<f64>();
    let mut alpha = y.to_owned();
    solve_lower(factor.as_ref(), alpha.as_mut(), par);
    solve_upper_transposed(factor.as_ref(), alpha.as_mut(), par);
    let data_fit: f64 = (0..m).map(|c| (0..n).map(|i| y[(i, c)] * alpha[(i, c)]).sum::<f64>()).sum();
    let value =
        -0.5 * data_fit - 0.5 * m as f64 * log_determinant - 0.5 * (n * m) as f64 * (2.0 * std::f64::consts::PI).ln();
    workspace.last = Some(LastValue { kernel: kernel.clone(), evaluator, prepared, alpha, cached });
    Ok(value)
}

/// The gradient stage at the point of the last successful [`evaluate_value`] (empty if there was
/// none): `L⁻¹` (`n³/3`), the lower triangle of `K⁻¹ = L⁻ᵀ L⁻¹` (`n³/3`) over the factor, and one
/// contraction for every parameter (R&W Eq. 5.9).
pub(crate) fn evaluate_gradient(workspace: &mut Workspace, dim: usize, parallelism: Parallelism) -> Vec<f64> {
    let par = parallelism.faer();
    let Some(LastValue { kernel, evaluator, prepared, alpha, cached }) = workspace.last.take() else {
        return Vec::new();
    };
    let n = alpha.nrows();
    if workspace.inverse.nrows() != n {
        workspace.inverse = Mat::zeros(n, n);
    }
    let Workspace { factor, inverse, cache, .. } = workspace;
    triangular_inverse::invert_lower_triangular(inverse.as_mut(), factor.as_ref(), par);
    triangular::matmul(
        factor.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        inverse.transpose(),
        BlockStructure::TriangularUpper,
        inverse.as_ref(),
        BlockStructure::TriangularLower,
        1.0,
        par,
    );
    let cache = cached.then_some(cache.as_mut_slice());
    let expanded =
        contract_gradient(&evaluator, &prepared, factor.as_mut(), alpha.as_ref(), inverse.as_mut(), cache, parallelism);
    kernel.fold_gradient(&expanded, dim)
}
