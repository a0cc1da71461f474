//! Kernel (Gram) matrices and the likelihood-gradient contraction, built on matrix products.
//!
//! The stationary term is a function of `r² = ‖x − z‖²` on inputs divided by their length
//! scales; one faer product `X Zᵀ` gives every `r² = ‖x‖² + ‖z‖² − 2 xᵀz` (clamped at 0 against
//! round-off, exactly 0 on the diagonal of a training matrix), and the kernel is applied entry by
//! entry, columns in parallel. The linear term is itself a product, added by faer. Likewise the
//! gradients in the length scales and slope weights come from products of the weight matrix with
//! the inputs (see [`contract_gradient`]).
//!
//! Every entry is computed by exactly one closure call, whatever the thread that runs it, and
//! reductions sum one partial vector per column in column order: with faer's products, which
//! split work by output blocks, the results are the same serial or parallel (tested to the bit).

use dense::product;
use faer::col::ColMut;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef};
use rayon::prelude::*;

use crate::additive;
use crate::config::Parallelism;
use crate::kernel::{Evaluator, Expanded, Prepared, StationaryShape};
use crate::points::Points;
use dense::stationary;

/// Runs `f(j, column j)` over the columns, in parallel or not.
fn for_each_column(mat: MatMut<'_, f64>, par: Parallelism, f: impl Fn(usize, ColMut<'_, f64>) + Sync + Send) {
    match par {
        Parallelism::Sequential => mat.col_iter_mut().enumerate().for_each(|(j, c)| f(j, c)),
        Parallelism::Rayon => mat.par_col_iter_mut().enumerate().for_each(|(j, c)| f(j, c)),
    }
}

/// A column of an owned matrix as a slice (owned faer matrices store columns contiguously).
#[inline]
fn slice_mut(col: ColMut<'_, f64>) -> &mut [f64] {
    col.try_as_col_major_mut().expect("columns of an owned matrix are contiguous").as_slice_mut()
}

pub(crate) fn as_matrix(p: &Points) -> MatRef<'_, f64> {
    MatRef::from_row_major_slice(p.as_slice(), p.len(), p.dim())
}

fn squared_norms(p: &Points) -> Vec<f64> {
    (0..p.len()).map(|i| p.row(i).iter().map(|v| v * v).sum()).collect()
}

/// The lower triangle (diagonal included) of `dst ← X Xᵀ`.
fn lower_inner_products(dst: MatMut<'_, f64>, x: &Points, par: Parallelism) {
    let xm = as_matrix(x);
    triangular::matmul(
        dst,
        BlockStructure::TriangularLower,
        Accum::Replace,
        xm,
        BlockStructure::Rectangular,
        xm.transpose(),
        BlockStructure::Rectangular,
        1.0,
        par.faer(),
    );
}

/// `r²` from the squared norms and the inner product; exactly 0 on the diagonal of a training
/// matrix, never negative.
#[inline]
fn squared_distance(sq_i: f64, sq_j: f64, dot: f64, same: bool) -> f64 {
    if same { 0.0 } else { (sq_i + sq_j - 2.0 * dot).max(0.0) }
}

/// The exponentials of a training matrix's lower triangle that [`fill_training_lower`] can keep
/// for [`contract_gradient`] (squared-exponential shape only): for each column `j`, a block of
/// `(1 + additive inputs) · (n − j)` values, the stationary term's `σf² e^{−r²/2}` for rows
/// `j..n` (the first, the diagonal's, unused), then each additive input's `e^{−r²/2}` for the
/// same rows. `None` where it does not apply or would exceed `budget_bytes`.
pub(crate) fn cache_len(kernel: &Evaluator, x: &Prepared, budget_bytes: usize) -> Option<usize> {
    if kernel.shape != StationaryShape::SquaredExponential {
        return None;
    }
    let n = x.len();
    let per_entry = 1 + x.additive.as_ref().map_or(0, Points::dim);
    let len = per_entry.checked_mul(n.checked_mul(n + 1)? / 2)?;
    (len.checked_mul(std::mem::size_of::<f64>())? <= budget_bytes).then_some(len)
}

