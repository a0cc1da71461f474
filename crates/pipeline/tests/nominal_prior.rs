//! The prior toward the nominal geometry (issue 30): fitted on one wrist configuration and
//! evaluated on the flipped one, a calibrated model is no further off than the nominal geometry
//! (at its fitted base and tool placement), and `eval` says the rows lie outside the fitted range.

use loadsim::{Harmonic, JointRange, PeriodicError};
use pipeline::effects::EffectSelection;
use pipeline::simulated::{Effects, GeneratorConfig, Perturbation, TrackerNoise, simulate, simulated_cell};
use pipeline::{EvalReport, FitOptions, MeasurementSet, Method, RobotDescription};
use std::f64::consts::PI;
use std::path::PathBuf;

fn ur10() -> RobotDescription {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots/ur10.ron");
    RobotDescription::read(&path).unwrap()
}

/// A gear error of orders 2 and 3 on joints 2 and 3 and of order 1 on joint 5, 0.6–1 mrad: what a
/// geometry cannot hold. On one side of the wrist's singular angle the joint-5 term looks like an
/// offset of that joint, which a plain fit takes into its links and carries, with the wrong sign,
/// to the other side.
fn gear_error() -> PeriodicError {
    let harmonic = |joint_index: usize, order: f64, amplitude_rad: f64, phase_rad: f64| Harmonic {
        joint_index,
        order,
        amplitude_rad,
        phase_rad,
    };
    PeriodicError {
        harmonics: vec![harmonic(1, 2.0, 1e-3, 0.4), harmonic(2, 3.0, 6e-4, -1.2), harmonic(4, 1.0, 1e-3, 0.0)],
    }
}

/// `count` poses of the same cell with joint 5 on one side of its singular angle (`flipped`:
/// the other side), elbow up and down both, the tracker's noise and the gear error.
fn wrist(seed: u64, count: usize, flipped: bool) -> MeasurementSet {
    let robot = ur10();
    // A well-made arm: 0.1 mm and 0.1 mrad per component, so that the nominal geometry misses
    // by under a millimetre and the non-geometric error is as large as the geometric one (the
    // case of issue 30: poe 12.9 mm on the third solution space against the nominal's 10.5).
    let geometry = Perturbation { translation_m: 1e-4, rotation_rad: 1e-4, ..Perturbation::default() };
    let turn = |lower_rad: f64, upper_rad: f64| JointRange { lower_rad, upper_rad };
    let wrist = if flipped { turn(-PI + 0.2, -0.2) } else { turn(0.2, PI - 0.2) };
    let ranges = [turn(-PI, PI), turn(-PI, 0.0), turn(-PI + 0.2, PI - 0.2), turn(-PI, PI), wrist, turn(-PI, PI)];
    let effects =
        Effects { periodic: Some(gear_error()), tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
    // Separate pose streams for the two sides; the cell (geometry, tool) is the seed's.
    let config = GeneratorConfig { sample_count: count, seed: seed + u64::from(flipped) * 1000, ..Default::default() };
    let mut set =
        simulate(&simulated_cell(&robot, &geometry, seed).unwrap(), &effects, &ranges, &config, false).unwrap();
    set.source = if flipped { "flipped.csv".into() } else { "trained.csv".into() };
    set
}

fn heldout(
    robot: &RobotDescription,
    train: &MeasurementSet,
    test: &MeasurementSet,
    method: Method,
    effects: &str,
) -> (f64, EvalReport) {
    heldout_with(robot, train, test, method, effects, FitOptions::default())
}

fn heldout_with(
    robot: &RobotDescription,
    train: &MeasurementSet,
    test: &MeasurementSet,
    method: Method,
    effects: &str,
    options: FitOptions,
) -> (f64, EvalReport) {
    let selection: EffectSelection = if effects.is_empty() { EffectSelection::None } else { effects.parse().unwrap() };
    let (model, _) = pipeline::fit(robot, train, method, &options.with_effects(selection)).unwrap();
    let evaluation = pipeline::evaluate(&model, test).unwrap();
    let report = EvalReport::new(&model, test, &evaluation);
    (evaluation.summary.rms_position_error_mm, report)
}

#[test]
fn fitted_on_one_wrist_configuration_every_method_is_within_5_percent_of_the_nominal_on_the_flipped_one() {
    let robot = ur10();
    for seed in [3, 11, 29] {
        let train = wrist(seed, 300, false);
        let test = wrist(seed, 200, true);
        let (nominal, _) = heldout(&robot, &train, &test, Method::BaseTool, "");
        let (_, report) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default()).unwrap();
        eprintln!("seed {seed}: {}", report.nominal_prior.as_ref().unwrap());
        let mut off = FitOptions::default();
        off.nominal_prior.choose = false;
        // Without the prior, for the record: 1.12× and 1.06× the nominal on seeds 3 and 29.
        let (error, _) = heldout_with(&robot, &train, &test, Method::Poe, "", off);
        eprintln!("seed {seed}: poe without the prior {error:.4} mm ({:.3}× the nominal)", error / nominal);
        for (method, effects) in [(Method::Poe, ""), (Method::PoeGp, ""), (Method::Poe, "gear_periodic:2:3")] {
            let (error, eval) = heldout(&robot, &train, &test, method, effects);
            eprintln!(
                "seed {seed}: {method} {effects} {error:.4} mm RMS on the flipped wrist, nominal {nominal:.4} mm"
            );
            assert!(
                error <= 1.05 * nominal,
                "seed {seed}: {method} {effects} {error} mm against the nominal's {nominal} mm"
            );
            assert!(
                eval.out_of_range.iter().any(|w| w.input == "joint 5" && w.rows_outside == test.rows.len()),
                "{:?}",
                eval.out_of_range
            );
        }
    }
}

#[test]
fn above_max_rows_the_strength_is_not_chosen_and_the_report_says_so() {
    let robot = ur10();
    // Both wrists, so that there are clusters to hold out at the default.
    let mut train = wrist(3, 150, false);
    train.rows.extend(wrist(3, 150, true).rows);
    let (_, report) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default()).unwrap();
    assert!(!report.nominal_prior.as_ref().unwrap().reason.contains("max_rows"), "{:?}", report.nominal_prior);
    let mut capped = FitOptions::default();
    capped.nominal_prior.max_rows = 299;
    let (_, report) = pipeline::fit(&robot, &train, Method::Poe, &capped).unwrap();
    let choice = report.nominal_prior.unwrap();
    assert!(
        choice.chosen().is_none() && choice.reason.contains("300 rows, more than nominal_prior.max_rows = 299"),
        "{choice}"
    );
}
