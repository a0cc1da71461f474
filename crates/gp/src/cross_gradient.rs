//! `Σᵢⱼ Gᵢⱼ ∂K(Z, X)ᵢⱼ/∂θ` for every expanded log-parameter `θ` and a coefficient matrix `G`
//! (`|Z| × |X|`): the contraction that turns the sparse bound's derivative in `K_uu` and `K_uf`
//! into its gradient in the hyperparameters, without storing a derivative matrix.
//!
//! With prepared inputs (divided by the length scales), `∂Kᵢⱼ/∂ln ℓ_d = mᵢⱼ (zᵢ_d − xⱼ_d)²` where
//! `m` is the shape's length-scale weight, so with `H = G ∘ m`:
//! `Σᵢⱼ Hᵢⱼ (zᵢ_d − xⱼ_d)² = Σᵢ zᵢ_d² (H 1)ᵢ + Σⱼ xⱼ_d² (Hᵀ 1)ⱼ − 2 Σᵢ zᵢ_d (H X)ᵢ_d`; for a slope
//! weight, `∂Kᵢⱼ/∂ln w_d = lᵢ_d lⱼ_d` on inputs times `√w`, so the sum is `Σᵢ lᵢ_d (G L)ᵢ_d`.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef};
use rayon::prelude::*;

use crate::config::Parallelism;
use crate::gram::as_matrix;
use crate::kernel::{Evaluator, Expanded, Prepared};
use dense::product;

fn squared_norms(rows: MatRef<'_, f64>) -> Vec<f64> {
    (0..rows.nrows()).map(|i| (0..rows.ncols()).map(|d| rows[(i, d)] * rows[(i, d)]).sum()).collect()
}

/// The contraction, noise entry 0; `same` when `X` is `Z` (the diagonal then has `r² = 0` exactly,
/// as in the kernel matrix the bound factored).
pub fn contract_cross(
    kernel: &Evaluator,
    z: &Prepared,
    x: &Prepared,
    g: MatRef<'_, f64>,
    same: bool,
    parallelism: Parallelism,
) -> Vec<f64> {
    let par = parallelism.faer();
    let (zm, xm) = (as_matrix(&z.stationary), as_matrix(&x.stationary));
    let (m, c, dim) = (zm.nrows(), xm.nrows(), zm.ncols());
    let (sz, sx) = (squared_norms(zm), squared_norms(xm));
    let mut h = Mat::zeros(m, c);
    product(h.as_mut(), Accum::Replace, zm, xm.transpose(), 1.0, par);
    let (shape, signal) = (kernel.shape, kernel.signal_variance);
    let additive = z
        .additive
        .as_ref()
        .zip(x.additive.as_ref())
        .map(|(az, ax)| (crate::additive::columns(az), crate::additive::columns(ax)));
    let additive_dim = if additive.is_some() { kernel.additive_variances.len() } else { 0 };
    // Per column j: Σᵢ Gᵢⱼ s(r²ᵢⱼ), Σᵢ Gᵢⱼ, Σᵢ Hᵢⱼ; H overwrites the inner products; then, with an
    // additive term, for each input k, Σᵢ Gᵢⱼ aₖ s(rₖ²) and Σᵢ Gᵢⱼ mₖ rₖ².
    let column = |j: usize, col: faer::col::ColMut<'_, f64>| -> Vec<f64> {
        let mut sums = vec![0.0; 3 + 2 * additive_dim];
        let col = col.try_as_col_major_mut().expect("columns of an owned matrix are contiguous").as_slice_mut();
        for (i, v) in col.iter_mut().enumerate() {
            let r2 = if same && i == j { 0.0 } else { (sz[i] + sx[j] - 2.0 * *v).max(0.0) };
            let (value, weight) = shape.value_and_weight(signal, r2);
            let gij = g[(i, j)];
            *v = gij * weight;
            sums[0] += gij * value;
            sums[1] += gij;
            sums[2] += *v;
        }
        if let Some((az, ax)) = &additive {
            let gj: Vec<f64> = (0..m).map(|i| g[(i, j)]).collect();
            let term =
                crate::additive::Additive { shape, variances: &kernel.additive_variances, columns: az, query: ax };
            term.gradient_sums(&mut sums[3..], &gj, j, 0);
        }
        sums
    };
    let partial: Vec<Vec<f64>> = match parallelism {
        Parallelism::Sequential => h.col_iter_mut().enumerate().map(|(j, col)| column(j, col)).collect(),
        Parallelism::Rayon => h.par_col_iter_mut().enumerate().map(|(j, col)| column(j, col)).collect(),
    };
    let layout = Expanded { dim };
    let mut out = vec![0.0; layout.len()];
    for p in &partial {
        out[Expanded::SIGNAL] += p[0];
        out[layout.constant()] += p[1];
        for k in 0..additive_dim {
            out[layout.additive_variance(k)] += p[3 + k];
            out[layout.additive_length(k)] += p[3 + additive_dim + k];
        }
    }
    out[layout.constant()] *= kernel.constant;
    // H 1 (rows) and H X (m × d).
    let row_sums: Vec<f64> = (0..m).map(|i| (0..c).map(|j| h[(i, j)]).sum()).collect();
    let mut hx = Mat::zeros(m, dim);
    // Narrow outputs (m × d, long inner dimension) serially, so that the sums do not depend on
    // how threads would split the inner dimension.
    matmul(hx.as_mut(), Accum::Replace, h.as_ref(), xm, 1.0, faer::Par::Seq);
    for d in 0..dim {
        let from_z: f64 = (0..m).map(|i| zm[(i, d)] * (zm[(i, d)] * row_sums[i] - 2.0 * hx[(i, d)])).sum();
        let from_x: f64 = (0..c).map(|j| xm[(j, d)] * xm[(j, d)] * partial[j][2]).sum();
        out[layout.length(d)] = from_z + from_x;
    }
    if let (Some(lz), Some(lx)) = (&z.linear, &x.linear) {
        let (lzm, lxm) = (as_matrix(lz), as_matrix(lx));
        let mut gl = Mat::zeros(m, dim);
        matmul(gl.as_mut(), Accum::Replace, g, lxm, 1.0, faer::Par::Seq);
        for d in 0..dim {
            out[layout.linear(d)] = (0..m).map(|i| lzm[(i, d)] * gl[(i, d)]).sum();
        }
    }
    out
}
