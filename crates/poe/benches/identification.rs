//! Identification time against the number of measured poses (full pose, 6R, one core).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use lie::{Matrix3, SE3, SO3, Twist, Vector3};
use poe::identify::{IdentificationOptions, Observation, ParameterMask, Target, identify, register};
use poe::{JointAxis, JointKind, LocalPoe};
use std::hint::black_box;

fn irb4400() -> LocalPoe {
    let r = |d: [f64; 3], p: [f64; 3]| JointAxis { kind: JointKind::Revolute, direction: d.into(), point: p.into() };
    let axes = [
        r([0.0, 0.0, 1.0], [0.0, 0.0, 0.0]),
        r([0.0, 1.0, 0.0], [0.2, 0.0, 0.68]),
        r([0.0, 1.0, 0.0], [0.2, 0.0, 1.57]),
        r([1.0, 0.0, 0.0], [1.08, 0.0, 1.72]),
        r([0.0, 1.0, 0.0], [1.08, 0.0, 1.72]),
        r([1.0, 0.0, 0.0], [1.22, 0.0, 1.72]),
    ];
    let flange = SE3::new(
        SO3::from_matrix_unchecked(Matrix3::from_columns(&[-Vector3::z(), Vector3::y(), Vector3::x()])),
        Vector3::new(1.22, 0.0, 1.72),
    );
    LocalPoe::from_zero_configuration(&axes, flange).expect("unit axes")
}

/// A deterministic pseudo-random sequence in [-1, 1) (keeps the bench free of rand).
fn sequence(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

fn data(rows: usize) -> (LocalPoe, Vec<Observation>) {
    let nominal = irb4400();
    let mut next = sequence(rows as u64);
    let mut truth = nominal.clone();
    for joint in truth.joints_mut() {
        let twist =
            Twist::new(Vector3::new(next(), next(), next()) * 0.002, Vector3::new(next(), next(), next()) * 0.002);
        joint.previous_from_joint_zero = twist.exp() * joint.previous_from_joint_zero;
    }
    truth.change_reference(Twist::new(Vector3::new(3.0, -1.0, 0.5), Vector3::new(0.1, 0.2, 1.0)).exp());
    let observations = (0..rows)
        .map(|_| {
            let q: Vec<f64> = (0..6).map(|_| next() * 1.5).collect();
            let pose = truth.forward(&q, 0).expect("six joints");
            Observation { q, tool: 0, target: Target::Pose(pose), stated_sigma: None }
        })
        .collect();
    (nominal, observations)
}

fn bench(c: &mut Criterion) {
    // The target is stated for one core: keep faer's SVD serial.
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("identify_full_pose_6r");
    group.sample_size(20);
    for rows in [100, 300, 1000, 3000] {
        let (nominal, observations) = data(rows);
        let start = register(&nominal, &observations).expect("registration");
        let mask = ParameterMask::all(start.layout());
        let options = IdentificationOptions::default();
        group.bench_with_input(BenchmarkId::from_parameter(rows), &rows, |b, _| {
            b.iter(|| identify(black_box(&start), black_box(&observations), &mask, &options).expect("converges"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
