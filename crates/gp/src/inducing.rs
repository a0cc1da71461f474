//! Choice of inducing inputs for the sparse approximation: a seeded random subset of the training
//! inputs, or k-means centres (k-means++ seeding, Arthur & Vassilvitskii 2007, then Lloyd steps).

use rand::seq::index::sample;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::config::Parallelism;
use crate::kernel::squared_distance;
use crate::points::Points;

/// How the inducing inputs are chosen (on standardised inputs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum InducingSelection {
    /// Distinct training inputs drawn uniformly without replacement.
    RandomSubset,
    /// k-means centres after this many Lloyd iterations from a k-means++ start.
    KMeans {
        /// Lloyd iterations.
        iterations: usize,
    },
}

impl Default for InducingSelection {
    fn default() -> Self {
        Self::KMeans { iterations: 10 }
    }
}

/// `count` distinct indices out of `0..n`, sorted, from `seed`.
pub(crate) fn random_indices(n: usize, count: usize, seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut indices = sample(&mut rng, n, count.min(n)).into_vec();
    indices.sort_unstable();
    indices
}

/// `count` inducing inputs chosen from `x` by `selection`.
pub(crate) fn select_inducing(
    x: &Points,
    count: usize,
    selection: InducingSelection,
    seed: u64,
    parallelism: Parallelism,
) -> Points {
    match selection {
        InducingSelection::RandomSubset => x.select(&random_indices(x.len(), count, seed)),
        InducingSelection::KMeans { iterations } => k_means(x, count, iterations, seed, parallelism),
    }
}

/// Index of the nearest centre (the first of equals) by the exact squared distance, among
/// `candidates` (ascending; every centre when `None`).
fn nearest(p: &[f64], centres: &Points, candidates: Option<&[usize]>) -> usize {
    let exact = |c: usize| (c, squared_distance(p, centres.row(c)));
    let first_least = |best: (usize, f64), cur: (usize, f64)| if cur.1 < best.1 { cur } else { best };
    match candidates {
        None => (0..centres.len()).map(exact).fold((0, f64::INFINITY), first_least).0,
        Some(c) => c.iter().map(|&c| exact(c)).fold((0, f64::INFINITY), first_least).0,
    }
}

/// Rows screened at a time by [`labels`]: a `ROWS × k` block of inner products (4 MB at k = 500).
const SCREEN_ROWS: usize = 1024;

/// The nearest centre of every point, the same labels as comparing every exact distance
/// ([`nearest`] over all centres), in a fraction of the time: `‖x − c‖² = ‖x‖² + ‖c‖² − 2 xᵀc` from
/// one matrix product per block of rows screens out every centre whose distance cannot be the
/// least (its expansion exceeds the least one's by more than four times a bound far above the
/// expansion's rounding error), and only the rest are compared exactly.
fn labels(x: &Points, centres: &Points, parallelism: Parallelism) -> Vec<usize> {
    let (n, k) = (x.len(), centres.len());
    let norms = |p: &Points| -> Vec<f64> { (0..p.len()).map(|i| p.row(i).iter().map(|v| v * v).sum()).collect() };
    let (xn, cn) = (norms(x), norms(centres));
    let largest = cn.iter().copied().fold(0.0, f64::max);
    let cm = crate::gram::as_matrix(centres);
    let block = |start: usize| -> Vec<usize> {
        let rows = start..(start + SCREEN_ROWS).min(n);
        let xm = faer::MatRef::from_row_major_slice(
            &x.as_slice()[rows.start * x.dim()..rows.end * x.dim()],
            rows.len(),
            x.dim(),
        );
        let mut dots = faer::Mat::<f64>::zeros(rows.len(), k);
        dense::product(dots.as_mut(), faer::Accum::Replace, xm, cm.transpose(), 1.0, faer::Par::Seq);
        let mut candidates = Vec::with_capacity(k);
        rows.clone()
            .enumerate()
            .map(|(r, i)| {
                let expanded = |c: usize| xn[i] + cn[c] - 2.0 * dots[(r, c)];
                let least = (0..k).map(expanded).fold(f64::INFINITY, f64::min);
                // Rounding of a d-term expansion is below (d + 2) ε (‖x‖² + ‖c‖² + 2|xᵀc|); 1e-12
                // of the norms is a thousand times that for any dimension used here.
                let bound = 1e-12 * (xn[i] + largest + 1.0);
                candidates.clear();
                candidates.extend((0..k).filter(|&c| expanded(c) <= least + 4.0 * bound));
                nearest(x.row(i), centres, Some(&candidates))
            })
            .collect()
    };
    let starts: Vec<usize> = (0..n).step_by(SCREEN_ROWS).collect();
    let blocks: Vec<Vec<usize>> = match parallelism {
        Parallelism::Sequential => starts.iter().map(|&s| block(s)).collect(),
        Parallelism::Rayon => starts.par_iter().map(|&s| block(s)).collect(),
    };
    blocks.concat()
}

