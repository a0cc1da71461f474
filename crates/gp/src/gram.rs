//! Kernel (Gram) matrices built column by column on the rayon pool.
//!
//! Every entry is computed by exactly one closure call, whatever the thread that runs it, and the
//! gradient contraction sums one partial vector per column in column order: the results are the
//! same to the last bit serial or parallel. Each loop is compiled once per kernel
//! ([`with_pair_kernel`]), with no dispatch per pair.

use faer::col::ColMut;
use faer::reborrow::ReborrowMut;
use faer::{Mat, MatMut, MatRef};
use rayon::prelude::*;

use crate::config::Parallelism;
use crate::kernel::{Evaluator, PairKernel, with_pair_kernel};
use crate::points::Points;

fn for_each_column(mat: MatMut<'_, f64>, par: Parallelism, f: impl Fn(usize, ColMut<'_, f64>) + Sync + Send) {
    match par {
        Parallelism::Sequential => mat.col_iter_mut().enumerate().for_each(|(j, c)| f(j, c)),
        Parallelism::Rayon => mat.par_col_iter_mut().enumerate().for_each(|(j, c)| f(j, c)),
    }
}

/// Calls `f(i, &mut entry)` for rows `start..` of a column, through a slice when the column is
/// contiguous (always, for an owned `Mat`) so the loop has no per-entry bounds checks.
#[inline]
fn for_each_entry(mut col: ColMut<'_, f64>, start: usize, mut f: impl FnMut(usize, &mut f64)) {
    match col.rb_mut().try_as_col_major_mut() {
        Some(c) => c.as_slice_mut().iter_mut().enumerate().skip(start).for_each(|(i, v)| f(i, v)),
        None => col.iter_mut().enumerate().skip(start).for_each(|(i, v)| f(i, v)),
    }
}

/// Column `j` of `m` as a slice (copied when the column is not contiguous).
#[inline]
fn column(m: MatRef<'_, f64>, j: usize) -> std::borrow::Cow<'_, [f64]> {
    match m.col(j).try_as_col_major() {
        Some(c) => std::borrow::Cow::Borrowed(c.as_slice()),
        None => std::borrow::Cow::Owned(m.col(j).iter().copied().collect()),
    }
}

/// Lower triangle, diagonal included, of `K(X, X) + σn² I` (R&W Eq. 2.21's `K + σn² I`).
///
/// The strict upper triangle is left at zero: the Cholesky factorisation reads only the lower one.
pub(crate) fn training_covariance(kernel: &Evaluator, x: &Points, noise_variance: f64, par: Parallelism) -> Mat<f64> {
    let n = x.len();
    let mut k = Mat::zeros(n, n);
    with_pair_kernel!(kernel, pk => for_each_column(k.as_mut(), par, |j, col| {
        let xj = x.row(j);
        for_each_entry(col, j, |i, v| *v = pk.value(x.row(i), xj));
    }));
    for i in 0..n {
        k[(i, i)] += noise_variance;
    }
    k
}

/// As [`training_covariance`], and in a second matrix (lower triangle) the per-pair factor that
/// [`contract_gradient`] needs.
pub(crate) fn training_covariance_with_cache(
    kernel: &Evaluator,
    x: &Points,
    noise_variance: f64,
    par: Parallelism,
) -> (Mat<f64>, Mat<f64>) {
    let n = x.len();
    let mut k = Mat::zeros(n, n);
    let mut cache = Mat::zeros(n, n);
    with_pair_kernel!(kernel, pk => match par {
        Parallelism::Sequential => k
            .col_iter_mut()
            .zip(cache.col_iter_mut())
            .enumerate()
            .for_each(|(j, (kc, cc))| fill_with_cache(pk, x, j, kc, cc)),
        Parallelism::Rayon => k
            .par_col_iter_mut()
            .zip(cache.par_col_iter_mut())
            .enumerate()
            .for_each(|(j, (kc, cc))| fill_with_cache(pk, x, j, kc, cc)),
    });
    for i in 0..n {
        k[(i, i)] += noise_variance;
    }
    (k, cache)
}

fn fill_with_cache<K: PairKernel>(pk: &K, x: &Points, j: usize, kc: ColMut<'_, f64>, cc: ColMut<'_, f64>) {
    let xj = x.row(j);
    let mut caches = Vec::with_capacity(x.len() - j);
    for_each_entry(kc, j, |i, v| {
        let (value, cache) = pk.value_and_cache(x.row(i), xj);
        *v = value;
        caches.push(cache);
    });
    let mut caches = caches.into_iter();
    for_each_entry(cc, j, |_, c| *c = caches.next().unwrap_or(0.0));
}

/// `K(X, Z)`, `|X|` rows by `|Z|` columns, without noise.
pub(crate) fn cross_covariance(kernel: &Evaluator, x: &Points, z: &Points, par: Parallelism) -> Mat<f64> {
    let mut k = Mat::zeros(x.len(), z.len());
    with_pair_kernel!(kernel, pk => for_each_column(k.as_mut(), par, |j, col| {
        let zj = z.row(j);
        for_each_entry(col, 0, |i, v| *v = pk.value(x.row(i), zj));
    }));
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
/// so the kernel derivatives are never stored as matrices. `cache` is the second matrix of
/// [`training_covariance_with_cache`]; `kernel_parameters` excludes the noise.
pub(crate) fn contract_gradient(
    kernel: &Evaluator,
    x: &Points,
    w: MatRef<'_, f64>,
    cache: MatRef<'_, f64>,
    noise_variance: f64,
    kernel_parameters: usize,
    par: Parallelism,
) -> Vec<f64> {
    let n = x.len();
    let partial: Vec<Vec<f64>> = with_pair_kernel!(kernel, pk => {
        let column = |j: usize| {
            let mut sum = vec![0.0; kernel_parameters + 1];
            let mut g = vec![0.0; kernel_parameters];
            let xj = x.row(j);
            let (wj, cj) = (column(w, j), column(cache, j));
            // Diagonal entry counts once, each strict-lower entry twice (for its mirror).
            pk.gradient_from_cache(xj, xj, cj[j], &mut g);
            let wjj = wj[j];
            for (s, gp) in sum.iter_mut().zip(&g) {
                *s += 0.5 * wjj * gp;
            }
            sum[kernel_parameters] = 0.5 * wjj * noise_variance;
            for i in j + 1..n {
                pk.gradient_from_cache(x.row(i), xj, cj[i], &mut g);
                let wij = wj[i];
                for (s, gp) in sum.iter_mut().zip(&g) {
                    *s += wij * gp;
                }
            }
            sum
        };
        match par {
            Parallelism::Sequential => (0..n).map(column).collect(),
            Parallelism::Rayon => (0..n).into_par_iter().map(column).collect(),
        }
    });
    let mut total = vec![0.0; kernel_parameters + 1];
    for p in &partial {
        for (t, v) in total.iter_mut().zip(p) {
            *t += v;
        }
    }
    total
}
