//! Nanoseconds per call of the SO(3) and SE(3) exponential, logarithm and composition.

use criterion::{Criterion, criterion_group, criterion_main};
use lie::{SE3, SO3, Twist, Vector3};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let w = Vector3::new(0.61, -0.29, 1.37);
    let xi = Twist::new(Vector3::new(0.42, -1.1, 0.73), w);
    let r = SO3::exp(&w);
    let r2 = SO3::exp(&Vector3::new(-0.3, 0.8, 0.1));
    let t = SE3::exp(&xi);
    let t2 = SE3::exp(&Twist::new(Vector3::new(0.1, 0.2, -0.3), Vector3::new(-0.3, 0.8, 0.1)));

    let mut group = c.benchmark_group("so3");
    group.bench_function("exp", |b| b.iter(|| SO3::exp(black_box(&w))));
    group.bench_function("log", |b| b.iter(|| black_box(&r).log()));
    group.bench_function("compose", |b| b.iter(|| black_box(r) * black_box(r2)));
    group.finish();

    let mut group = c.benchmark_group("se3");
    group.bench_function("exp", |b| b.iter(|| SE3::exp(black_box(&xi))));
    group.bench_function("log", |b| b.iter(|| black_box(&t).log()));
    group.bench_function("compose", |b| b.iter(|| black_box(t) * black_box(t2)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
