//! The inner loops of the first-order additive term `Σₖ aₖ s((pₖ − qₖ)²)` (inputs already divided
//! by the term's own length scales), column by column over one input at a time on contiguous
//! copies of each input.
//!
//! With `d` inputs the term costs `d` exponentials per kernel entry: at n = 1,387 and d = 6 about
//! as much as the rest of a likelihood evaluation without the gradient (0.027 → 0.062 s) and 0.06
//! s more with it (0.083 → 0.14 s). A branch-free polynomial exponential was tried: 1.35× faster
//! than the standard library's in isolation, no measurable gain in the evaluation, so not kept.
//!
//! Every entry is computed by the same code whatever thread runs its column, so results stay the
//! same serial or parallel.

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
    /// `Σₖ aₖ s((cₖ[i] − qₖ[j])²)` added to `out[i − from]` for `i` in `from..from + out.len()`:
    /// part of column `j` of the kernel matrix.
    pub(crate) fn add_column(&self, out: &mut [f64], j: usize, from: usize) {
        let rows = from..from + out.len();
        for ((a, col), qcol) in self.variances.iter().zip(self.columns).zip(self.query) {
            let (a, q) = (*a, qcol[j]);
            for (v, p) in out.iter_mut().zip(&col[rows.clone()]) {
                *v += self.shape.value(a, (p - q) * (p - q));
            }
        }
    }

    /// For each input `k`: `Σᵢ wᵢ aₖ s(rᵢₖ²)` and `Σᵢ wᵢ mᵢₖ rᵢₖ²` (the variance's and the length
    /// scale's share of `Σᵢ wᵢ ∂Kᵢⱼ/∂θ`, `m` the shape's length-scale weight) over `i` in
    /// `from..from + w.len()` against column `j`, added to `sums[k]` and `sums[d + k]`.
    pub(crate) fn gradient_sums(&self, sums: &mut [f64], w: &[f64], j: usize, from: usize) {
        let d = self.variances.len();
        for (k, ((a, col), qcol)) in self.variances.iter().zip(self.columns).zip(self.query).enumerate() {
            let (a, q) = (*a, qcol[j]);
            let (mut value, mut length) = (0.0, 0.0);
            for (p, wi) in col[from..from + w.len()].iter().zip(w) {
                let r = (p - q) * (p - q);
                let (v, m) = self.shape.value_and_weight(a, r);
                value += wi * v;
                length += wi * m * r;
            }
            sums[k] += value;
            sums[d + k] += length;
        }
    }
}
