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

#[test]
fn the_prior_variance_bounds_the_posterior_and_is_reached_far_from_the_data() {
    let (n, d) = (30, 2);
    let mut r = rng(4);
    let x = uniform_points(&mut r, n, d, -3.0, 3.0);
    let y = Mat::from_fn(n, 1, |i, _| 40.0 * x[(i, 0)].sin() * x[(i, 1)].cos() + 7.0);
    for kernel in kernels(d).into_iter().skip(1) {
        let model = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), std::slice::from_ref(&kernel), &GpConfig::default())
            .expect("fit");
        let queries = Mat::from_fn(3, d, |i, c| if i == 0 { x[(0, c)] } else { [0.5, 40.0][i - 1] * (c as f64 + 1.0) });
        let p = model.predict(queries.as_ref()).expect("predict");
        assert_eq!((p.prior_variance.nrows(), p.prior_variance.ncols()), (3, 1));
        // A stationary kernel's prior variance is the same everywhere.
        let prior = p.prior_variance[(0, 0)];
        assert!(prior > 0.0 && (p.prior_variance[(2, 0)] - prior).abs() < 1e-12 * prior, "{kernel:?}");
        // At a training point the data explain nearly all of it; between them some; far away none.
        let ratio = |i: usize| p.variance[(i, 0)] / p.prior_variance[(i, 0)];
        assert!(
            ratio(0) < 1e-6 && ratio(1) < 1.0 && (ratio(2) - 1.0).abs() < 1e-9,
            "{kernel:?}: {:?}",
            [0, 1, 2].map(ratio)
        );
    }
    // Without the variance, no prior variance either.
    let model = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &kernels(d)[1..2], &GpConfig::default()).expect("fit");
    let options = PredictOptions { variance: false, full_covariance: false, include_noise: false };
    assert_eq!(model.predict_with(x.as_ref(), &options).expect("predict").prior_variance.nrows(), 0);
}

#[test]
fn the_prior_variance_alone_is_the_predictions_to_the_bit() {
    let (n, d) = (30, 2);
    let mut r = rng(6);
    let x = uniform_points(&mut r, n, d, -3.0, 3.0);
    // Two outputs of different scales, so that each output's normalisation shows.
    let y = Mat::from_fn(n, 2, |i, j| (40.0 * x[(i, 0)].sin() + 3.0 * x[(i, 1)]) * [1.0, 0.01][j] + 7.0);
    let queries = uniform_points(&mut r, 9, d, -6.0, 6.0);
    for kernel in kernels(d) {
        let model = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &[kernel.clone(), kernel.clone()], &GpConfig::default())
            .expect("fit");
        let full = model.predict(queries.as_ref()).expect("predict").prior_variance;
        let alone = model.prior_variance(queries.as_ref()).expect("prior variance");
        assert_eq!((alone.nrows(), alone.ncols()), (9, 2));
        for i in 0..9 {
            for j in 0..2 {
                assert_eq!(alone[(i, j)].to_bits(), full[(i, j)].to_bits(), "{kernel:?} ({i}, {j})");
            }
        }
    }
}
