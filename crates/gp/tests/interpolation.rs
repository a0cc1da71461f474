//! Noiseless interpolation: with (almost) no noise the posterior mean passes through the training
//! points and the posterior variance vanishes there, for every kernel.

mod common;

use common::{rng, uniform_points};
use faer::Mat;
use gp::{ExactGp, GpConfig, Kernel, Matern52Ard, PredictOptions, QuadraticKernel, SquaredExponentialArd};

fn kernels(d: usize) -> Vec<Kernel> {
    let noise_variance = 1e-12;
    vec![
        Kernel::Quadratic(QuadraticKernel { theta0: 1.0, theta1: 4.0, theta2: 0.1, theta3: 0.2, noise_variance }),
        Kernel::SquaredExponentialArd(SquaredExponentialArd {
            signal_variance: 1.0,
            length_scales: vec![0.5; d],
            noise_variance,
        }),
        Kernel::Matern52Ard(Matern52Ard { signal_variance: 1.0, length_scales: vec![0.7; d], noise_variance }),
    ]
}

#[test]
fn posterior_mean_passes_through_training_points_with_zero_variance_there() {
    let (n, d) = (30, 2);
    for seed in [1, 2] {
        let mut r = rng(seed);
        let x = uniform_points(&mut r, n, d, -3.0, 3.0);
        let y = Mat::from_fn(n, 2, |i, c| 40.0 * (x[(i, 0)] + c as f64).sin() * x[(i, 1)].cos() + 7.0);
        let y_scale = 40.0;
        for kernel in kernels(d) {
            let model = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), std::slice::from_ref(&kernel), &GpConfig::default())
                .expect("fit");
            let options = PredictOptions { variance: true, full_covariance: true, include_noise: false };
            let p = model.predict_with(x.as_ref(), &options).expect("predict");
            for c in 0..2 {
                for i in 0..n {
                    let err = (p.mean[(i, c)] - y[(i, c)]).abs();
                    assert!(err < 1e-6 * y_scale, "{kernel:?} seed {seed}: residual {err} at point {i}");
                    assert!(
                        p.variance[(i, c)] < 1e-8 * y_scale * y_scale,
                        "{kernel:?}: variance {}",
                        p.variance[(i, c)]
                    );
                    assert!(p.covariance[c][(i, i)].abs() < 1e-8 * y_scale * y_scale);
                }
            }
            // Away from the data the variance is not zero: the test above is not vacuous.
            let far = Mat::from_fn(1, d, |_, _| 10.0);
            let pf = model.predict(far.as_ref()).expect("predict");
            assert!(pf.variance[(0, 0)] > 1e-3 * y_scale * y_scale, "{kernel:?}: far variance {}", pf.variance[(0, 0)]);
        }
    }
}

#[test]
fn full_covariance_diagonal_equals_the_variance_and_is_symmetric() {
    let mut r = rng(9);
    let x = uniform_points(&mut r, 25, 3, -1.0, 1.0);
    let y = Mat::from_fn(25, 1, |i, _| x[(i, 0)] * x[(i, 2)]);
    let xq = uniform_points(&mut r, 8, 3, -1.5, 1.5);
    for mut kernel in kernels(3) {
        kernel = kernel
            .with_parameters(&{
                let mut p = kernel.parameters();
                *p.last_mut().expect("noise") = 1e-2;
                p
            })
            .expect("valid");
        let model = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &[kernel], &GpConfig::default()).expect("fit");
        for include_noise in [false, true] {
            let options = PredictOptions { variance: true, full_covariance: true, include_noise };
            let p = model.predict_with(xq.as_ref(), &options).expect("predict");
            let cov = &p.covariance[0];
            for i in 0..8 {
                assert!((cov[(i, i)] - p.variance[(i, 0)]).abs() < 1e-12 * (1.0 + p.variance[(i, 0)]));
                for j in 0..8 {
                    assert!((cov[(i, j)] - cov[(j, i)]).abs() < 1e-12);
                }
            }
        }
    }
}
