//! Criterion benchmarks of the gp crate: the log marginal likelihood with its gradient (the unit of
//! work of the hyperparameter search), the full fit with the search and prediction, across n so
//! that the scaling exponent can be read off, serial and rayon (the sparse fit's: gp-sparse's).
//!
//! `cargo bench -p gp`; `cargo xtask bench-gp` prints the summary table with scikit-learn.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use gp::{ExactGp, Kernel, KernelChoice, log_marginal_likelihood};

mod common;

use common::{DIM, config, data, modes};

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

criterion_group!(benches, lml_gradient, fit, predict);
criterion_main!(benches);
