//! What the solvers promise: refusal of data that cannot determine the parameters, "converged"
//! only on a stated criterion, more parameters never a higher cost, unexcited parameters held at
//! their prior, options checked once.

mod common;

use common::{gaussian, irb4400, measured_robot, observe, rng};
use lie::Vector6;
use poe::LocalPoe;
use poe::identify::{
    IdentificationOptions, Observation, ParameterMask, PoseCorrection, Scope, Solver, Target, Termination, calibrate,
    identify, identify_with_correction,
};
use proptest::prelude::*;

/// `δq_j = Σ θ_l φ_l(q)` with random smooth features of every joint's angle, plus one parameter
/// that no pose excites (its twist is zero everywhere).
struct Features {
    q: Vec<Vec<f64>>,
    frequencies: Vec<(usize, f64, f64)>,
    prior: f64,
}

impl PoseCorrection for Features {
    fn parameter_count(&self) -> usize {
        self.frequencies.len() + 1
    }

    fn twists(&self, model: &LocalPoe, index: usize, out: &mut [Vector6]) {
        let q = &self.q[index];
        let twists = model.spatial_twists(q).unwrap();
        for (o, &(joint, frequency, phase)) in out.iter_mut().zip(&self.frequencies) {
            *o = twists[joint].to_vector() * (frequency * q[joint] + phase).sin();
        }
        out[self.frequencies.len()] = Vector6::zeros();
    }

    fn prior_sigma(&self, _: usize) -> f64 {
        self.prior
    }
}

fn noisy_positions(seed: u64, n: usize, sigma: f64) -> (LocalPoe, Vec<Observation>) {
    let (nominal, limits) = irb4400();
    let mut r = rng(seed);
    let truth = measured_robot(&nominal, &mut r);
    let mut observations = observe(&truth, &limits, n, false, 0.0, 0.0, &mut r);
    for o in &mut observations {
        if let Target::Point(p) = &mut o.target {
            for k in 0..3 {
                // Noise plus an unmodelled joint-angle error the features partly explain.
                p[k] += sigma * gaussian(&mut r) + 2e-4 * (3.0 * o.q[1]).sin() * (k as f64 - 1.0);
            }
        }
    }
    (nominal, observations)
}

fn lm(prior: f64) -> IdentificationOptions {
    IdentificationOptions {
        solver: Solver::LevenbergMarquardt,
        position_sigma_m: 2e-5,
        prior_translation_m: prior,
        prior_rotation_rad: prior,
        ..IdentificationOptions::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 12,
        rng_seed: proptest::test_runner::RngSeed::Fixed(20261126),
        ..ProptestConfig::default()
    })]

    /// Started from the smaller model's solution with the new parameters at zero, the larger fit's
    /// data cost ends at or below the smaller one's, with or without a prior.
    #[test]
    fn a_superset_of_parameters_never_ends_at_a_higher_training_cost(
        seed in 0_u64..1000,
        count in 1_usize..6,
        with_prior in any::<bool>(),
    ) {
        let (nominal, observations) = noisy_positions(seed, 40, 2e-5);
        let prior = if with_prior { 1e-3 } else { f64::INFINITY };
        let options = lm(prior);
        let base = calibrate(&nominal, &observations, Scope::BaseTool, &options).unwrap();
        // Subset: the kinematics alone; superset: the same plus `count` feature parameters.
        let mask = ParameterMask::all(base.model.layout());
        let subset = identify(&base.model, &observations, &mask, &options).unwrap();
        let mut r = rng(seed + 1);
        let frequencies = (0..count)
            .map(|k| (k % 6, 1.0 + (k as f64) * 0.7, gaussian(&mut r)))
            .collect();
        let features = Features { q: observations.iter().map(|o| o.q.clone()).collect(), frequencies, prior };
        let superset =
            identify_with_correction(&subset.model, &observations, &mask, Some(&features), &options).unwrap();
        let data_cost = |model: &LocalPoe, theta: Option<&[f64]>| -> f64 {
            observations
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    let mut pose = model.forward(&o.q, o.tool).unwrap();
                    if let Some(theta) = theta {
                        let mut twists = vec![Vector6::zeros(); features.parameter_count()];
                        features.twists(model, i, &mut twists);
                        let total: Vector6 = twists.iter().zip(theta).map(|(c, t)| c * *t).sum();
                        pose = lie::Twist::from_vector(&total).exp() * pose;
                    }
                    let Target::Point(p) = o.target else { unreachable!() };
                    ((p - pose.translation()) / 2e-5).norm_squared()
                })
                .sum()
        };
        let before = data_cost(&subset.model, None);
        let after = data_cost(&superset.model, Some(&superset.correction));
        prop_assert!(after <= before * (1.0 + 1e-12), "superset {after} > subset {before}");
    }
}

