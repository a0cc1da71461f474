//! The nearest of `k` centres for each point (k-means' assignment step): screened by one matrix
//! product, then compared exactly, so the labels are those of comparing every exact distance.

use faer::{Accum, Mat, MatRef, Par};

/// Points a caller should hand [`labels`] at a time: a `ROWS × k` block of inner products (4 MB
/// at k = 500).
pub const SCREEN_ROWS: usize = 1024;

/// `Σ (aᵢ − bᵢ)²`, summed in index order.
fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Index of the nearest centre (the first of equals) by the exact squared distance, among
/// `candidates` (ascending) of the row-major `centres` (`dim` values each).
fn nearest(p: &[f64], centres: &[f64], dim: usize, candidates: impl Iterator<Item = usize>) -> usize {
    let exact = |c: usize| (c, squared_distance(p, &centres[c * dim..(c + 1) * dim]));
    candidates.map(exact).fold((0, f64::INFINITY), |best, cur| if cur.1 < best.1 { cur } else { best }).0
}

/// The nearest centre of each point of `points` (row-major, `dim` values each) among `centres`
/// (the same layout): the same labels as comparing every exact distance, the first of equals
/// winning, in a fraction of the time. `‖x − c‖² = ‖x‖² + ‖c‖² − 2 xᵀc` from one matrix product
/// screens out every centre whose expansion exceeds the least one's by more than four times a
/// bound far above the expansion's rounding error, and only the rest are compared exactly.
pub fn labels(points: &[f64], centres: &[f64], dim: usize) -> Vec<usize> {
    let (n, k) = (points.len() / dim.max(1), centres.len() / dim.max(1));
    let norms = |p: &[f64]| -> Vec<f64> { p.chunks_exact(dim.max(1)).map(|r| r.iter().map(|v| v * v).sum()).collect() };
    let (xn, cn) = (norms(points), norms(centres));
    let largest = cn.iter().copied().fold(0.0, f64::max);
    let mut dots = Mat::<f64>::zeros(n, k);
    crate::product(
        dots.as_mut(),
        Accum::Replace,
        MatRef::from_row_major_slice(points, n, dim),
        MatRef::from_row_major_slice(centres, k, dim).transpose(),
        1.0,
        Par::Seq,
    );
    (0..n)
        .map(|i| {
            let expanded = |c: usize| xn[i] + cn[c] - 2.0 * dots[(i, c)];
            let least = (0..k).map(expanded).fold(f64::INFINITY, f64::min);
            // Rounding of a d-term expansion is below (d + 2) ε (‖x‖² + ‖c‖² + 2|xᵀc|); 1e-12 of
            // the norms is a thousand times that for any dimension used here.
            let bound = 1e-12 * (xn[i] + largest + 1.0);
            let candidates = (0..k).filter(|&c| expanded(c) <= least + 4.0 * bound);
            nearest(&points[i * dim..(i + 1) * dim], centres, dim, candidates)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screened_labels_are_the_exact_comparison_s_ties_included() {
        // xorshift64*: a fixed sequence, enough for a test.
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut uniform = move || {
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        };
        let d = 7;
        // Far from the origin on a coarse grid (large norms, many exact ties), then spread points,
        // then a cluster at 1e3 whose distances differ by less than the expansion's rounding.
        let mut points: Vec<f64> = (0..2500 * d).map(|_| 40.0 + (uniform() * 6.0).floor() * 0.5).collect();
        points.extend((0..500 * d).map(|_| uniform() * 6.0 - 3.0));
        points.extend((0..500 * d).map(|_| 1e3 + (uniform() * 2.0 - 1.0) * 1e-5));
        let n = points.len() / d;
        let row = |i: usize| points[i * d..(i + 1) * d].to_vec();
        let mut chosen: Vec<usize> = (0..60).map(|_| (uniform() * 3000.0) as usize).collect();
        // A duplicate of the first centre: the first of equals wins.
        chosen.push(chosen[0]);
        chosen.extend((0..20).map(|_| 3000 + (uniform() * 500.0) as usize));
        let centres: Vec<f64> = chosen.iter().flat_map(|&i| row(i)).collect();
        let k = chosen.len();
        let exact: Vec<usize> = (0..n).map(|i| nearest(&row(i), &centres, d, 0..k)).collect();
        assert!(exact.iter().all(|&c| c != 60), "the duplicate centre is never the first of equals");
        // The expansion alone mislabels some of the far cluster: the exact comparison after the
        // screen is what makes the labels the same.
        let by_expansion = |i: usize| {
            let p = row(i);
            let pn: f64 = p.iter().map(|v| v * v).sum();
            (0..k)
                .map(|c| {
                    let q = &centres[c * d..(c + 1) * d];
                    let qn: f64 = q.iter().map(|v| v * v).sum();
                    (c, pn + qn - 2.0 * p.iter().zip(q).map(|(a, b)| a * b).sum::<f64>())
                })
                .fold((0, f64::INFINITY), |b, c| if c.1 < b.1 { c } else { b })
                .0
        };
        assert!((3000..3500).any(|i| by_expansion(i) != exact[i]));
        assert_eq!(labels(&points, &centres, d), exact);
        // In blocks, as callers run it.
        let blocks: Vec<usize> = points.chunks(SCREEN_ROWS * d).flat_map(|b| labels(b, &centres, d)).collect();
        assert_eq!(blocks, exact);
    }
}
