//! Hyperparameters recovered from samples of a known GP (n = 500), for several seeds.
//!
//! Tolerances are honest for n = 500: the noise variance and length scales are pinned down to a
//! few tens of percent; the signal variance, which a single draw on a bounded domain determines
//! poorly, only to a factor of about two.

mod common;

use common::{rng, sample_gp, uniform_points};
use gp::{ExactGp, GpConfig, Kernel, Matern52Ard, OptimiserConfig, QuadraticKernel, SquaredExponentialArd};

fn fit(kernel: &Kernel, seed: u64) -> Kernel {
    let mut r = rng(seed);
    let x = uniform_points(&mut r, 500, 2, -3.0, 3.0);
    let y = sample_gp(&mut r, kernel, &x, 1);
    // The hyperparameters are those of the raw data: no standardisation, no normalisation.
    let config = GpConfig {
        kernel: kernel.choice(),
        standardise_inputs: false,
        normalise_outputs: false,
        optimiser: OptimiserConfig { restarts: 1, seed, ..OptimiserConfig::default() },
        ..GpConfig::default()
    };
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    model.kernel_for_output(0).expect("one output").clone()
}

fn within(estimate: f64, truth: f64, relative: f64) -> bool {
    (estimate / truth - 1.0).abs() <= relative
}

#[test]
fn squared_exponential_hyperparameters_are_recovered_from_its_samples() {
    let truth = SquaredExponentialArd { signal_variance: 1.5, length_scales: vec![0.6, 1.4], noise_variance: 0.04 };
    for seed in [1, 2, 3] {
        let Kernel::SquaredExponentialArd(k) = fit(&Kernel::SquaredExponentialArd(truth.clone()), seed) else {
            panic!("family changed")
        };
        eprintln!("SE seed {seed}: {k:?}");
        assert!(within(k.noise_variance, truth.noise_variance, 0.25), "seed {seed}: {k:?}");
        assert!(within(k.length_scales[0], 0.6, 0.2), "seed {seed}: {k:?}");
        assert!(within(k.length_scales[1], 1.4, 0.25), "seed {seed}: {k:?}");
        assert!(k.signal_variance > 1.5 / 2.5 && k.signal_variance < 1.5 * 2.5, "seed {seed}: {k:?}");
    }
}

#[test]
fn matern52_hyperparameters_are_recovered_from_its_samples() {
    let truth = Matern52Ard { signal_variance: 0.8, length_scales: vec![1.0, 0.5], noise_variance: 0.02 };
    for seed in [4, 5, 6] {
        let Kernel::Matern52Ard(k) = fit(&Kernel::Matern52Ard(truth.clone()), seed) else { panic!("family changed") };
        eprintln!("Matern seed {seed}: {k:?}");
        assert!(within(k.noise_variance, truth.noise_variance, 0.3), "seed {seed}: {k:?}");
        assert!(within(k.length_scales[0], 1.0, 0.25), "seed {seed}: {k:?}");
        assert!(within(k.length_scales[1], 0.5, 0.25), "seed {seed}: {k:?}");
        assert!(k.signal_variance > 0.8 / 2.5 && k.signal_variance < 0.8 * 2.5, "seed {seed}: {k:?}");
    }
}

#[test]
fn quadratic_kernel_length_scale_and_noise_are_recovered_from_its_samples() {
    // θ2 and θ3 are the variances of one random offset and one random slope: a single draw cannot
    // determine them, so only θ0, θ1 and the noise are checked.
    let truth = QuadraticKernel { theta0: 1.0, theta1: 2.0, theta2: 0.5, theta3: 0.3, noise_variance: 0.03 };
    for seed in [7, 8, 9] {
        let Kernel::Quadratic(k) = fit(&Kernel::Quadratic(truth), seed) else { panic!("family changed") };
        eprintln!("Quadratic seed {seed}: {k:?}");
        assert!(within(k.noise_variance, truth.noise_variance, 0.25), "seed {seed}: {k:?}");
        assert!(within(k.theta1, truth.theta1, 0.3), "seed {seed}: {k:?}");
        assert!(k.theta0 > 1.0 / 2.5 && k.theta0 < 2.5, "seed {seed}: {k:?}");
    }
}
