//! Criterion benchmarks of the gp crate: the log marginal likelihood with its gradient (the unit of
//! work of the hyperparameter search), the full fit with the search, prediction, and the sparse
//! fit, across n so that the scaling exponent can be read off, serial and rayon.
//!
//! `cargo bench -p gp`; `cargo xtask bench-gp` prints the summary table with scikit-learn.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use gp::{
    ExactGp, GpConfig, Kernel, KernelChoice, OptimiserConfig, OutputMode, Parallelism, SparseConfig, SparseGp,
    log_marginal_likelihood,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const DIM: usize = 7;
const OUTPUTS: usize = 6;

/// Robot-like data: six joint angles and a payload in, six smooth outputs.
fn data(n: usize, seed: u64) -> (Mat<f64>, Mat<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x = Mat::from_fn(n, DIM, |_, j| if j < 6 { rng.random_range(-2.5..2.5) } else { rng.random_range(1.0..7.5) });
    let y = Mat::from_fn(n, OUTPUTS, |i, k| {
        (x[(i, 1)] + 0.7 * k as f64).sin() * (1.0 + 0.1 * x[(i, 6)])
            + 0.3 * (2.0 * x[(i, 0)]).cos()
            + 0.02 * rng.random::<f64>()
    });
    (x, y)
}

fn modes() -> [(&'static str, Parallelism); 2] {
    [("serial", Parallelism::Sequential), ("rayon", Parallelism::Rayon)]
}

fn config(parallelism: Parallelism) -> GpConfig {
    GpConfig {
        kernel: KernelChoice::Quadratic,
        outputs: OutputMode::Shared,
        parallelism,
        optimiser: OptimiserConfig { restarts: 0, ..OptimiserConfig::default() },
        ..GpConfig::default()
    }
}

fn lml_gradient(c: &mut Criterion) {
    let mut group = c.benchmark_group("lml_gradient");
    group.sample_size(10);
    let kernel = Kernel::start(KernelChoice::Quadratic, DIM);
    for n in [100, 300, 1000, 2000] {
        let (x, y) = data(n, 1);
        for (name, par) in modes() {
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| black_box(log_marginal_likelihood(&kernel, x.as_ref(), y.as_ref(), true, par)))
            });
        }
    }
    group.finish();
}

fn fit(c: &mut Criterion) {
    let mut group = c.benchmark_group("fit_with_search");
    group.sample_size(10);
    for n in [100, 300, 1000] {
        let (x, y) = data(n, 2);
        for (name, par) in modes() {
            let cfg = config(par);
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| black_box(ExactGp::fit(x.as_ref(), y.as_ref(), &cfg)))
            });
        }
    }
    group.finish();
}

fn predict(c: &mut Criterion) {
    let mut group = c.benchmark_group("predict_1000_points");
    group.sample_size(10);
    let (xq, _) = data(1000, 3);
    let kernel = Kernel::start(KernelChoice::Quadratic, DIM);
    for n in [100, 300, 1000, 3000] {
        let (x, y) = data(n, 4);
        for (name, par) in modes() {
            let model = match ExactGp::fit_fixed(x.as_ref(), y.as_ref(), std::slice::from_ref(&kernel), &config(par)) {
                Ok(m) => m,
                Err(e) => panic!("benchmark model does not fit: {e}"),
            };
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| black_box(model.predict(xq.as_ref())))
            });
        }
    }
    group.finish();
}

fn sparse(c: &mut Criterion) {
    let mut group = c.benchmark_group("sparse_fit_fixed_300_inducing");
    group.sample_size(10);
    let kernel = Kernel::start(KernelChoice::Quadratic, DIM);
    for n in [1000, 3000, 10000] {
        let (x, y) = data(n, 5);
        for (name, par) in modes() {
            let cfg = SparseConfig { gp: config(par), inducing_points: 300, ..SparseConfig::default() };
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| black_box(SparseGp::fit_fixed(x.as_ref(), y.as_ref(), std::slice::from_ref(&kernel), &cfg)))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, lml_gradient, fit, predict, sparse);
criterion_main!(benches);