/// `cache` (laid out as [`cache_len`] says) cut into one block per column.
fn cache_blocks<T>(mut cache: &mut [T], n: usize, per_entry: usize) -> Vec<&mut [T]> {
    let mut blocks = Vec::with_capacity(n);
    for j in 0..n {
        let (block, rest) = std::mem::take(&mut cache).split_at_mut(per_entry * (n - j));
        blocks.push(block);
        cache = rest;
    }
    blocks
}

/// Lower triangle, diagonal included, of `K(X, X) + diagonal · I` written into `dst` (`n × n`);
/// the strict upper triangle is left as it was (the Cholesky factorisation reads only the lower).
/// With `cache` ([`cache_len`] long), the exponentials are kept there too.
pub(crate) fn fill_training_lower(
    mut dst: MatMut<'_, f64>,
    kernel: &Evaluator,
    x: &Prepared,
    diagonal: f64,
    cache: Option<&mut [f64]>,
    par: Parallelism,
) {
    let sq = squared_norms(&x.stationary);
    lower_inner_products(dst.rb_mut(), &x.stationary, par);
    let (shape, signal, constant) = (kernel.shape, kernel.signal_variance, kernel.constant);
    let additive = x.additive.as_ref().map(additive::columns);
    let term = additive.as_ref().map(|a| additive::Additive {
        shape,
        variances: &kernel.additive_variances,
        columns: a,
        query: a,
    });
    match cache {
        Some(cache) if shape == StationaryShape::SquaredExponential => {
            let n = x.len();
            let per_entry = 1 + additive.as_ref().map_or(0, Vec::len);
            let blocks = cache_blocks(cache, n, per_entry);
            let column = |(j, (col, block)): (usize, (ColMut<'_, f64>, &mut [f64]))| {
                let (col, len) = (slice_mut(col), n - j);
                let (own, rest) = block.split_at_mut(len);
                col[j] = shape.value(signal, 0.0) + constant;
                own[0] = col[j];
                stationary::fill_column_caching(
                    &mut col[j + 1..],
                    &mut own[1..],
                    &sq[j + 1..],
                    sq[j],
                    signal,
                    constant,
                );
                if let Some(term) = &term {
                    term.add_column_caching(&mut col[j..], rest, j, j);
                }
            };
            match par {
                Parallelism::Sequential => dst.rb_mut().col_iter_mut().zip(blocks).enumerate().for_each(column),
                Parallelism::Rayon => dst.rb_mut().par_col_iter_mut().zip(blocks).enumerate().for_each(column),
            }
        }
        _ => for_each_column(dst.rb_mut(), par, |j, col| {
            let col = slice_mut(col);
            match shape {
                StationaryShape::SquaredExponential => {
                    col[j] = shape.value(signal, 0.0) + constant;
                    stationary::fill_column(&mut col[j + 1..], &sq[j + 1..], sq[j], signal, constant);
                }
                StationaryShape::Matern52 => {
                    for (i, v) in col.iter_mut().enumerate().skip(j) {
                        *v = shape.value(signal, squared_distance(sq[i], sq[j], *v, i == j)) + constant;
                    }
                }
            }
            if let Some(term) = &term {
                term.add_column(&mut col[j..], j, j);
            }
        }),
    }
    if let Some(l) = &x.linear {
        let lm = as_matrix(l);
        triangular::matmul(
            dst.rb_mut(),
            BlockStructure::TriangularLower,
            Accum::Add,
            lm,
            BlockStructure::Rectangular,
            lm.transpose(),
            BlockStructure::Rectangular,
            1.0,
            par.faer(),
        );
    }
    for i in 0..x.len() {
        dst[(i, i)] += diagonal;
    }
}

/// Lower triangle of `K(X, X) + diagonal · I` in a new matrix (R&W Eq. 2.21's `K + σn² I`).
pub fn training_covariance(kernel: &Evaluator, x: &Prepared, diagonal: f64, par: Parallelism) -> Mat<f64> {
    let mut k = Mat::zeros(x.len(), x.len());
    fill_training_lower(k.as_mut(), kernel, x, diagonal, None, par);
    k
}

/// `K(X, Z)`, `|X|` rows by `|Z|` columns, without noise; `same` when `Z` is `X` (the diagonal
/// then has `r² = 0` exactly).
fn covariance(kernel: &Evaluator, x: &Prepared, z: &Prepared, same: bool, par: Parallelism) -> Mat<f64> {
    let (sx, sz) = (squared_norms(&x.stationary), squared_norms(&z.stationary));
    let mut k = Mat::zeros(x.len(), z.len());
    product(
        k.as_mut(),
        Accum::Replace,
        as_matrix(&x.stationary),
        as_matrix(&z.stationary).transpose(),
        1.0,
        par.faer(),
    );
    let (shape, signal, constant) = (kernel.shape, kernel.signal_variance, kernel.constant);
    let additive =
        x.additive.as_ref().zip(z.additive.as_ref()).map(|(ax, az)| (additive::columns(ax), additive::columns(az)));
    for_each_column(k.as_mut(), par, |j, col| {
        let col = slice_mut(col);
        match shape {
            // The training matrix's vectorised loop, so that a prediction's cross covariances
            // use the exponential the fit's own matrices were built with.
            StationaryShape::SquaredExponential => {
                stationary::fill_column(col, &sx, sz[j], signal, constant);
                if same {
                    col[j] = shape.value(signal, 0.0) + constant;
                }
            }
            StationaryShape::Matern52 => {
                for (i, v) in col.iter_mut().enumerate() {
                    *v = shape.value(signal, squared_distance(sx[i], sz[j], *v, same && i == j)) + constant;
                }
            }
        }
        if let Some((ax, az)) = &additive {
            let term = additive::Additive { shape, variances: &kernel.additive_variances, columns: ax, query: az };
            term.add_column(col, j, 0);
        }
    });
    if let (Some(lx), Some(lz)) = (&x.linear, &z.linear) {
        product(k.as_mut(), Accum::Add, as_matrix(lx), as_matrix(lz).transpose(), 1.0, par.faer());
    }
    k
}

/// `K(X, Z)` without noise.
pub fn cross_covariance(kernel: &Evaluator, x: &Prepared, z: &Prepared, par: Parallelism) -> Mat<f64> {
    covariance(kernel, x, z, false, par)
}

/// `K(Z, Z)` in full (both triangles), without noise.
pub fn full_covariance(kernel: &Evaluator, z: &Prepared, par: Parallelism) -> Mat<f64> {
    covariance(kernel, z, z, true, par)
}

/// `k(z, z)` for every point, without noise.
pub fn prior_variances(kernel: &Evaluator, z: &Prepared) -> Vec<f64> {
    let linear = z.linear.as_ref().map(squared_norms).unwrap_or_else(|| vec![0.0; z.len()]);
    linear.into_iter().map(|l| kernel.prior_variance(l)).collect()
}

/// `sym(A) R` where only the lower triangle of `A` is meaningful: `tril(A) R + stril(A)ᵀ R`.
fn symmetric_product(a: MatRef<'_, f64>, r: MatRef<'_, f64>, par: Parallelism) -> Mat<f64> {
    let mut out = Mat::zeros(a.nrows(), r.ncols());
    // One column: a matrix–vector product, whose sums faer splits by thread count (dense::product).
    let par = if r.ncols() <= 1 { Parallelism::Sequential } else { par };
    triangular::matmul(
        out.as_mut(),
        BlockStructure::Rectangular,
        Accum::Replace,
        a,
        BlockStructure::TriangularLower,
        r,
        BlockStructure::Rectangular,
        1.0,
        par.faer(),
    );
    triangular::matmul(
        out.as_mut(),
        BlockStructure::Rectangular,
        Accum::Add,
        a.transpose(),
        BlockStructure::StrictTriangularUpper,
        r,
        BlockStructure::Rectangular,
        1.0,
        par.faer(),
    );
    out
}

/// `½ tr(W ∂K/∂θⱼ)` for every expanded log-parameter `θⱼ` (R&W Eq. 5.9), with
/// `W = A Aᵀ − m K⁻¹`, `A = K⁻¹ Y` (`alpha`, `n × m`).
///
/// On entry the lower triangle of `inverse` holds `K⁻¹`; on exit it holds `W`. `scratch` (`n × n`)
/// is overwritten. The kernel derivatives are never stored as matrices: the scalar parameters are
/// summed entry by entry; for a length scale, `∂Kᵢⱼ/∂ln ℓ_d = mᵢⱼ (xᵢ_d − xⱼ_d)²` on prepared
/// inputs, so with `M = W ∘ m` and `s = M 1`:
/// `½ Σᵢⱼ Mᵢⱼ (xᵢ_d − xⱼ_d)² = Σᵢ xᵢ_d (xᵢ_d sᵢ − (M X)ᵢ_d)`, one product for all `d`; for a
/// slope weight, `∂Kᵢⱼ/∂ln w_d = lᵢ_d lⱼ_d` on inputs times `√w`, so the sum is `½ Σᵢ lᵢ_d (W L)ᵢ_d`.
pub(crate) fn contract_gradient(
    kernel: &Evaluator,
    x: &Prepared,
    mut inverse: MatMut<'_, f64>,
    alpha: MatRef<'_, f64>,
    mut scratch: MatMut<'_, f64>,
    cache: Option<&mut [f64]>,
    par: Parallelism,
) -> Vec<f64> {
    let (n, dim, m) = (x.len(), x.stationary.dim(), alpha.ncols());
    let layout = Expanded { dim };
    let sq = squared_norms(&x.stationary);
    let alpha_rows: Vec<f64> = (0..n).flat_map(|i| (0..m).map(move |c| alpha[(i, c)])).collect();
    lower_inner_products(scratch.rb_mut(), &x.stationary, par);
    let (shape, signal) = (kernel.shape, kernel.signal_variance);
    let scale = m as f64;
    let additive = x.additive.as_ref().map(additive::columns);
    let additive_dim = if additive.is_some() { kernel.additive_variances.len() } else { 0 };
    // Per column: Σ f Wᵢⱼ sᵢⱼ, Σ f Wᵢⱼ, ½ Wⱼⱼ, with f = ½ on the diagonal and 1 below it (each
    // strict-lower entry stands for itself and its mirror); then, with an additive term, for each
    // input k, Σ f Wᵢⱼ aₖ s(rₖ²) and Σ f Wᵢⱼ mₖ rₖ² (its variance's and its length scale's).
    // The exponentials [`fill_training_lower`] kept, read instead of computed again: the same
    // values, so the same sums to the bit.
    let per_entry = 1 + additive_dim;
    let cached = cache.filter(|_| shape == StationaryShape::SquaredExponential);
    let mut blocks: Vec<Option<&mut [f64]>> = match cached {
        Some(cache) => cache_blocks(cache, n, per_entry).into_iter().map(Some).collect(),
        None => (0..n).map(|_| None).collect(),
    };
    let column = |j: usize, wc: ColMut<'_, f64>, mc: ColMut<'_, f64>, block: Option<&mut [f64]>| -> Vec<f64> {
        let (wc, mc) = (slice_mut(wc), slice_mut(mc));
        let block = block.map(|b| &*b);
        let aj = &alpha_rows[j * m..(j + 1) * m];
        let mut sums = vec![0.0; 3 + 2 * additive_dim];
        for i in j..n {
            let ai = &alpha_rows[i * m..(i + 1) * m];
            wc[i] = ai.iter().zip(aj).map(|(a, b)| a * b).sum::<f64>() - scale * wc[i];
        }
        match shape {
            StationaryShape::SquaredExponential => {
                // The diagonal (r = 0, weight ½) apart, the rest of the column vectorised.
                let (value, weight) = shape.value_and_weight(signal, 0.0);
                mc[j] = wc[j] * weight;
                let (v, w) = match block {
                    Some(b) => stationary::weigh_column_cached(&mut mc[j + 1..], &wc[j + 1..], &b[1..n - j]),
                    None => stationary::weigh_column(&mut mc[j + 1..], &wc[j + 1..], &sq[j + 1..], sq[j], signal),
                };
                sums[0] = 0.5 * wc[j] * value + v;
                sums[1] = 0.5 * wc[j] + w;
            }
            StationaryShape::Matern52 => {
                for i in j..n {
                    let w = wc[i];
                    let r2 = squared_distance(sq[i], sq[j], mc[i], i == j);
                    let (value, weight) = shape.value_and_weight(signal, r2);
                    mc[i] = w * weight;
                    let f = if i == j { 0.5 } else { 1.0 };
                    sums[0] += f * w * value;
                    sums[1] += f * w;
                }
            }
        }
        sums[2] = 0.5 * wc[j];
        if let Some(a) = &additive {
            // Below the diagonal each entry stands for itself and its mirror; on it r = 0, so the
            // length scales get nothing and each variance ½ Wⱼⱼ aₖ.
            let term = additive::Additive { shape, variances: &kernel.additive_variances, columns: a, query: a };
            match block {
                Some(b) => term.gradient_sums_cached(&mut sums[3..], &wc[j + 1..], &b[n - j..], 1, j, j + 1),
                None => term.gradient_sums(&mut sums[3..], &wc[j + 1..], j, j + 1),
            }
            for (k, v) in kernel.additive_variances.iter().enumerate() {
                sums[3 + k] += 0.5 * wc[j] * v;
            }
        }
        sums
    };
    let blocks: Vec<Option<&mut [f64]>> = std::mem::take(&mut blocks);
    let partial: Vec<Vec<f64>> = match par {
        Parallelism::Sequential => inverse
            .rb_mut()
            .col_iter_mut()
            .zip(scratch.rb_mut().col_iter_mut())
            .zip(blocks)
            .enumerate()
            .map(|(j, ((w, mc), b))| column(j, w, mc, b))
            .collect(),
        Parallelism::Rayon => inverse
            .rb_mut()
            .par_col_iter_mut()
            .zip(scratch.rb_mut().par_col_iter_mut())
            .zip(blocks)
            .enumerate()
            .map(|(j, ((w, mc), b))| column(j, w, mc, b))
            .collect(),
    };
    let mut total = vec![0.0; 3 + 2 * additive_dim];
    for p in &partial {
        for (t, v) in total.iter_mut().zip(p) {
            *t += v;
        }
    }
    let mut g = vec![0.0; layout.len()];
    g[Expanded::SIGNAL] = total[0];
    g[layout.constant()] = kernel.constant * total[1];
    g[layout.noise()] = kernel.noise_variance * total[2];
    for k in 0..additive_dim {
        g[layout.additive_variance(k)] = total[3 + k];
        g[layout.additive_length(k)] = total[3 + additive_dim + k];
    }
    // [M X | M 1] in one product.
    let p = &x.stationary;
    let x1 = Mat::from_fn(n, dim + 1, |i, d| if d < dim { p.row(i)[d] } else { 1.0 });
    let q = symmetric_product(scratch.rb(), x1.as_ref(), par);
    for d in 0..dim {
        g[layout.length(d)] = (0..n).map(|i| x1[(i, d)] * (x1[(i, d)] * q[(i, dim)] - q[(i, d)])).sum();
    }
    if let Some(l) = &x.linear {
        let lm = as_matrix(l);
        let q = symmetric_product(inverse.rb(), lm, par);
        for d in 0..dim {
            g[layout.linear(d)] = 0.5 * (0..n).map(|i| lm[(i, d)] * q[(i, d)]).sum::<f64>();
        }
    }
    g
}
