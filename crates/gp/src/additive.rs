//! The first-order additive term `Σₖ aₖ s((pₖ − qₖ)²)` (inputs already divided by the term's own
//! length scales), column by column over one input at a time on contiguous copies of each input.
//! The squared exponential's loops are `dense::one_input`'s (vectorised, without library `exp`);
//! the Matérn shape keeps the scalar library path.
//!
//! Every entry is computed by the same code whatever thread runs its column, so results stay the
//! same serial or parallel on one machine; a processor without AVX2 + FMA rounds differently in
//! the last bits.

use crate::kernel::StationaryShape;
use crate::points::Points;

/// The additive inputs as one contiguous column per input dimension (`n` values each).
pub(crate) fn columns(points: &Points) -> Vec<Vec<f64>> {
    (0..points.dim()).map(|k| (0..points.len()).map(|i| points.row(i)[k]).collect()).collect()
}

/// The additive term between the rows of `columns` (`i`) and those of `query` (`j`), both
/// prepared by [`columns`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Additive<'a> {
    pub(crate) shape: StationaryShape,
    /// `aₖ`.
    pub(crate) variances: &'a [f64],
    pub(crate) columns: &'a [Vec<f64>],
    pub(crate) query: &'a [Vec<f64>],
}

impl Additive<'_> {
    /// [`Additive::add_column`] for the squared-exponential shape that also keeps each input's
    /// exponentials: `cache[k · out.len() ..][.. out.len()]` for input `k`.
    pub(crate) fn add_column_caching(&self, out: &mut [f64], cache: &mut [f64], j: usize, from: usize) {
        let len = out.len();
        let rows = from..from + len;
        for (((a, col), qcol), cache) in
            self.variances.iter().zip(self.columns).zip(self.query).zip(cache.chunks_exact_mut(len.max(1)))
        {
            let (a, q, col) = (*a, qcol[j], &col[rows.clone()]);
            dense::one_input::add_column_caching(out, cache, col, a, q)
        }
    }

    /// [`Additive::gradient_sums`] for the squared-exponential shape with the exponentials read
    /// from `cache`, laid out as [`Additive::add_column_caching`] wrote them for rows
    /// `from − skip ..` (`skip` leading rows of each input's block are not summed).
    pub(crate) fn gradient_sums_cached(
        &self,
        sums: &mut [f64],
        w: &[f64],
        cache: &[f64],
        skip: usize,
        j: usize,
        from: usize,
    ) {
        let d = self.variances.len();
        let block = w.len() + skip;
        for (k, ((a, col), qcol)) in self.variances.iter().zip(self.columns).zip(self.query).enumerate() {
            let (a, q, col) = (*a, qcol[j], &col[from..from + w.len()]);
            let cache = &cache[k * block + skip..(k + 1) * block];
            let (value, length) = dense::one_input::sums_cached(col, w, cache, a, q);
            sums[k] += value;
            sums[d + k] += length;
        }
    }

    /// `Σₖ aₖ s((cₖ[i] − qₖ[j])²)` added to `out[i − from]` for `i` in `from..from + out.len()`:
    /// part of column `j` of the kernel matrix.
    pub(crate) fn add_column(&self, out: &mut [f64], j: usize, from: usize) {
        let rows = from..from + out.len();
        for ((a, col), qcol) in self.variances.iter().zip(self.columns).zip(self.query) {
            let (a, q, col) = (*a, qcol[j], &col[rows.clone()]);
            match self.shape {
                StationaryShape::SquaredExponential => dense::one_input::add_column(out, col, a, q),
                StationaryShape::Matern52 => {
                    for (v, p) in out.iter_mut().zip(col) {
                        *v += self.shape.value(a, (p - q) * (p - q));
                    }
                }
            }
        }
    }

    /// For each input `k`: `Σᵢ wᵢ aₖ s(rᵢₖ²)` and `Σᵢ wᵢ mᵢₖ rᵢₖ²` (the variance's and the length
    /// scale's share of `Σᵢ wᵢ ∂Kᵢⱼ/∂θ`, `m` the shape's length-scale weight) over `i` in
    /// `from..from + w.len()` against column `j`, added to `sums[k]` and `sums[d + k]`.
    pub(crate) fn gradient_sums(&self, sums: &mut [f64], w: &[f64], j: usize, from: usize) {
        let d = self.variances.len();
        for (k, ((a, col), qcol)) in self.variances.iter().zip(self.columns).zip(self.query).enumerate() {
            let (a, q, col) = (*a, qcol[j], &col[from..from + w.len()]);
            let (value, length) = match self.shape {
                StationaryShape::SquaredExponential => dense::one_input::sums(col, w, a, q),
                StationaryShape::Matern52 => {
                    let (mut value, mut length) = (0.0, 0.0);
                    for (p, wi) in col.iter().zip(w) {
                        let r = (p - q) * (p - q);
                        let (v, m) = self.shape.value_and_weight(a, r);
                        value += wi * v;
                        length += wi * m * r;
                    }
                    (value, length)
                }
            };
            sums[k] += value;
            sums[d + k] += length;
        }
    }
}
