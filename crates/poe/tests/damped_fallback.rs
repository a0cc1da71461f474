//! On a 7-axis arm whose joints 3–7 barely move (the wrist held within 2 mrad of zero,
//! positions only) the pseudo-inverse Gauss–Newton direction overshoots along the weakly
//! determined directions so far that no halving of it lowers the cost, and the fit stopped at
//! its start after 0 iterations. Damped steps must be tried before giving up.

mod common;

use common::{gaussian, iiwa7, measured_robot, rng};
use lie::Vector3;
use poe::identify::{IdentificationOptions, Observation, Scope, Target, calibrate};
use rand::Rng;

/// Positions of an iiwa 7 with joints 1 and 2 moving over their range, the others within 2 mrad
/// of zero; noise plus a smooth error of joint 2's angle that no geometry explains.
fn wrist_held_still(seed: u64, count: usize) -> (poe::LocalPoe, Vec<Observation>) {
    let (nominal, limits) = iiwa7();
    let mut r = rng(seed);
    let truth = measured_robot(&nominal, &mut r);
    let observations = (0..count)
        .map(|_| {
            let q: Vec<f64> = limits
                .iter()
                .enumerate()
                .map(|(j, &(lo, hi))| if j < 2 { r.random_range(lo * 0.9..hi * 0.9) } else { 2e-3 * gaussian(&mut r) })
                .collect();
            let noise = Vector3::new(gaussian(&mut r), gaussian(&mut r), gaussian(&mut r)) * 5e-5;
            let unmodelled = Vector3::new(1.0, -1.0, 0.5) * 3e-4 * (3.0 * q[1]).sin();
            let point = truth.forward(&q, 0).unwrap().translation() + noise + unmodelled;
            Observation { q, tool: 0, target: Target::Point(point), stated_sigma: None }
        })
        .collect();
    (nominal, observations)
}

#[test]
fn where_no_gauss_newton_step_lowers_the_cost_damped_steps_still_do() {
    // Seed 3: the first pseudo-inverse step of the full identification lowers nothing even
    // halved 12 times (before the fallback: 0 iterations, `LineSearchFailed`).
    let (nominal, observations) = wrist_held_still(3, 80);
    let fit = calibrate(&nominal, &observations, Scope::Full, &IdentificationOptions::default()).unwrap();
    let report = &fit.report;
    let fallback = report.damping_fallback.expect("the Gauss–Newton direction fails here: damping must take over");
    assert_eq!(fallback.after_iteration, 0, "{fallback}");
    assert!(fallback.gradient_cosine > 0.1, "{fallback}");
    assert!(report.iteration_count() > 0, "{}", report.termination);
    let start = report.iterations[0].cost;
    assert!(report.final_cost < 0.5 * start, "start {start:e}, end {:e}", report.final_cost);
    // Honest words: convergence only on a criterion, and the damping said.
    assert_eq!(report.converged, report.termination.converged());
    assert!(fallback.to_string().contains("Levenberg–Marquardt"), "{fallback}");
}

#[test]
fn a_gauss_newton_fit_that_needs_no_damping_reports_none() {
    let (nominal, limits) = iiwa7();
    let mut r = rng(11);
    let truth = measured_robot(&nominal, &mut r);
    let observations = common::observe(&truth, &limits, 60, true, 2e-5, 2e-5, &mut r);
    let fit = calibrate(&nominal, &observations, Scope::Full, &IdentificationOptions::default()).unwrap();
    assert!(fit.report.converged, "{}", fit.report.termination);
    assert_eq!(fit.report.damping_fallback, None);
}
