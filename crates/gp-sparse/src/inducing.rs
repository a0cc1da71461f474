//! Choice of inducing inputs for the sparse approximation: a seeded random subset of the training
//! inputs, or k-means centres (k-means++ seeding, Arthur & Vassilvitskii 2007, then Lloyd steps).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use gp::Parallelism;
use gp::blocks::{Points, random_indices};

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

/// `‖a − b‖²`.
#[inline]
fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
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

/// The nearest centre of every point ([`dense::nearest::labels`]: the labels of comparing every
/// exact distance), blocks of points side by side.
fn labels(x: &Points, centres: &Points, parallelism: Parallelism) -> Vec<usize> {
    let d = x.dim().max(1);
    let label = |block: &[f64]| dense::nearest::labels(block, centres.as_slice(), d);
    let blocks: Vec<Vec<usize>> = match parallelism {
        Parallelism::Sequential => x.as_slice().chunks(dense::nearest::SCREEN_ROWS * d).map(label).collect(),
        Parallelism::Rayon => x.as_slice().par_chunks(dense::nearest::SCREEN_ROWS * d).map(label).collect(),
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
