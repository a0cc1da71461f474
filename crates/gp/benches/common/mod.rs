//! What the benchmarks of gp and gp-sparse share: robot-like data and the configurations they run.
#![allow(dead_code)]

use faer::Mat;
use gp::{GpConfig, KernelChoice, OptimiserConfig, OutputMode, Parallelism};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const DIM: usize = 7;
pub const OUTPUTS: usize = 6;

/// Robot-like data: six joint angles and a payload in, six smooth outputs.
pub fn data(n: usize, seed: u64) -> (Mat<f64>, Mat<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x = Mat::from_fn(n, DIM, |_, j| if j < 6 { rng.random_range(-2.5..2.5) } else { rng.random_range(1.0..7.5) });
    let y = Mat::from_fn(n, OUTPUTS, |i, k| {
        (x[(i, 1)] + 0.7 * k as f64).sin() * (1.0 + 0.1 * x[(i, 6)])
            + 0.3 * (2.0 * x[(i, 0)]).cos()
            + 0.02 * rng.random::<f64>()
    });
    (x, y)
}

pub fn modes() -> [(&'static str, Parallelism); 2] {
    [("serial", Parallelism::Sequential), ("rayon", Parallelism::Rayon)]
}

pub fn config(parallelism: Parallelism) -> GpConfig {
    GpConfig {
        kernel: KernelChoice::Quadratic,
        outputs: OutputMode::Shared,
        parallelism,
        optimiser: OptimiserConfig { restarts: 0, ..OptimiserConfig::default() },
        ..GpConfig::default()
    }
}
