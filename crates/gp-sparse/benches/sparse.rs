//! Criterion benchmark of the sparse fit with fixed hyperparameters across n (its cost is linear in
//! n), serial and rayon, on the data of gp's benchmarks.
//!
//! `cargo bench -p gp-sparse`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use gp::{Kernel, KernelChoice};
use gp_sparse::{SparseConfig, SparseGp};

#[path = "../../gp/benches/common/mod.rs"]
mod common;

use common::{DIM, config, data, modes};

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

criterion_group!(benches, sparse);
criterion_main!(benches);
