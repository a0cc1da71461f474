//! Cholesky factorisation of a kernel matrix on faer with explicit parallelism, with jitter
//! escalation when a pivot is not positive, and the solves built on it.

use dense::{FactorOptions, cholesky_lower_in_place};
use faer::{Mat, MatMut, Par};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::config::JitterConfig;
use dense::{solve_lower, solve_upper_transposed};

/// `K + jitter·I = L Lᵀ` (the jitter is recorded by the caller in a [`JitterOutcome`]).
#[derive(Debug, Clone)]
pub struct Factor {
    /// Lower-triangular factor; the strict upper triangle is zero.
    l: Mat<f64>,
}

/// What the jitter escalation did, for the fit report.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JitterOutcome {
    /// Absolute jitter added to the diagonal of the kernel matrix (normalised output units²).
    pub added: f64,
    /// Failed attempts before the one that succeeded.
    pub failed_attempts: usize,
}

/// Factors the lower triangle of `a` in place; on failure returns the index of the first pivot that
/// was not positive.
pub(crate) fn factor_in_place(mut a: Mat<f64>, par: Par) -> Result<Mat<f64>, usize> {
    let n = a.nrows();
    cholesky_lower_in_place(a.as_mut(), &FactorOptions::default(), par)?;
    for j in 1..n {
        a.col_mut(j).subrows_mut(0, j).fill(0.0);
    }
    Ok(a)
}

impl Factor {
    /// Factors `k` (lower triangle read) as it is, then with growing jitter on the diagonal until
    /// it succeeds or [`JitterConfig::max_attempts`] is exhausted.
    pub fn with_jitter(k: &Mat<f64>, config: &JitterConfig, par: Par) -> Result<(Self, JitterOutcome), Error> {
        let n = k.nrows();
        let mut pivot = match factor_in_place(k.clone(), par) {
            Ok(l) => return Ok((Self { l }, JitterOutcome { added: 0.0, failed_attempts: 0 })),
            Err(pivot) => pivot,
        };
        let mean_diagonal = (0..n).map(|i| k[(i, i)].abs()).sum::<f64>() / n.max(1) as f64;
        let base = if mean_diagonal.is_finite() && mean_diagonal > 0.0 { mean_diagonal } else { 1.0 };
        let mut jitter = config.initial_relative * base;
        let mut tried = 0.0;
        for attempt in 1..=config.max_attempts {
            match Self::with_fixed_jitter(k, jitter, par) {
                Ok(factor) => return Ok((factor, JitterOutcome { added: jitter, failed_attempts: attempt })),
                Err(Error::CholeskyFailed { pivot: p, .. }) => pivot = p,
                Err(other) => return Err(other),
            }
            tried = jitter;
            jitter *= config.growth;
        }
        Err(Error::CholeskyFailed { size: n, pivot, jitter_tried: tried })
    }

    /// Factors `k + jitter·I` once (used to rebuild a stored model with its recorded jitter).
    pub fn with_fixed_jitter(k: &Mat<f64>, jitter: f64, par: Par) -> Result<Self, Error> {
        let n = k.nrows();
        let mut a = k.clone();
        for i in 0..n {
            a[(i, i)] += jitter;
        }
        factor_in_place(a, par).map(|l| Self { l }).map_err(|pivot| Error::CholeskyFailed {
            size: n,
            pivot,
            jitter_tried: jitter,
        })
    }

    /// A factor read back from storage: lower triangular (the upper triangle is ignored), every
    /// entry finite, a positive diagonal; otherwise the index of the first bad pivot.
    pub fn from_lower(mut l: Mat<f64>) -> Result<Self, usize> {
        let n = l.nrows();
        for j in 0..n {
            if !(l[(j, j)] > 0.0 && l[(j, j)].is_finite()) || (j..n).any(|i| !l[(i, j)].is_finite()) {
                return Err(j);
            }
            l.col_mut(j).subrows_mut(0, j).fill(0.0);
        }
        Ok(Self { l })
    }

    /// The lower-triangular factor.
    pub fn lower(&self) -> &Mat<f64> {
        &self.l
    }

    /// `L⁻¹`, lower triangular (the strict upper triangle 0), in `n³/3` flops.
    pub(crate) fn inverse_lower(&self, par: Par) -> Mat<f64> {
        let n = self.l.nrows();
        let mut inverse = Mat::<f64>::zeros(n, n);
        faer::linalg::triangular_inverse::invert_lower_triangular(inverse.as_mut(), self.l.as_ref(), par);
        inverse
    }

    /// `K⁻¹ = L⁻ᵀ L⁻¹` in full (both triangles): `2n³/3` flops, the lower triangle by one
    /// triangular product, then mirrored.
    pub(crate) fn inverse(&self, par: Par) -> Mat<f64> {
        use faer::linalg::matmul::triangular::{self, BlockStructure};
        let n = self.l.nrows();
        let lower = self.inverse_lower(par);
        let mut inverse = Mat::<f64>::zeros(n, n);
        triangular::matmul(
            inverse.as_mut(),
            BlockStructure::TriangularLower,
            faer::Accum::Replace,
            lower.transpose(),
            BlockStructure::TriangularUpper,
            lower.as_ref(),
            BlockStructure::TriangularLower,
            1.0,
            par,
        );
        for j in 1..n {
            for i in 0..j {
                inverse[(i, j)] = inverse[(j, i)];
            }
        }
        inverse
    }

    /// `rhs ← L⁻¹ rhs`.
    pub fn solve_lower_in_place(&self, rhs: MatMut<'_, f64>, par: Par) {
        solve_lower(self.l.as_ref(), rhs, par);
    }

    /// `rhs ← L⁻ᵀ rhs`.
    pub fn solve_upper_transposed_in_place(&self, rhs: MatMut<'_, f64>, par: Par) {
        solve_upper_transposed(self.l.as_ref(), rhs, par);
    }

    /// `rhs ← (L Lᵀ)⁻¹ rhs` (R&W Algorithm 2.1, line 3).
    pub fn solve_in_place(&self, mut rhs: MatMut<'_, f64>, par: Par) {
        solve_lower(self.l.as_ref(), rhs.as_mut(), par);
        solve_upper_transposed(self.l.as_ref(), rhs, par);
    }

    /// `ln |L Lᵀ| = 2 Σ ln Lᵢᵢ`.
    pub fn log_determinant(&self) -> f64 {
        2.0 * (0..self.l.nrows()).map(|i| self.l[(i, i)].ln()).sum::<f64>()
    }
}
