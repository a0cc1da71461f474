//! Helpers shared by the integration tests (gp's and gp-sparse's): seeded data, GP samples and
//! central differences.
#![allow(dead_code)]

use faer::Mat;
use gp::{AdditiveTerm, CompositeKernel, Kernel, Matern52Ard, QuadraticKernel, SquaredExponentialArd, StationaryShape};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// `n × d` points uniform in `[lo, hi]`.
pub fn uniform_points(rng: &mut ChaCha8Rng, n: usize, d: usize, lo: f64, hi: f64) -> Mat<f64> {
    Mat::from_fn(n, d, |_, _| rng.random_range(lo..hi))
}

/// One kernel of each family, and the composite kernel with each shape and each choice of its
/// optional terms, with random parameters (natural scale between 0.3 and 3).
pub fn random_kernels(rng: &mut ChaCha8Rng, d: usize) -> Vec<Kernel> {
    let mut p = || rng.random_range(0.3f64.ln()..3.0f64.ln()).exp();
    let mut composites = Vec::new();
    for shape in [StationaryShape::SquaredExponential, StationaryShape::Matern52] {
        for (constant, linear, additive) in
            [(true, true, false), (true, false, false), (false, true, false), (false, false, true), (true, true, true)]
        {
            composites.push(Kernel::Composite(CompositeKernel {
                shape,
                signal_variance: p(),
                length_scales: (0..d).map(|_| p()).collect(),
                constant: constant.then(&mut p),
                linear_weights: linear.then(|| (0..d).map(|_| p()).collect()),
                additive: additive.then(|| AdditiveTerm {
                    variances: (0..d).map(|_| p()).collect(),
                    length_scales: (0..d).map(|_| p()).collect(),
                }),
                noise_variance: p(),
            }));
        }
    }
    let mut kernels = vec![
        Kernel::Quadratic(QuadraticKernel { theta0: p(), theta1: p(), theta2: p(), theta3: p(), noise_variance: p() }),
        Kernel::SquaredExponentialArd(SquaredExponentialArd {
            signal_variance: p(),
            length_scales: (0..d).map(|_| p()).collect(),
            noise_variance: p(),
        }),
        Kernel::Matern52Ard(Matern52Ard {
            signal_variance: p(),
            length_scales: (0..d).map(|_| p()).collect(),
            noise_variance: p(),
        }),
    ];
    kernels.extend(composites);
    kernels
}

/// `m` independent draws `y ~ N(0, K(X, X) + σn² I)` (columns), by a Cholesky factor computed
/// here independently of the crate (plain triple loop).
pub fn sample_gp(rng: &mut ChaCha8Rng, kernel: &Kernel, x: &Mat<f64>, m: usize) -> Mat<f64> {
    let n = x.nrows();
    let row = |i: usize| (0..x.ncols()).map(|j| x[(i, j)]).collect::<Vec<_>>();
    let rows: Vec<Vec<f64>> = (0..n).map(row).collect();
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut s = kernel.value(&rows[i], &rows[j]);
            if i == j {
                s += kernel.noise_variance();
            }
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            l[i * n + j] = if i == j { s.max(0.0).sqrt() } else { s / l[j * n + j] };
        }
    }
    let mut y = Mat::zeros(n, m);
    for c in 0..m {
        let z: Vec<f64> = (0..n).map(|_| rng.sample(StandardNormal)).collect();
        for i in 0..n {
            y[(i, c)] = (0..=i).map(|k| l[i * n + k] * z[k]).sum();
        }
    }
    y
}

/// `|a − b| ≤ tol · max(1, |a|, |b|)`.
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

const STEP: f64 = 1e-5;

/// Central difference of `f` in log-parameter `j`.
pub fn central_difference(kernel: &Kernel, j: usize, f: impl Fn(&Kernel) -> f64) -> f64 {
    let p = kernel.log_parameters();
    let mut plus = p.clone();
    plus[j] += STEP;
    let mut minus = p;
    minus[j] -= STEP;
    let kp = kernel.with_log_parameters(&plus).expect("finite parameters");
    let km = kernel.with_log_parameters(&minus).expect("finite parameters");
    (f(&kp) - f(&km)) / (2.0 * STEP)
}
