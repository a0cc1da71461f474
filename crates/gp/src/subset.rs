//! Seeded random subsets of the training rows (the search's warm start here, the sparse GP's
//! subsets and inducing inputs in `gp-sparse`): the same rows for the same seed on every machine.

use rand::SeedableRng;
use rand::seq::index::sample;
use rand_chacha::ChaCha8Rng;

/// `count` distinct indices out of `0..n`, sorted, from `seed`.
pub fn random_indices(n: usize, count: usize, seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut indices = sample(&mut rng, n, count.min(n)).into_vec();
    indices.sort_unstable();
    indices
}
