//! `--effects auto`'s held-out prediction with the GP stage on top. The diagnosis's
//! folds (random rows, and arcs of each moving joint's angles) are used again after the final GP's
//! hyperparameters are chosen: each fold's GP is conditioned on its training rows' residuals alone.

use campaign::{
    CouplingFactor, CouplingModel, CouplingTerm, Effects, GeneratorConfig, Perturbation, TrackerNoiseModel,
    joint_ranges, simulate, simulated_cell,
};
use effects::EffectSelection;
use loadsim::{GearPeriodicModel, Harmonic};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use robot::RobotDescription;

/// The rows whose joint 2 satisfies `keep`.
fn rows_where(all: &MeasurementSet, keep: impl Fn(f64) -> bool) -> MeasurementSet {
    let rows: Vec<usize> = (0..all.rows.len()).filter(|&i| keep(all.rows[i].q[1])).collect();
    all.subset(&rows)
}

/// The gap campaign with joint 3's error also driven by joints 2 and 4 (a coupling no effect
/// candidate models, so the GP is what takes it).
fn coupled_campaign(seed: u64) -> (RobotDescription, MeasurementSet) {
    let robot = testkit::robot("irb4400.ron");
    let harmonic =
        |order: f64, amplitude_rad: f64, phase_rad: f64| Harmonic { joint_index: 1, order, amplitude_rad, phase_rad };
    let periodic = GearPeriodicModel {
        harmonics: vec![harmonic(1.0, 1e-4, 0.3), harmonic(7.0, 2e-4, -1.0), harmonic(12.0, 1e-4, 2.0)],
    };
    let coupling = CouplingModel {
        terms: vec![CouplingTerm {
            joint_index: 2,
            amplitude_rad: 3e-4,
            factors: vec![
                CouplingFactor { source_joint_index: 1, order: 2.0, phase_rad: 0.3 },
                CouplingFactor { source_joint_index: 3, order: 1.0, phase_rad: 1.0 },
            ],
        }],
    };
    let effects = Effects {
        gear_periodic: Some(periodic),
        coupling: Some(coupling),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    let cell = simulated_cell(&robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: 1500, seed, ..GeneratorConfig::default() };
    (robot.clone(), simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap())
}

/// On poses that leave a 40° gap in joint 2 and stop short of its range (the campaign of
/// `effects.rs`'s gap tests, with a coupling only the GP takes): the prediction with the GP is
/// within 25 % of what `poe-gp --effects auto` does, on poses like the training poses
/// (even rows → odd rows, random folds) and in the gap and past the end (joint 2's arcs). Without
/// the GP the random folds' prediction is far above the fitted error there, so the GP's share is
/// what is checked; a GP that saw the held-out rows would predict them near its noise.
#[test]
fn the_prediction_with_the_gp_meets_the_fitted_error_like_the_training_poses_and_in_a_gap() {
    // Seed 53 is the one on which the final GP in place of each fold's fails (0.0272 against
    // 0.0442) and a GP conditioned without a buffer beside the arcs fails (0.0808 against 0.1939).
    prediction_with_the_gp_meets_the_fitted_error(53);
}

/// The same on the gap tests' other seeds: four more `poe-gp --effects auto` fits of 1,500-row
/// campaigns, a minute in the debug profile, so `cargo xtask long-tests` runs it and CI does not.
#[test]
#[ignore = "long (the same property as the test above on two more seeds): cargo xtask long-tests"]
fn the_prediction_with_the_gp_meets_the_fitted_error_on_more_seeds() {
    for seed in [7, 91] {
        prediction_with_the_gp_meets_the_fitted_error(seed);
    }
}

fn prediction_with_the_gp_meets_the_fitted_error(seed: u64) {
    // Seeds 53, 7, 91 (the gap tests' seeds); measured on/even->odd fitted: 0.0503/0.0442,
    // 0.0509/0.0491, 0.0458/0.0511 mm (random folds without the GP: 0.0899, 0.0890, 0.0794); joint
    // 2's arcs/gap fitted: 0.2188/0.1939, 0.2263/0.1895, 0.2181/0.1932 mm. Before the model kept a
    // GP of what the geometry alone leaves for where its effects fade, the gap fitted
    // 0.2580, 0.2697, 0.2831 (predicted 0.2692, 0.2675, 0.2505); that GP's arcs conditioned
    // without a buffer beside them predicted 0.0808 on seed 53, a promise the fit broke.
    let (robot, all) = coupled_campaign(seed);
    let gapped = rows_where(&all, |q| (0.35..=0.9).contains(&q.abs()));
    let off = rows_where(&all, |q| q.abs() < 0.3 || q.abs() > 0.95);
    let even = gapped.subset(&(0..gapped.rows.len()).step_by(2).collect::<Vec<_>>());
    let odd = gapped.subset(&(1..gapped.rows.len()).step_by(2).collect::<Vec<_>>());
    let options = FitOptions::default().with_effects(EffectSelection::Auto);
    let fitted = |train: &MeasurementSet, test: &MeasurementSet| {
        let (model, report) = pipeline::fit(&robot, train, Method::PoeGp, &options).unwrap();
        let error = model::evaluate(&model, &model.bind(test).unwrap()).unwrap().summary.mean_position_error_mm;
        let auto = report.auto.expect("--effects auto");
        let with_gp = auto.predicted_with_gp.clone().expect("a GP method predicts with its GP");
        (error, auto, with_gp)
    };
    let (like, auto, with_gp) = fitted(&even, &odd);
    eprintln!(
        "seed {seed}, even -> odd: fitted {like:.4} mm; predicted {:.4} with the GP, {:.4} without",
        with_gp.on_poses_mm, auto.heldout_after_mm
    );
    assert!(!auto.chosen.is_empty(), "seed {seed}: the gear error is found");
    assert!((with_gp.on_poses_mm - like).abs() <= 0.25 * like, "seed {seed}: {} against {like}", with_gp.on_poses_mm);
    assert!(auto.heldout_after_mm > 1.25 * like, "seed {seed}: the GP takes nothing here");
    let (gap, _, with_gp) = fitted(&gapped, &off);
    let joint_2 = with_gp.arcs.iter().find(|a| a.joint == 2).expect("joint 2 moves").mean_mm;
    eprintln!("seed {seed}, in the gap and past the end: fitted {gap:.4} mm; joint 2's arcs with the GP {joint_2:.4}");
    assert!((joint_2 - gap).abs() <= 0.25 * gap, "seed {seed}: {joint_2} against {gap}");
}
