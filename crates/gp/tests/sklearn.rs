//! Agreement with scikit-learn's `GaussianProcessRegressor` on the fixture written by
//! `tests/sklearn/make_fixture.py` (same data, same kernel, same normalisation).

mod common;

use common::close;
use faer::Mat;
use gp::{Bounds, ExactGp, GpConfig, Kernel, KernelChoice, OptimiserConfig, OutputMode, PredictOptions};
use serde::Deserialize;

#[derive(Deserialize)]
struct Fixture {
    x_train: Vec<Vec<f64>>,
    y_train: Vec<Vec<f64>>,
    x_test: Vec<Vec<f64>>,
    cases: Vec<Case>,
}

#[derive(Deserialize)]
struct Case {
    kernel: KernelChoice,
    outputs: Vec<usize>,
    parameters: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    log_marginal_likelihood: f64,
    mean: Vec<Vec<f64>>,
    std_with_noise: Vec<Vec<f64>>,
    optimised_log_marginal_likelihood: f64,
}

fn fixture() -> Fixture {
    serde_json::from_str(include_str!("sklearn/fixture.json")).expect("fixture is valid JSON")
}

fn matrix(rows: &[Vec<f64>]) -> Mat<f64> {
    Mat::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j])
}

fn case_data(f: &Fixture, c: &Case) -> (Mat<f64>, Mat<f64>, Mat<f64>, GpConfig, Kernel) {
    let x = matrix(&f.x_train);
    let y = Mat::from_fn(x.nrows(), c.outputs.len(), |i, k| f.y_train[i][c.outputs[k]]);
    let xt = matrix(&f.x_test);
    let config = GpConfig {
        kernel: c.kernel,
        outputs: OutputMode::Shared,
        standardise_inputs: true,
        normalise_outputs: true,
        bounds: Some(Bounds { lower: c.lower.clone(), upper: c.upper.clone() }),
        ..GpConfig::default()
    };
    let kernel = Kernel::start(c.kernel, x.ncols()).with_parameters(&c.parameters).expect("valid parameters");
    (x, y, xt, config, kernel)
}

#[test]
fn log_marginal_likelihood_and_predictions_match_sklearn_at_fixed_hyperparameters() {
    let f = fixture();
    for c in &f.cases {
        let (x, y, xt, config, kernel) = case_data(&f, c);
        let model = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &[kernel], &config).expect("fit");
        assert_eq!(model.report().components[0].jitter.added, 0.0);
        let lml = model.log_marginal_likelihood();
        assert!(
            close(lml, c.log_marginal_likelihood, 1e-9),
            "{:?}: lml {lml} vs sklearn {}",
            c.kernel,
            c.log_marginal_likelihood
        );
        let options = PredictOptions { variance: true, full_covariance: false, include_noise: true };
        let p = model.predict_with(xt.as_ref(), &options).expect("predict");
        for i in 0..xt.nrows() {
            for k in 0..c.outputs.len() {
                let (mean, std) = (p.mean[(i, k)], p.variance[(i, k)].sqrt());
                assert!(close(mean, c.mean[i][k], 1e-8), "{:?} mean[{i},{k}] {mean} vs {}", c.kernel, c.mean[i][k]);
                assert!(
                    close(std, c.std_with_noise[i][k], 1e-8),
                    "{:?} std[{i},{k}] {std} vs {}",
                    c.kernel,
                    c.std_with_noise[i][k]
                );
            }
        }
    }
}

#[test]
fn optimised_log_marginal_likelihood_is_at_least_sklearns() {
    let f = fixture();
    for c in &f.cases {
        let (x, y, _, config, kernel) = case_data(&f, c);
        // Same number of random restarts as the fixture gave scikit-learn, from its start.
        let config = GpConfig { optimiser: OptimiserConfig { restarts: 4, ..OptimiserConfig::default() }, ..config };
        let model = ExactGp::fit_from(x.as_ref(), y.as_ref(), &kernel, &config).expect("fit");
        let ours = model.log_marginal_likelihood();
        let theirs = c.optimised_log_marginal_likelihood;
        eprintln!("{:?} outputs {:?}: optimised lml ours {ours:.6}, sklearn {theirs:.6}", c.kernel, c.outputs);
        assert!(
            ours >= theirs - 1e-4 * theirs.abs().max(1.0),
            "{:?} {:?}: ours {ours} < sklearn {theirs}",
            c.kernel,
            c.outputs
        );
    }
}