#[test]
fn thirteen_position_only_poses_cannot_determine_a_six_axis_arm() {
    let (nominal, observations) = noisy_positions(3, 13, 2e-5);
    let error = calibrate(&nominal, &observations, Scope::Full, &IdentificationOptions::default()).unwrap_err();
    assert_eq!(error, poe::Error::TooFewObservations { observations: 13, rows: 39, parameters: 42 });
    let message = error.to_string();
    assert!(message.contains("39") && message.contains("42"), "{message}");
    // The base-tool baseline's 12 parameters are determined by the same rows.
    assert!(calibrate(&nominal, &observations, Scope::BaseTool, &IdentificationOptions::default()).is_ok());
}

#[test]
fn an_iteration_limit_is_not_reported_as_convergence() {
    let (nominal, observations) = noisy_positions(4, 60, 2e-5);
    let base = calibrate(&nominal, &observations, Scope::BaseTool, &IdentificationOptions::default()).unwrap();
    for solver in [Solver::PseudoInverse, Solver::LevenbergMarquardt] {
        let options = IdentificationOptions { solver, max_iterations: 1, ..IdentificationOptions::default() };
        let fit = identify(&base.model, &observations, &ParameterMask::all(base.model.layout()), &options).unwrap();
        assert!(!fit.report.converged, "{solver:?}: {}", fit.report.termination);
        assert_eq!(fit.report.termination, Termination::IterationLimit { iterations: 1 });
        assert!(fit.report.termination.to_string().starts_with("NOT converged"));
    }
}

#[test]
fn convergence_names_the_criterion_it_met() {
    let (nominal, observations) = noisy_positions(5, 60, 2e-5);
    for solver in [Solver::PseudoInverse, Solver::LevenbergMarquardt] {
        let options = IdentificationOptions { solver, ..IdentificationOptions::default() };
        let fit = calibrate(&nominal, &observations, Scope::Full, &options).unwrap();
        assert!(fit.report.converged, "{solver:?}: {}", fit.report.termination);
        assert!(fit.report.gradient_cosine < 1e-6, "{solver:?}: {:e}", fit.report.gradient_cosine);
        let cost = fit.report.iterations.last().unwrap().cost;
        assert_eq!(cost, fit.report.final_cost);
    }
}

#[test]
fn a_parameter_no_pose_excites_stays_at_its_prior_and_is_named() {
    let (nominal, observations) = noisy_positions(6, 80, 2e-5);
    let options = lm(1e-3);
    let base = calibrate(&nominal, &observations, Scope::Full, &IdentificationOptions::default()).unwrap();
    let features = Features {
        q: observations.iter().map(|o| o.q.clone()).collect(),
        frequencies: vec![(1, 3.0, 0.0)],
        prior: 1e-3,
    };
    let mask = ParameterMask::all(base.model.layout());
    let fit = identify_with_correction(&base.model, &observations, &mask, Some(&features), &options).unwrap();
    assert_eq!(fit.correction[1], 0.0);
    assert_eq!(fit.report.held_at_prior, vec![1]);
    // The excited feature is determined by the data and identified (the truth has 2e-4 m of it).
    assert!(fit.correction[0].abs() > 1e-5, "{}", fit.correction[0]);
}

#[test]
fn options_out_of_range_are_refused_once_before_any_work() {
    let (nominal, observations) = noisy_positions(7, 40, 2e-5);
    let cases: [(IdentificationOptions, &str); 5] = [
        (IdentificationOptions { cost_tolerance: -1.0, ..Default::default() }, "cost_tolerance"),
        (IdentificationOptions { rcond: 2.0, ..Default::default() }, "rcond"),
        (IdentificationOptions { position_sigma_m: f64::NAN, ..Default::default() }, "position_sigma_m"),
        (IdentificationOptions { max_iterations: 0, ..Default::default() }, "max_iterations"),
        (IdentificationOptions { initial_damping: 1e20, ..Default::default() }, "initial_damping"),
    ];
    for (options, field) in cases {
        let error = calibrate(&nominal, &observations, Scope::Full, &options).unwrap_err();
        assert!(matches!(error, poe::Error::InvalidOption { name, .. } if name == field), "{field}: {error}");
    }
}
