//! The prior toward the nominal geometry: fitted on one wrist configuration and
//! evaluated on the flipped one, a calibrated model is no further off than the nominal geometry
//! (at its fitted base and tool placement), and `eval` says the rows lie outside the fitted range.
//! The prior is never weaker than the nominal's tolerance against the residual a plain fit leaves.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoiseModel, simulate, simulated_cell};
use effects::EffectSelection;
use loadsim::{GearPeriodicModel, Harmonic, JointRange};
use measurements::MeasurementSet;
use model::{EvalReport, Method};
use pipeline::FitOptions;
use robot::RobotDescription;
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
fn gear_error() -> GearPeriodicModel {
    let harmonic = |joint_index: usize, order: f64, amplitude_rad: f64, phase_rad: f64| Harmonic {
        joint_index,
        order,
        amplitude_rad,
        phase_rad,
    };
    GearPeriodicModel {
        harmonics: vec![harmonic(1, 2.0, 1e-3, 0.4), harmonic(2, 3.0, 6e-4, -1.2), harmonic(4, 1.0, 1e-3, 0.0)],
    }
}

/// `count` poses of the same cell with joint 5 on one side of its singular angle (`flipped`:
/// the other side), elbow up and down both, the tracker's noise and the gear error.
fn wrist(seed: u64, count: usize, flipped: bool) -> MeasurementSet {
    let robot = ur10();
    // A well-made arm: 0.1 mm and 0.1 mrad per component, so that the nominal geometry misses
    // by under a millimetre and the non-geometric error is as large as the geometric one (where a
    // fit on one solution space can do worse than the nominal on another).
    let geometry = Perturbation { translation_m: 1e-4, rotation_rad: 1e-4, ..Perturbation::default() };
    let turn = |lower_rad: f64, upper_rad: f64| JointRange { lower_rad, upper_rad };
    let wrist = if flipped { turn(-PI + 0.2, -0.2) } else { turn(0.2, PI - 0.2) };
    let ranges = [turn(-PI, PI), turn(-PI, 0.0), turn(-PI + 0.2, PI - 0.2), turn(-PI, PI), wrist, turn(-PI, PI)];
    let effects = Effects {
        gear_periodic: Some(gear_error()),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
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
    let bound = model.bind(test).unwrap();
    let evaluation = model::evaluate(&model, &bound).unwrap();
    let report = EvalReport::new(&model, &bound, &evaluation);
    (evaluation.summary.rms_position_error_mm, report)
}

#[test]
fn fitted_on_one_wrist_configuration_every_method_is_at_most_the_nominals_error_on_the_flipped_one() {
    let robot = ur10();
    for seed in [3, 11, 29] {
        let train = wrist(seed, 300, false);
        let test = wrist(seed, 200, true);
        let (nominal, _) = heldout(&robot, &train, &test, Method::BaseTool, "");
        let (_, report) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default()).unwrap();
        eprintln!("seed {seed}: {}", report.nominal_prior.as_ref().unwrap());
        let mut off = FitOptions::default();
        off.nominal_prior.choose = false;
        // Without the prior, for the record: 1.12× and 1.06× the nominal on seeds 3 and 29: this
        // test fails with `choose: false`.
        let (error, _) = heldout_with(&robot, &train, &test, Method::Poe, "", off);
        eprintln!("seed {seed}: poe without the prior {error:.4} mm ({:.3}× the nominal)", error / nominal);
        for (method, effects) in [(Method::Poe, ""), (Method::PoeGp, ""), (Method::Poe, "gear_periodic:2:3")] {
            let (error, eval) = heldout(&robot, &train, &test, method, effects);
            eprintln!(
                "seed {seed}: {method} {effects} {error:.4} mm RMS on the flipped wrist, nominal {nominal:.4} mm"
            );
            assert!(error <= nominal, "seed {seed}: {method} {effects} {error} mm against the nominal's {nominal} mm");
            // Beside the warning, the error the geometry's own uncertainty predicts there: its
            // posterior under the nominal's tolerance, whatever the held-out choice was (0.2 mm
            // on seed 3 against 0.11 mm on the training rows). The gear error, not the geometry,
            // makes most of the 0.7 mm there: no geometric σ can say that.
            let predicted = eval.geometry_sigma.as_ref().expect("the geometry's predicted error");
            eprintln!("seed {seed}: {method} {effects} {predicted}");
            assert!(
                predicted.rms_mm > 1.5 * predicted.training_rms_mm && predicted.rows == test.rows.len(),
                "{predicted}: {error} mm"
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
fn the_prior_is_never_weaker_than_the_tolerance_and_above_max_rows_there_is_none() {
    let robot = ur10();
    // Both wrists: two configuration clusters.
    let mut train = wrist(3, 150, false);
    train.rows.extend(wrist(3, 150, true).rows);
    let (_, report) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default()).unwrap();
    let choice = report.nominal_prior.as_ref().unwrap();
    assert!(!choice.reason.contains("max_rows"), "{choice:?}");
    // Never weaker than the tolerance over the residual's scale (noise and the gear error).
    let (scale, (t, r)) = (choice.residual_scale.unwrap(), choice.tolerance);
    assert!(scale >= 1.0, "{choice}");
    let (chosen_t, chosen_r) = choice.chosen().expect("a prior");
    assert!(chosen_t <= t / scale && chosen_r <= r / scale, "{choice}");
    let mut capped = FitOptions::default();
    capped.nominal_prior.max_rows = 299;
    let (_, report) = pipeline::fit(&robot, &train, Method::Poe, &capped).unwrap();
    let choice = report.nominal_prior.unwrap();
    assert!(
        choice.chosen().is_none() && choice.reason.contains("300 rows, more than nominal_prior.max_rows = 299"),
        "{choice}"
    );
}

/// `eval` gives the error inside and outside the fitted range apart for a plain geometric model,
/// and names a row far beyond the others among those inside, not the rows outside it, whose
/// large errors are the model's.
#[test]
fn eval_splits_the_error_at_the_fitted_range_and_names_a_glitch_inside_it() {
    let robot = ur10();
    let mut train = wrist(5, 260, false);
    let mut test = train.clone();
    test.rows = train.rows.split_off(200);
    let (model, _) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default()).unwrap();
    // The later rows are later and warmer than every training row: not what this test is about.
    for row in &mut test.rows {
        (row.t_s, row.temp_c) = (None, None);
    }
    let range = model.training_range.clone().unwrap();
    test.rows.retain(|row| range.contains(row));
    let inside = test.rows.len();
    assert!(inside >= 40, "{inside} of 60 rows inside the fitted range");
    // One row measured 10 mm off (a tracker glitch), then the flipped wrist.
    let glitch = test.rows[10].line;
    test.rows[10].position.x += 1e-2;
    let flipped = wrist(5, 20, true);
    test.rows.extend(flipped.rows.iter().map(|r| measurements::Measurement { line: r.line + 1000, ..r.clone() }));
    let bound = model.bind(&test).unwrap();
    let evaluation = model::evaluate(&model, &bound).unwrap();
    let report = EvalReport::new(&model, &bound, &evaluation);
    let split = report.range_split.expect("rows outside the fitted range: a split");
    assert_eq!((split.inside.n, split.outside.n), (inside, 20));
    let suspects = report.suspect_rows.expect("the glitch is named");
    assert_eq!(suspects.rows.iter().map(|r| r.line).collect::<Vec<_>>(), vec![glitch], "{suspects:?}");
    assert_eq!(suspects.without.n, inside + 20 - 1);
    assert!(suspects.without.max_position_error_mm < 3.0, "{suspects:?}");
    assert!(evaluation.summary.max_position_error_mm > 9.0);
}

/// An arm on a lifting column (seven joints: the column, folded from its URDF mimic stages, and
/// six revolute ones) has configuration clusters too: the arm's branches from its six revolute
/// joints, and the column's lower and upper half, and a prior.
#[test]
fn a_column_arms_clusters_are_its_branches_and_the_halves_of_its_column() {
    let robot = testkit::robot("column_arm.urdf");
    let geometry = Perturbation { translation_m: 1e-4, rotation_rad: 1e-4, ..Perturbation::default() };
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..Effects::default() };
    let ranges = campaign::joint_ranges(&robot);
    let config = GeneratorConfig { sample_count: 300, seed: 4, ..Default::default() };
    let data = simulate(&simulated_cell(&robot, &geometry, 4).unwrap(), &effects, &ranges, &config, false).unwrap();
    let (_, report) = pipeline::fit(&robot, &data, Method::Poe, &FitOptions::default()).unwrap();
    let choice = report.nominal_prior.expect("a prior choice is reported");
    eprintln!("{choice}\n{:?}", choice.clusters.iter().map(|c| (&c.label, c.n)).collect::<Vec<_>>());
    assert_eq!(choice.height_splits.iter().map(|h| h.joint).collect::<Vec<_>>(), vec![1], "{choice:?}");
    assert!(!choice.branch_joints.is_empty(), "{choice:?}");
    assert!(choice.clusters.iter().any(|c| c.label.contains("joint 1 below")), "{:?}", choice.clusters);
    assert!(choice.clusters.iter().any(|c| c.label.contains("joint 1 at or above")), "{:?}", choice.clusters);
    assert!(choice.held_out.len() >= 2 && choice.chosen().is_some(), "{choice}");
    // A column that hardly moves (a few centimetres) is no cluster of its own.
    let mut held = ranges.clone();
    held[0] = JointRange { lower_rad: 0.3, upper_rad: 0.5 };
    let fixed = simulate(&simulated_cell(&robot, &geometry, 4).unwrap(), &effects, &held, &config, false).unwrap();
    let (_, report) = pipeline::fit(&robot, &fixed, Method::Poe, &FitOptions::default()).unwrap();
    assert!(report.nominal_prior.unwrap().height_splits.is_empty());
}

/// The posterior keeps what the training poses cannot determine at about the nominal's
/// tolerance, and says so where it matters: a 7-axis arm fitted with only joints 1 and
/// 2 moving (the others within 2 mrad of zero) cannot know its outer links' errors, and on poses
/// that move every joint `eval` gives, beside the warning, the error the geometry's own
/// uncertainty predicts there: of the size of the error it makes (a σ of the tolerance against an
/// arm off by up to that much), far above its training rows'. Without a prior, the directions no
/// training pose sees have no variance, and the model keeps no geometry uncertainty at all.
#[test]
fn outside_the_fitted_joints_eval_gives_the_error_the_geometrys_uncertainty_predicts() {
    let robot = testkit::robot("iiwa7.ron");
    let cell = simulated_cell(&robot, &Perturbation::default(), 7).unwrap();
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..Effects::default() };
    let turn = |lower_rad: f64, upper_rad: f64| JointRange { lower_rad, upper_rad };
    let outer = turn(-1.0, 1.0);
    let ranges = [turn(-2.0, 2.0), turn(-1.5, 1.5), outer, outer, outer, outer, outer];
    // Trained as a real 7-axis campaign: joints 1 and 2 moving, the others at 0 within 2 mrad.
    let config = GeneratorConfig {
        sample_count: 200,
        seed: 7,
        moving_joints: vec![0, 1],
        fixed_jitter_rad: 2e-3,
        ..Default::default()
    };
    let train = simulate(&cell, &effects, &ranges, &config, true).unwrap();
    let config = GeneratorConfig { sample_count: 60, seed: 8, ..Default::default() };
    let test = simulate(&cell, &effects, &ranges, &config, true).unwrap();
    let (model, report) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default()).unwrap();
    eprintln!("{}", report.nominal_prior.as_ref().unwrap());
    let bound = model.bind(&test).unwrap();
    let evaluation = model::evaluate(&model, &bound).unwrap();
    let eval = EvalReport::new(&model, &bound, &evaluation);
    let outside = eval.range_split.expect("rows outside the fitted range").outside;
    let predicted = eval.geometry_sigma.clone().expect("the geometry's predicted error beside the warning");
    eprintln!("{predicted}; the error there: {:.4} mm RMS", outside.rms_position_error_mm);
    assert_eq!((predicted.rows, predicted.of_rows), (outside.n, test.rows.len()));
    let ratio = predicted.rms_mm / outside.rms_position_error_mm;
    assert!((0.5..=4.0).contains(&ratio), "{predicted}: {ratio} times the error {outside:?}");
    assert!(predicted.rms_mm > 10.0 * predicted.training_rms_mm, "{predicted}");
    let json = serde_json::to_string(&eval).unwrap();
    assert!(json.contains("\"geometry_sigma\":{\"rows\":"), "{json}");
    let mut off = FitOptions::default();
    off.nominal_prior.choose = false;
    let (plain, _) = pipeline::fit(&robot, &train, Method::Poe, &off).unwrap();
    assert!(plain.geometry_uncertainty.is_none());
}
