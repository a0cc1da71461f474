//! Kernel (Gram) matrices and the likelihood-gradient contraction, built on matrix products.
//!
//! Every kernel here is a function of `r² = ‖x − z‖²` and `xᵀz` on prepared inputs, so one faer
//! product `X Zᵀ` gives both (`r² = ‖x‖² + ‖z‖² − 2 xᵀz`, clamped at 0 against round-off) and the
//! kernel is applied entry by entry, columns in parallel. Likewise the length-scale gradients
//! `½ Σᵢⱼ Mᵢⱼ (xᵢ_d − xⱼ_d)²` come from one product `M X` (see [`contract_gradient`]).
//!
//! Every entry is computed by exactly one closure call, whatever the thread that runs it, and
//! reductions sum one partial vector per column in column order: with faer's products, which
//! split work by output blocks, the results are the same serial or parallel (tested to the bit).

use faer::col::ColMut;
use faer::linalg::matmul::matmul;
use faer::reborrow::ReborrowMut;
use faer::{Accum, Mat, MatMut, MatRef};
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

fn as_matrix(p: &Points) -> MatRef<'_, f64> {
    MatRef::from_row_major_slice(p.as_slice(), p.len(), p.dim())
}

fn squared_norms(p: &Points) -> Vec<f64> {
    (0..p.len()).map(|i| p.row(i).iter().map(|v| v * v).sum()).collect()
}

/// `X Zᵀ`.
fn inner_products(x: &Points, z: &Points, par: Parallelism) -> Mat<f64> {
    let mut d = Mat::zeros(x.len(), z.len());
    matmul(d.as_mut(), Accum::Replace, as_matrix(x), as_matrix(z).transpose(), 1.0, par.faer());
    d
}

/// `r²` from the squared norms and the inner product; exactly 0 on the diagonal of a training
/// matrix, never negative.
#[inline]
fn squared_distance(sq_i: f64, sq_j: f64, dot: f64, same: bool) -> f64 {
    if same { 0.0 } else { (sq_i + sq_j - 2.0 * dot).max(0.0) }
}

/// Lower triangle, diagonal included, of `K(X, X) + σn² I` (R&W Eq. 2.21's `K + σn² I`).
///
/// The strict upper triangle is not meaningful: the Cholesky factorisation reads only the lower one.
pub(crate) fn training_covariance(kernel: &Evaluator, x: &Points, noise_variance: f64, par: Parallelism) -> Mat<f64> {
    let sq = squared_norms(x);
    let mut k = inner_products(x, x, par);
    with_pair_kernel!(kernel, pk => for_each_column(k.as_mut(), par, |j, col| {
        for_each_entry(col, j, |i, v| *v = pk.value(squared_distance(sq[i], sq[j], *v, i == j), *v));
    }));
    for i in 0..x.len() {
        k[(i, i)] += noise_variance;
    }
    k
}

/// What [`training_covariance_with_cache`] keeps for the gradient.
pub(crate) struct GradientCache {
    /// Per-pair factor from [`PairKernel::value_and_cache`] (lower triangle).
    factor: Mat<f64>,
    /// `X Xᵀ` (lower triangle).
    inner: Mat<f64>,
    /// `‖xᵢ‖²`.
    squared_norms: Vec<f64>,
}

/// As [`training_covariance`], and what [`contract_gradient`] needs.
pub(crate) fn training_covariance_with_cache(
    kernel: &Evaluator,
    x: &Points,
    noise_variance: f64,
    par: Parallelism,
) -> (Mat<f64>, GradientCache) {
    let sq = squared_norms(x);
    let inner = inner_products(x, x, par);
    let mut k = inner.clone();
    let mut factor = Mat::zeros(x.len(), x.len());
    let fill = |j: usize, kc: ColMut<'_, f64>, fc: ColMut<'_, f64>| {
        let mut caches = Vec::with_capacity(x.len() - j);
        with_pair_kernel!(kernel, pk => for_each_entry(kc, j, |i, v| {
            let (value, cache) = pk.value_and_cache(squared_distance(sq[i], sq[j], *v, i == j), *v);
            *v = value;
            caches.push(cache);
        }));
        let mut caches = caches.into_iter();
        for_each_entry(fc, j, |_, c| *c = caches.next().unwrap_or(0.0));
    };
    match par {
        Parallelism::Sequential => {
            k.col_iter_mut().zip(factor.col_iter_mut()).enumerate().for_each(|(j, (kc, fc))| fill(j, kc, fc))
        }
        Parallelism::Rayon => {
            k.par_col_iter_mut().zip(factor.par_col_iter_mut()).enumerate().for_each(|(j, (kc, fc))| fill(j, kc, fc))
        }
    }
    for i in 0..x.len() {
        k[(i, i)] += noise_variance;
    }
    (k, GradientCache { factor, inner, squared_norms: sq })
}

/// `K(X, Z)`, `|X|` rows by `|Z|` columns, without noise.
pub(crate) fn cross_covariance(kernel: &Evaluator, x: &Points, z: &Points, par: Parallelism) -> Mat<f64> {
    let (sx, sz) = (squared_norms(x), squared_norms(z));
    let mut k = inner_products(x, z, par);
    with_pair_kernel!(kernel, pk => for_each_column(k.as_mut(), par, |j, col| {
        for_each_entry(col, 0, |i, v| *v = pk.value(squared_distance(sx[i], sz[j], *v, false), *v));
    }));
    k
}

