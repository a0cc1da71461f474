//! The linear algebra of one iteration: the SVD pseudo-inverse of the paper's update, and the
//! damped normal equations of Levenberg–Marquardt with a prior.

use super::reduced::Reduced;
use crate::Error;
use faer::prelude::Solve;
use faer::{Mat, Side};

/// Singular value decomposition of the weighted Jacobian, taken of its QR triangle ([`Reduced`]):
/// the same singular values and right vectors, and `U` only `p × p`.
pub(super) struct Decomposition {
    pub singular_values: Vec<f64>,
    u: Mat<f64>,
    v: Mat<f64>,
}

impl Decomposition {
    pub(super) fn new(reduced: &Reduced, iteration: usize) -> Result<Self, Error> {
        let svd = reduced.r.thin_svd().map_err(|_| Error::LinearSolveFailed { iteration, decomposition: "SVD" })?;
        let s = svd.S().column_vector();
        Ok(Self {
            singular_values: (0..s.nrows()).map(|i| s[i]).collect(),
            u: svd.U().to_owned(),
            v: svd.V().to_owned(),
        })
    }

    /// `x = A⁺ y = R⁺ z` with the directions below `rcond · σ_max` dropped (the paper's
    /// pseudo-inverse), `z = Qᵀy` of [`Reduced`].
    pub(super) fn pseudo_inverse_solve(&self, y: &[f64], rcond: f64) -> Vec<f64> {
        let threshold = rcond * self.singular_values.first().copied().unwrap_or(0.0);
        let mut x = vec![0.0; self.v.nrows()];
        for (k, &sigma) in self.singular_values.iter().enumerate() {
            if sigma <= threshold || sigma == 0.0 {
                continue;
            }
            let uty: f64 = (0..y.len()).map(|i| self.u[(i, k)] * y[i]).sum();
            let scale = uty / sigma;
            for (j, xj) in x.iter_mut().enumerate() {
                *xj += scale * self.v[(j, k)];
            }
        }
        x
    }
}

/// The normal equations of `‖y − A δ‖² + Σ_j (w_j (d_j + δ_j))²`: `H = AᵀA + diag(w²)` and
/// `g = Aᵀy − w² ∘ d` (the prior pulls the deviation `d` from the start back to zero).
pub(super) struct Normal {
    pub h: Mat<f64>,
    pub g: Vec<f64>,
}

impl Normal {
    pub(super) fn new(reduced: &Reduced, prior_weights: &[f64], deviation: &[f64]) -> Self {
        let mut h = reduced.gram();
        let mut g = reduced.gradient();
        for (j, (&w, &d)) in prior_weights.iter().zip(deviation).enumerate() {
            h[(j, j)] += w * w;
            g[j] -= w * w * d;
        }
        Self { h, g }
    }

    /// Solves `(H + λ D) δ = g`, `D = diag(H)` floored so that a column no row sees stays definite
    /// (Marquardt's scaling: the damping acts alike on parameters of any unit).
    pub(super) fn damped_solve(&self, lambda: f64) -> Option<Vec<f64>> {
        let p = self.h.nrows();
        let largest = (0..p).map(|i| self.h[(i, i)]).fold(0.0_f64, f64::max);
        let floor = largest * 1e-15 + f64::MIN_POSITIVE;
        let mut damped = self.h.clone();
        for i in 0..p {
            damped[(i, i)] += lambda * self.h[(i, i)].max(floor);
        }
        let llt = damped.llt(Side::Lower).ok()?;
        let x = llt.solve(Mat::<f64>::from_fn(p, 1, |i, _| self.g[i]));
        let x: Vec<f64> = (0..p).map(|i| x[(i, 0)]).collect();
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// The decrease of the quadratic model for a step: `2 δᵀg − δᵀHδ`.
    pub(super) fn predicted_decrease(&self, step: &[f64]) -> f64 {
        let p = step.len();
        let mut quadratic = 0.0;
        for i in 0..p {
            let hi: f64 = (0..p).map(|j| self.h[(i, j)] * step[j]).sum();
            quadratic += step[i] * hi;
        }
        2.0 * step.iter().zip(&self.g).map(|(s, g)| s * g).sum::<f64>() - quadratic
    }

    /// The posterior variance of each parameter, `diag(H⁻¹)`, where `H` is definite.
    pub(super) fn posterior_variances(&self) -> Option<Vec<f64>> {
        let inverse = self.inverse()?;
        Some((0..inverse.nrows()).map(|i| inverse[(i, i)]).collect())
    }

    /// `H⁻¹`, where `H` is definite.
    pub(super) fn inverse(&self) -> Option<Mat<f64>> {
        let p = self.h.nrows();
        let llt = self.h.llt(Side::Lower).ok()?;
        Some(llt.solve(Mat::<f64>::identity(p, p)))
    }

    /// `H⁺`: the inverse on the directions whose eigenvalue is above the larger of `rcond²` (the
    /// rank's `rcond` is of the singular values of `A`, whose squares `H` has) and `p·ε` (the
    /// rounding floor of a symmetric `p × p` eigenvalue problem: numerical rank as MATLAB's
    /// `pinv` and LAPACK take it) times the largest, zero on the others. A local POE model has
    /// directions no pose sees (a joint frame moved along its own axis): their eigenvalues are
    /// rounding (1e-16 of the largest, against 1e-8 for the weakest direction a pose sees on the
    /// simulated IRB 4400), and they have no variance to carry to a prediction.
    pub(super) fn pseudo_inverse(&self, rcond: f64) -> Option<Mat<f64>> {
        let p = self.h.nrows();
        let svd = self.h.thin_svd().ok()?;
        let s = svd.S().column_vector();
        let largest = (0..p).map(|k| s[k]).fold(0.0_f64, f64::max);
        let threshold = (rcond * rcond).max(p as f64 * f64::EPSILON) * largest;
        let v = svd.V();
        let mut inverse = Mat::<f64>::zeros(p, p);
        for k in 0..p {
            if !(s[k] > threshold && s[k] > 0.0) {
                continue;
            }
            let scale = 1.0 / s[k];
            for i in 0..p {
                let vi = v[(i, k)] * scale;
                if vi == 0.0 {
                    continue;
                }
                for j in 0..p {
                    inverse[(i, j)] += vi * v[(j, k)];
                }
            }
        }
        (0..p).all(|i| inverse[(i, i)].is_finite()).then_some(inverse)
    }
}

/// MINPACK's gradient criterion on the problem augmented by the prior rows:
/// `max_j |g_j| / (‖a_j‖ ‖y‖)`, 0 at a stationary point, 1 when the residual lies along a column.
pub(super) fn gradient_cosine(reduced: &Reduced, prior_weights: &[f64], deviation: &[f64]) -> f64 {
    let mut residual_sq = reduced.residual_sq;
    residual_sq += prior_weights.iter().zip(deviation).map(|(w, d)| (w * d).powi(2)).sum::<f64>();
    if residual_sq == 0.0 {
        return 0.0;
    }
    let mut worst = 0.0_f64;
    let gradient = reduced.gradient();
    for (j, (mut column_sq, mut g)) in reduced.column_norms_sq().into_iter().zip(gradient).enumerate() {
        if let (Some(&w), Some(&d)) = (prior_weights.get(j), deviation.get(j)) {
            column_sq += w * w;
            g -= w * w * d;
        }
        if column_sq > 0.0 {
            worst = worst.max(g.abs() / (column_sq * residual_sq).sqrt());
        }
    }
    worst
}