fn k_means(x: &Points, k: usize, iterations: usize, seed: u64, parallelism: Parallelism) -> Points {
    let (n, d) = (x.len(), x.dim());
    let k = k.min(n);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // k-means++: each next centre drawn with probability proportional to D(x)².
    let mut chosen = vec![rng.random_range(0..n)];
    let mut d2: Vec<f64> = (0..n).map(|i| squared_distance(x.row(i), x.row(chosen[0]))).collect();
    while chosen.len() < k {
        let total: f64 = d2.iter().sum();
        let next = if total > 0.0 {
            let mut t = rng.random_range(0.0..total);
            d2.iter().position(|&v| {
                t -= v;
                t < 0.0
            })
        } else {
            None
        };
        // All remaining points coincide with a centre: take the first point not yet chosen.
        let next = next.or_else(|| (0..n).find(|i| !chosen.contains(i))).unwrap_or(0);
        chosen.push(next);
        for (i, v) in d2.iter_mut().enumerate() {
            *v = v.min(squared_distance(x.row(i), x.row(next)));
        }
    }
    let mut centres = x.select(&chosen);
    for _ in 0..iterations {
        let labels = labels(x, &centres, parallelism);
        // Sums in point order: the same whatever thread assigned which point.
        let mut sums = vec![0.0; k * d];
        let mut counts = vec![0usize; k];
        for (i, &c) in labels.iter().enumerate() {
            counts[c] += 1;
            for (s, v) in sums[c * d..(c + 1) * d].iter_mut().zip(x.row(i)) {
                *s += v;
            }
        }
        let mut data = centres.as_slice().to_vec();
        for c in 0..k {
            // An empty cluster keeps its centre.
            if counts[c] > 0 {
                for j in 0..d {
                    data[c * d + j] = sums[c * d + j] / counts[c] as f64;
                }
            }
        }
        let moved = Points::from_row_major(d, data);
        if moved == centres {
            break;
        }
        centres = moved;
    }
    centres
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screened_labels_are_the_exact_comparison_s_ties_included() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let d = 7;
        // Far from the origin (large norms: the expansion's worst case), on a coarse grid so that
        // many points are exactly as far from two centres.
        let mut data: Vec<f64> = (0..2500 * d).map(|_| 40.0 + f64::from(rng.random_range(0..6u8)) * 0.5).collect();
        data.extend((0..500 * d).map(|_| rng.random_range(-3.0..3.0)));
        // A cluster far out whose distances differ by less than the expansion's rounding.
        data.extend((0..500 * d).map(|_| 1e3 + rng.random_range(-1e-5..1e-5)));
        let x = Points::from_row_major(d, data);
        let mut centres: Vec<usize> = (0..60).map(|_| rng.random_range(0..x.len())).collect();
        centres.extend((0..20).map(|_| rng.random_range(3000..3500)));
        // Two equal centres: the first of them wins.
        centres.insert(60, centres[0]);
        let centres = x.select(&centres);
        let exact: Vec<usize> = (0..x.len()).map(|i| nearest(x.row(i), &centres, None)).collect();
        assert!(exact.iter().all(|&c| c != 60), "the duplicate centre is never the first of equals");
        // The expansion alone would label some of the far cluster wrongly: the exact comparison
        // after the screen is what makes the labels the same.
        let expanded = |i: usize, c: usize| {
            let (p, q) = (x.row(i), centres.row(c));
            p.iter().map(|v| v * v).sum::<f64>() + q.iter().map(|v| v * v).sum::<f64>()
                - 2.0 * p.iter().zip(q).map(|(a, b)| a * b).sum::<f64>()
        };
        let by_expansion = |i: usize| {
            (0..centres.len())
                .map(|c| (c, expanded(i, c)))
                .fold((0, f64::INFINITY), |b, c| if c.1 < b.1 { c } else { b })
                .0
        };
        assert!((3000..3500).any(|i| by_expansion(i) != exact[i]));
        assert_eq!(labels(&x, &centres, Parallelism::Sequential), exact);
        assert_eq!(labels(&x, &centres, Parallelism::Rayon), exact);
    }
}