/// `k(z, z)` for every point, without noise.
pub(crate) fn prior_variances(kernel: &Evaluator, z: &Points) -> Vec<f64> {
    squared_norms(z).into_iter().map(|s| with_pair_kernel!(kernel, pk => pk.value(0.0, s))).collect()
}

/// `K(Z, Z)` in full (both triangles), without noise.
pub(crate) fn full_covariance(kernel: &Evaluator, z: &Points, par: Parallelism) -> Mat<f64> {
    let sq = squared_norms(z);
    let mut k = inner_products(z, z, par);
    with_pair_kernel!(kernel, pk => for_each_column(k.as_mut(), par, |j, col| {
        for_each_entry(col, 0, |i, v| *v = pk.value(squared_distance(sq[i], sq[j], *v, i == j), *v));
    }));
    k
}

/// `½ Σᵢₖ Wᵢₖ ∂Kᵢₖ/∂ln pⱼ` for every log-parameter `pⱼ` of the kernel and, last, of the noise.
///
/// This is R&W Eq. 5.9, `½ tr(W ∂K/∂θⱼ)`, with `W` symmetric and only its lower triangle read;
/// the kernel derivatives are never stored as matrices. Parameters differentiated pair by pair are
/// summed entry by entry. For a length scale, `∂Kᵢⱼ/∂ln ℓ_d = mᵢⱼ (xᵢ_d − xⱼ_d)²` on prepared
/// inputs, so with `M = W ∘ m` and `s = M 1`:
/// `½ Σᵢⱼ Mᵢⱼ (xᵢ_d − xⱼ_d)² = Σᵢ xᵢ_d (xᵢ_d sᵢ − (M X)ᵢ_d)`, one matrix product for all `d`.
pub(crate) fn contract_gradient(
    kernel: &Evaluator,
    x: &Points,
    w: MatRef<'_, f64>,
    cache: &GradientCache,
    noise_variance: f64,
    kernel_parameters: usize,
    par: Parallelism,
) -> Vec<f64> {
    with_pair_kernel!(kernel, pk => contract(pk, x, w, cache, noise_variance, kernel_parameters, par))
}

fn contract<K: PairKernel>(
    pk: &K,
    x: &Points,
    w: MatRef<'_, f64>,
    cache: &GradientCache,
    noise_variance: f64,
    kernel_parameters: usize,
    par: Parallelism,
) -> Vec<f64> {
    let (n, dim) = (x.len(), x.dim());
    let scalars = K::SCALARS;
    let ard = kernel_parameters > scalars;
    let sq = &cache.squared_norms;
    // M = W ∘ m, lower triangle, filled while the scalar sums are taken.
    let mut m = if ard { Mat::zeros(n, n) } else { Mat::zeros(0, 0) };
    let column_sums = |j: usize, mcol: Option<ColMut<'_, f64>>| {
        let mut sum = vec![0.0; scalars + 1];
        let mut g = vec![0.0; scalars];
        let (wj, fj, dj) = (column(w, j), column(cache.factor.as_ref(), j), column(cache.inner.as_ref(), j));
        let mut weights = Vec::with_capacity(if ard { n - j } else { 0 });
        for i in j..n {
            let r2 = squared_distance(sq[i], sq[j], dj[i], i == j);
            let weight = pk.gradient_from_cache(r2, dj[i], fj[i], &mut g);
            // Diagonal entry counts once, each strict-lower entry twice (for its mirror).
            let wij = if i == j { 0.5 * wj[i] } else { wj[i] };
            for (s, gp) in sum.iter_mut().zip(&g) {
                *s += wij * gp;
            }
            if ard {
                weights.push(wj[i] * weight);
            }
        }
        sum[scalars] = 0.5 * wj[j] * noise_variance;
        if let Some(mcol) = mcol {
            let mut weights = weights.into_iter();
            for_each_entry(mcol, j, |_, v| *v = weights.next().unwrap_or(0.0));
        }
        sum
    };
    let partial: Vec<Vec<f64>> = match (par, ard) {
        (Parallelism::Sequential, true) => m.col_iter_mut().enumerate().map(|(j, c)| column_sums(j, Some(c))).collect(),
        (Parallelism::Rayon, true) => m.par_col_iter_mut().enumerate().map(|(j, c)| column_sums(j, Some(c))).collect(),
        (Parallelism::Sequential, false) => (0..n).map(|j| column_sums(j, None)).collect(),
        (Parallelism::Rayon, false) => (0..n).into_par_iter().map(|j| column_sums(j, None)).collect(),
    };
    let mut total = vec![0.0; kernel_parameters + 1];
    for p in &partial {
        for (t, v) in total[..scalars].iter_mut().zip(p) {
            *t += v;
        }
        total[kernel_parameters] += p[scalars];
    }
    if ard {
        // Mirror the lower triangle, then [M X | M 1] in one product.
        let full = Mat::from_fn(n, n, |i, j| if i >= j { m[(i, j)] } else { m[(j, i)] });
        drop(m);
        let x1 = Mat::from_fn(n, dim + 1, |i, d| if d < dim { x.row(i)[d] } else { 1.0 });
        let mut p = Mat::zeros(n, dim + 1);
        matmul(p.as_mut(), Accum::Replace, full.as_ref(), x1.as_ref(), 1.0, par.faer());
        for d in 0..dim {
            total[scalars + d] = (0..n).map(|i| x1[(i, d)] * (x1[(i, d)] * p[(i, dim)] - p[(i, d)])).sum();
        }
    }
    total
}
