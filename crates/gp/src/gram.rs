//! Kernel (Gram) matrices built column by column on the rayon pool.
//!
//! Every entry is computed by exactly one closure call, whatever the thread that runs it, and the
//! gradient contraction sums one partial vector per column in column order: the results are the
//! same to the last bit serial or parallel.

use faer::col::ColMut;
use faer::{Mat, MatMut, MatRef};
use rayon::prelude::*;

use crate::config::Parallelism;
use crate::kernel::Evaluator;
use crate::points::Points;

fn for_each_column(mat: MatMut<'_, f64>, par: Parallelism, f: impl Fn(usize, ColMut<'_, f64>) + Sync + Send) {
    match par {
        Parallelism::Sequential => mat.col_iter_mut().enumerate().for_each(|(j, c)| f(j, c)),
        Parallelism::Rayon => mat.par_col_iter_mut().enumerate().for_each(|(j, c)| f(j, c)),
    }
}

/// Lower triangle, diagonal included, of `K(X, X) + σn² I` (R&W Eq. 2.21's `K + σn² I`).
///
/// The strict upper triangle is left at zero: the Cholesky factorisation reads only the lower one.
pub(crate) fn training_covariance(kernel: &Evaluator, x: &Points, noise_variance: f64, par: Parallelism) -> Mat<f64> {
    let n = x.len();
    let mut k = Mat::zeros(n, n);
    for_each_column(k.as_mut(), par, |j, col| {
        let xj = x.row(j);
        for (i, v) in col.iter_mut().enumerate().skip(j) {
            *v = kernel.value(x.row(i), xj);
        }
    });
    for i in 0..n {
        k[(i, i)] += noise_variance;
    }
    k
}

/// `K(X, Z)`, `|X|` rows by `|Z|` columns, without noise.
pub(crate) fn cross_covariance(kernel: &Evaluator, x: &Points, z: &Points, par: Parallelism) -> Mat<f64> {
    let mut k = Mat::zeros(x.len(), z.len());
    for_each_column(k.as_mut(), par, |j, col| {
        let zj = z.row(j);
        for (i, v) in col.iter_mut().enumerate() {
            *v = kernel.value(x.row(i), zj);
        }
    });
    k
}

/// `k(z, z)` for every point, without noise.
pub(crate) fn prior_variances(kernel: &Evaluator, z: &Points) -> Vec<f64> {
    (0..z.len()).map(|i| kernel.value(z.row(i), z.row(i))).collect()
}

/// `K(Z, Z)` in full (both triangles), without noise.
pub(crate) fn full_covariance(kernel: &Evaluator, z: &Points, par: Parallelism) -> Mat<f64> {
    cross_covariance(kernel, z, z, par)
}

/// `½ Σᵢₖ Wᵢₖ ∂Kᵢₖ/∂ln pⱼ` for every log-parameter `pⱼ` of the kernel and, last, of the noise.
///
/// This is R&W Eq. 5.9, `½ tr(W ∂K/∂θⱼ)`, with `W` symmetric and only its lower triangle read,
/// so the kernel derivatives are never stored as matrices. `kernel_parameters` excludes the noise.
pub(crate) fn contract_gradient(
    kernel: &Evaluator,
    x: &Points,
    w: MatRef<'_, f64>,
    noise_variance: f64,
    kernel_parameters: usize,
    par: Parallelism,
) -> Vec<f64> {
    let n = x.len();
    let column = |j: usize| {
        let mut sum = vec![0.0; kernel_parameters + 1];
        let mut g = vec![0.0; kernel_parameters];
        let xj = x.row(j);
        let wj = w.col(j);
        // Diagonal entry counts once, each strict-lower entry twice (for its mirror).
        kernel.value_and_gradient(xj, xj, &mut g);
        let wjj = wj[j];
        for (s, gp) in sum.iter_mut().zip(&g) {
            *s += 0.5 * wjj * gp;
        }
        sum[kernel_parameters] = 0.5 * wjj * noise_variance;
        for i in j + 1..n {
            kernel.value_and_gradient(x.row(i), xj, &mut g);
            let wij = wj[i];
            for (s, gp) in sum.iter_mut().zip(&g) {
                *s += wij * gp;
            }
        }
        sum
    };
    let partial: Vec<Vec<f64>> = match par {
        Parallelism::Sequential => (0..n).map(column).collect(),
        Parallelism::Rayon => (0..n).into_par_iter().map(column).collect(),
    };
    let mut total = vec![0.0; kernel_parameters + 1];
    for p in &partial {
        for (t, v) in total.iter_mut().zip(p) {
            *t += v;
        }
    }
    total
}
