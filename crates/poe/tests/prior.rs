//! The prior toward a model: a strong one holds the links at its centre whatever the
//! start, while the base placement and the tools still fit; none at all is the plain
//! least-squares fit; between them the links move from the one to the other.

mod common;

use common::{irb4400, measured_robot, observe, rng};
use poe::LocalPoe;
use poe::identify::{
    IdentificationOptions, KinematicPrior, ParameterMask, Scope, Solver, calibrate_placed, calibrate_placed_with_prior,
    identify_with_prior, posterior_covariance,
};

/// The largest difference of the links' local transforms (joints 2…n), metres of translation.
fn link_distance(a: &LocalPoe, b: &LocalPoe) -> f64 {
    a.joints()[1..]
        .iter()
        .zip(&b.joints()[1..])
        .map(|(x, y)| (x.previous_from_joint_zero * y.previous_from_joint_zero.inverse()).log().v.norm())
        .fold(0.0, f64::max)
}

#[test]
fn a_strong_prior_holds_the_links_at_its_centre_and_none_is_the_plain_fit() {
    let (nominal, limits) = irb4400();
    let mut r = rng(7);
    let truth = measured_robot(&nominal, &mut r);
    let observations = observe(&truth, &limits, 120, true, 1e-5, 1e-5, &mut r);
    let options = IdentificationOptions::default();
    let (placed, plain) = calibrate_placed(&nominal, &observations, Scope::Full, &options).unwrap();
    let error = |m: &LocalPoe| common::mean_position_error(m, &observations);
    let (_, strong) =
        calibrate_placed_with_prior(&nominal, &observations, Scope::Full, Some((1e-9, 1e-9)), &options).unwrap();
    let (_, none) = calibrate_placed_with_prior(
        &nominal,
        &observations,
        Scope::Full,
        Some((f64::INFINITY, f64::INFINITY)),
        &options,
    )
    .unwrap();
    let (_, middle) =
        calibrate_placed_with_prior(&nominal, &observations, Scope::Full, Some((1e-4, 1e-4)), &options).unwrap();
    let moved = link_distance(&plain.model, &placed);
    eprintln!(
        "links moved by the plain fit {moved:.2e} m; strong prior {:.2e}, middle {:.2e}, none {:.2e}; errors: placed \
         {:.3e}, strong {:.3e}, middle {:.3e}, none {:.3e}, plain {:.3e} m",
        link_distance(&strong.model, &placed),
        link_distance(&middle.model, &placed),
        link_distance(&none.model, &placed),
        error(&placed),
        error(&strong.model),
        error(&middle.model),
        error(&none.model),
        error(&plain.model)
    );
    assert!(moved > 1e-4, "the measured robot differs from the nominal: {moved}");
    assert!(link_distance(&strong.model, &placed) < 1e-3 * moved);
    // The base and tool still fit under the strong prior: no worse than the placed nominal.
    assert!(error(&strong.model) <= error(&placed) * 1.0001);
    // No prior: the plain fit's error, to the noise.
    assert!((error(&none.model) - error(&plain.model)).abs() < 1e-6, "{} {}", error(&none.model), error(&plain.model));
    let between = link_distance(&middle.model, &placed);
    assert!(between > link_distance(&strong.model, &placed) && error(&middle.model) < error(&strong.model));
}

#[test]
fn the_prior_is_about_its_centre_not_the_start() {
    let (nominal, limits) = irb4400();
    let mut r = rng(8);
    let truth = measured_robot(&nominal, &mut r);
    let observations = observe(&truth, &limits, 80, true, 1e-5, 1e-5, &mut r);
    let options = IdentificationOptions { solver: Solver::LevenbergMarquardt, ..IdentificationOptions::default() };
    let (placed, plain) = calibrate_placed(&nominal, &observations, Scope::Full, &options).unwrap();
    // Started from the plain fit, a strong prior about the placed nominal brings the links back.
    let prior = KinematicPrior::on_links(placed.clone(), 1e-9, 1e-9);
    let mask = ParameterMask::all(placed.layout());
    let back = identify_with_prior(&plain.model, &observations, &mask, None, Some(&prior), &options).unwrap();
    let start = link_distance(&plain.model, &placed);
    let end = link_distance(&back.model, &placed);
    eprintln!("links from the centre: start {start:.2e} m, end {end:.2e} m");
    assert!(end < 1e-3 * start, "{end} against {start}");
}

/// The posterior covariance at a fitted model under the prior it was fitted with is the fit's own
/// (the same linearisation, weights and χ²); under a wider prior, every variance is at least as
/// large, and a direction the poses hardly see (the joints' range held to a tenth of a turn)
/// widens toward the wider prior's width.
#[test]
fn the_posterior_covariance_at_a_fit_is_its_own_and_widens_with_the_prior() {
    let (nominal, limits) = irb4400();
    let mut r = rng(9);
    let truth = measured_robot(&nominal, &mut r);
    let narrow: Vec<(f64, f64)> =
        limits.iter().map(|&(low, high)| (0.05 * (low + high), 0.05 * (low + high) + 0.3)).collect();
    let observations = observe(&truth, &narrow, 80, true, 1e-5, 1e-5, &mut r);
    let options = IdentificationOptions { solver: Solver::LevenbergMarquardt, ..IdentificationOptions::default() };
    let (placed, _) = calibrate_placed(&nominal, &observations, Scope::Full, &options).unwrap();
    let mask = ParameterMask::all(placed.layout());
    let tight = KinematicPrior::on_links(placed.clone(), 1e-5, 1e-5);
    let fit = identify_with_prior(&placed, &observations, &mask, None, Some(&tight), &options).unwrap();
    let own = posterior_covariance(&fit.model, &observations, &mask, None, &tight, &options).unwrap();
    let p = mask.free_indices().len();
    assert_eq!((fit.covariance.len(), own.len()), (p * p, p * p));
    let largest = fit.covariance.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let differs = fit.covariance.iter().zip(&own).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(differs <= 1e-6 * largest, "{differs:e} of {largest:e}");
    let wide = KinematicPrior::on_links(placed.clone(), 1e-3, 1e-3);
    let wider = posterior_covariance(&fit.model, &observations, &mask, None, &wide, &options).unwrap();
    let diagonal = |c: &[f64], i: usize| c[i * p + i];
    for i in 0..p {
        assert!(
            diagonal(&wider, i) >= diagonal(&own, i) * (1.0 - 1e-9),
            "{i}: {} {}",
            diagonal(&wider, i),
            diagonal(&own, i)
        );
    }
    let widest = (0..p).map(|i| diagonal(&wider, i).sqrt()).fold(0.0, f64::max);
    let was = (0..p).map(|i| diagonal(&own, i).sqrt()).fold(0.0, f64::max);
    eprintln!("largest σ: {was:.2e} under the fit's prior, {widest:.2e} under one 100 times wider");
    assert!(widest > 5.0 * was, "{widest:e} {was:e}");
}
