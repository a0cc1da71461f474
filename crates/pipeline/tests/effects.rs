//! Effects identified with the geometry (`calib fit --effects`): each one, on simulated data with
//! that effect hidden, takes the held-out error down to the tracker noise; the model file keeps
//! them and an older file (schema 1) still reads.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoiseModel, joint_ranges, simulate, simulated_cell};
use effects::{EffectSelection, IdentifiedEffect};
use loadsim::{GearPeriodicModel, Harmonic, JointBacklash, ThermalModel, TimeDriftModel};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use robot::RobotDescription;

/// 400 poses with `effects` and the tracker's noise: 250 to train on (the even rows... the first
/// 250) and 150 held out.
fn split(robot: &RobotDescription, effects: &Effects, seed: u64) -> (MeasurementSet, MeasurementSet) {
    let cell = simulated_cell(robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: 400, seed, ..GeneratorConfig::default() };
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..effects.clone() };
    let all = simulate(&cell, &effects, &joint_ranges(robot), &config, false).unwrap();
    (all.subset(&(0..250).collect::<Vec<_>>()), all.subset(&(250..400).collect::<Vec<_>>()))
}

fn heldout(robot: &RobotDescription, train: &MeasurementSet, test: &MeasurementSet, effects: &str) -> f64 {
    let selection: EffectSelection = if effects.is_empty() { EffectSelection::None } else { effects.parse().unwrap() };
    let (model, report) =
        pipeline::fit(robot, train, Method::Poe, &FitOptions::default().with_effects(selection)).unwrap();
    assert!(report.identification.converged, "{effects}: {}", report.identification.termination);
    model::evaluate(&model, &model.bind(test).unwrap()).unwrap().summary.mean_position_error_mm
}

/// The held-out error the tracker noise alone leaves on the same poses.
fn noise_floor(robot: &RobotDescription, seed: u64) -> f64 {
    let (train, test) = split(robot, &Effects::default(), seed);
    heldout(robot, &train, &test, "")
}

/// A gear error of orders 1, 7 and 12 on joint 2, 0.1–0.2 mrad each.
fn joint_2_gear_error() -> GearPeriodicModel {
    let harmonic =
        |order: f64, amplitude_rad: f64, phase_rad: f64| Harmonic { joint_index: 1, order, amplitude_rad, phase_rad };
    GearPeriodicModel {
        harmonics: vec![harmonic(1.0, 1e-4, 0.3), harmonic(7.0, 2e-4, -1.0), harmonic(12.0, 1e-4, 2.0)],
    }
}

#[test]
fn a_gear_error_of_high_order_is_identified_down_to_the_noise() {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects { gear_periodic: Some(joint_2_gear_error()), ..Effects::default() };
    let (train, test) = split(&robot, &effects, 31);
    let poe = heldout(&robot, &train, &test, "");
    let gear = heldout(&robot, &train, &test, "gear_periodic:2:12");
    let floor = noise_floor(&robot, 31);
    eprintln!("poe {poe:.4} mm, gear_periodic:2:12 {gear:.4} mm, noise alone {floor:.4} mm");
    assert!(gear < 1.3 * floor, "gear {gear} mm against the noise's {floor} mm");
    assert!(gear < 0.5 * poe, "gear {gear} mm against poe {poe} mm");
}

#[test]
fn backlash_thermal_growth_and_drift_are_each_identified_down_to_the_noise() {
    let robot = testkit::robot("irb4400.ron");
    let floor = noise_floor(&robot, 32);
    let cases = [
        (
            "backlash:3",
            Effects {
                backlash: Some(loadsim::BacklashModel {
                    joints: vec![JointBacklash { joint_index: 2, half_band_rad: 3e-4 }],
                }),
                ..Effects::default()
            },
        ),
        (
            "thermal",
            Effects {
                thermal: Some(ThermalModel { expansion_per_k: 1e-4, ..ThermalModel::default() }),
                ..Effects::default()
            },
        ),
        (
            "time_drift",
            Effects {
                time_drift: Some(TimeDriftModel { twist_per_s: [4e-8, -3e-8, 2e-8, 0.0, 1e-8, 0.0] }),
                ..Effects::default()
            },
        ),
    ];
    for (list, effects) in cases {
        let (train, test) = split(&robot, &effects, 32);
        let poe = heldout(&robot, &train, &test, "");
        let with = heldout(&robot, &train, &test, list);
        eprintln!("{list}: poe {poe:.4} mm, with the effect {with:.4} mm, noise alone {floor:.4} mm");
        assert!(with < 1.3 * floor, "{list}: {with} mm against the noise's {floor} mm");
        assert!(with < 0.7 * poe, "{list}: {with} mm against poe's {poe} mm");
    }
}

#[test]
fn an_effect_the_data_cannot_feed_is_refused_with_the_column_it_needs() {
    let robot = testkit::robot("irb4400.ron");
    let (mut train, _) = split(&robot, &Effects::default(), 33);
    for row in &mut train.rows {
        row.temp_c = None;
    }
    let options = FitOptions::default().with_effects("thermal".parse().unwrap());
    let message = pipeline::fit(&robot, &train, Method::Poe, &options).unwrap_err().to_string();
    assert!(message.contains("thermal needs the column 'temp_c'"), "{message}");
    let options = FitOptions::default().with_effects("backlash:7".parse().unwrap());
    let message = pipeline::fit(&robot, &train, Method::Poe, &options).unwrap_err().to_string();
    assert_eq!(message, "effect on joint 7: the robot has joints 1 to 6");
}

#[test]
fn a_model_with_every_effect_reads_back_and_predicts_the_same() {
    let robot = testkit::robot("irb4400.ron");
    let (train, test) = split(&robot, &Effects::default(), 34);
    let selection = "joint_compliance,gear_periodic:1:3,backlash:2,thermal,time_drift".parse().unwrap();
    let (model, _) =
        pipeline::fit(&robot, &train, Method::PoeGp, &FitOptions::default().with_effects(selection)).unwrap();
    let kinds: Vec<&str> = model.effects.iter().map(IdentifiedEffect::kind).collect();
    assert_eq!(kinds, ["joint_compliance", "gear_periodic", "backlash", "thermal", "time_drift"]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.ron");
    model::write_model(&path, &model).unwrap();
    let again = model::read_model(&path).unwrap();
    for (a, b) in again.effects.iter().zip(&model.effects) {
        assert_eq!(a.theta(), b.theta());
    }
    let before = model::evaluate(&model, &model.bind(&test).unwrap()).unwrap().errors;
    let after = model::evaluate(&again, &again.bind(&test).unwrap()).unwrap().errors;
    for (a, b) in before.iter().zip(&after) {
        assert!((a.position_mm - b.position_mm).abs() < 1e-9, "{a:?} {b:?}");
    }
}

/// A real 7-axis campaign's shape (joints 1 and 2 moving, the others at 0 within 2 mrad, four
/// payload runs with a tool each, measured torques), full pose, split even / odd rows.
fn campaign(effects: &Effects, seed: u64) -> (MeasurementSet, MeasurementSet) {
    let robot = testkit::robot("iiwa7.ron");
    let config = campaign::payload_run_campaign(400, seed);
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..effects.clone() };
    let remount = campaign::Remount::default();
    let (_, all) =
        campaign::simulate_campaign(&robot, &effects, &Perturbation::default(), &remount, &config, true).unwrap();
    let even: Vec<usize> = (0..all.rows.len()).step_by(2).collect();
    let odd: Vec<usize> = (1..all.rows.len()).step_by(2).collect();
    (all.subset(&even), all.subset(&odd))
}

#[test]
fn a_seven_axis_campaign_with_two_moving_joints_reaches_the_noise_with_joint_compliance() {
    let robot = testkit::robot("iiwa7.ron");
    let seed = 35;
    let (train, test) = campaign(&campaign::paper_effects(), seed);
    let (noise_train, noise_test) = campaign(&Effects::default(), seed);
    let floor = heldout(&robot, &noise_train, &noise_test, "");
    let poe = heldout(&robot, &train, &test, "");
    // With the measured torques (modelled on the gravity regressors), then without them.
    let measured = heldout(&robot, &train, &test, "joint_compliance");
    let strip = |set: &MeasurementSet| {
        let mut set = set.clone();
        set.rows.iter_mut().for_each(|r| r.torques_nm = None);
        set
    };
    let gravity = heldout(&robot, &strip(&train), &strip(&test), "joint_compliance");
    eprintln!("noise {floor:.4} mm, poe {poe:.4} mm, compliance: torques {measured:.4} mm, gravity {gravity:.4} mm");
    for (name, error) in [("measured torques", measured), ("gravity regressors", gravity)] {
        assert!(error < 1.5 * floor, "{name}: {error} mm against the noise's {floor} mm");
        assert!(error < poe, "{name}: {error} mm against poe's {poe} mm");
    }
}

/// The training costs a fit with the effects `mask` and one with `mask | extra` end at, and the
/// geometry's alone, on 80 simulated poses of the IRB 4400 (a gear error of joint 2 and the
/// tracker's noise) drawn with `seed`; with the convergence of the two effect fits.
fn training_costs(seed: u64, mask: u32, extra: u32, options: &FitOptions) -> TrainingCosts {
    const ITEMS: [&str; 5] = ["gear_periodic:2:2", "gear_periodic:3:1", "backlash:3", "thermal", "time_drift"];
    let pick = |bits: u32| -> String {
        ITEMS.iter().enumerate().filter(|(k, _)| bits & (1 << k) != 0).map(|(_, s)| *s).collect::<Vec<_>>().join(",")
    };
    let (subset, superset) = (pick(mask), pick(mask | extra));
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects {
        gear_periodic: Some(GearPeriodicModel {
            harmonics: vec![Harmonic { joint_index: 1, order: 3.0, amplitude_rad: 2e-4, phase_rad: 0.5 }],
        }),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    let cell = simulated_cell(&robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: 80, seed, ..GeneratorConfig::default() };
    let data = simulate(&cell, &effects, &joint_ranges(&robot), &config, seed.is_multiple_of(2)).unwrap();
    let cost = |list: &str| {
        let options =
            options.clone().with_effects(if list.is_empty() { EffectSelection::None } else { list.parse().unwrap() });
        let (_, report) = pipeline::fit(&robot, &data, Method::Poe, &options).unwrap();
        let id = &report.identification;
        (id.final_cost, (!id.converged).then(|| format!("{list}: {} after {}", id.termination, id.iteration_count())))
    };
    let (geometry, _) = cost("");
    let ((small, small_stop), (large, large_stop)) = (cost(&subset), cost(&superset));
    TrainingCosts { subset, superset, geometry, small, large, not_converged: small_stop.or(large_stop) }
}

struct TrainingCosts {
    subset: String,
    superset: String,
    geometry: f64,
    small: f64,
    large: f64,
    not_converged: Option<String>,
}

impl TrainingCosts {
    /// What the fit promises: each effect fit ends at or below the geometry's cost, where it
    /// starts, and converged; the superset at or below the subset.
    fn check(&self) -> Result<(), String> {
        let TrainingCosts { subset, superset, geometry, small, large, .. } = self;
        if let Some(stop) = &self.not_converged {
            return Err(format!("not converged: {stop}"));
        }
        if *small > geometry * (1.0 + 1e-12) {
            return Err(format!("{subset}: {small} above the geometry's {geometry}"));
        }
        if *large > geometry * (1.0 + 1e-12) {
            return Err(format!("{superset}: {large} above the geometry's {geometry}"));
        }
        if *large > small * (1.0 + 1e-6) {
            return Err(format!("{superset}: {large} above {subset}: {small} ({:.2e} relative)", large / small - 1.0));
        }
        Ok(())
    }
}

/// One objective for every selection: plain least squares and no prior toward the nominal, the
/// claim below being of one cost minimised with more freedom. The defaults make the objective
/// depend on the fit: the Huber loss reweights each fit's rows by its own residuals, and the
/// prior toward the nominal in a fit with effects is scaled by that fit's own residual
/// (`EffectsPrior::residual_scale` in pipeline's `fit_prior.rs`), so the subset's solution is no point of the
/// superset's problem and a superset can end above its subset without any solver fault.
fn one_objective() -> FitOptions {
    let mut options = FitOptions::default();
    options.identification.robust.loss = poe::identify::Loss::Squared;
    options.nominal_prior.choose = false;
    options
}

/// The counterexample an unseeded run of the property below drew under the default options
/// (seed 8, mask 23, extra 8: gear_periodic:2:2, gear_periodic:3:1, backlash:3 and time_drift,
/// then thermal too; 4.5e-6 above under the Huber loss, the same with every tolerance a
/// thousand times tighter), kept as a case of its own: it was found before the regressions file
/// recorded it. The other, seed 155, mask 4, extra 8 (backlash:3, then thermal: 4.6e-4 above
/// under the squared loss with the prior, the same with tighter tolerances, rcond 1e-14 or
/// Levenberg-Marquardt), is in effects.proptest-regressions.
#[test]
fn more_effects_never_end_at_a_higher_training_cost_seed_8_mask_23_extra_8() {
    let costs = training_costs(8, 23, 8, &one_objective());
    if let Err(failure) = costs.check() {
        panic!("{failure}");
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 8,
        ..proptest::prelude::ProptestConfig::default()
    })]

    /// The training cost a fit minimises (plain least squares, no prior: [`one_objective`])
    /// with a superset of effects ends at or below the cost with a subset: the subset's solution
    /// is a point of the superset's problem (its extra parameters at zero), and every effect fit
    /// starts from the geometry's solution.
    #[test]
    fn more_effects_never_end_at_a_higher_training_cost(seed in 0_u64..500, mask in 1_u32..32, extra in 1_u32..32) {
        let costs = training_costs(seed, mask, extra, &one_objective());
        proptest::prop_assert!(costs.check().is_ok(), "{}", costs.check().unwrap_err());
    }
}

#[test]
fn a_model_is_its_parts_applied_in_order_and_export_reports_each_one() {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects {
        gear_periodic: Some(GearPeriodicModel {
            harmonics: vec![Harmonic { joint_index: 2, order: 2.0, amplitude_rad: 3e-4, phase_rad: 0.1 }],
        }),
        backlash: Some(loadsim::BacklashModel { joints: vec![JointBacklash { joint_index: 1, half_band_rad: 3e-4 }] }),
        ..Effects::default()
    };
    let (train, test) = split(&robot, &effects, 36);
    let selection = "gear_periodic:3:2,backlash:2".parse().unwrap();
    let (model, _) =
        pipeline::fit(&robot, &train, Method::PoeGp, &FitOptions::default().with_effects(selection)).unwrap();
    let names: Vec<String> = model.parts().iter().map(model::Part::name).collect();
    assert_eq!(
        names,
        [
            "geometry",
            "gear_periodic:3:2",
            "backlash:2 (sign of the static torque of the mass model)",
            "geometry_fallback",
            "gaussian_process"
        ]
    );
    // The fallback geometry is a geometry: what a URDF cannot hold is the effects and the GP.
    let not_in_urdf: Vec<String> = names.iter().filter(|n| !n.starts_with("geometry")).cloned().collect();
    assert_eq!(model.non_geometric_parts(), not_in_urdf);
    // Every part matters on held-out rows, and leaving one out costs what it explained.
    let error = |m: &model::CalibratedModel| {
        model::evaluate(m, &m.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm
    };
    let whole = error(&model);
    for (k, name) in names.iter().enumerate().take(3).skip(1) {
        let without = error(&model.without_part(k));
        assert!(without > 1.5 * whole, "without {name}: {without} mm against {whole} mm");
    }
    let export = cell::export_urdf(
        &model,
        cell::UrdfTemplate::Plain { nominal: Some((&robot, "irb4400.ron")) },
        Some(&train),
        &robot::NominalTolerance::default(),
    )
    .unwrap();
    let training = export.report.training_error.unwrap();
    let left_out: Vec<&str> = training.without_each.iter().map(|p| p.part.as_str()).collect();
    assert_eq!(left_out, not_in_urdf.iter().map(String::as_str).collect::<Vec<_>>());
    for part in &training.without_each {
        assert!(part.error.mean_position_error_mm > training.model.mean_position_error_mm, "{part:?}");
    }
}

/// Rows of `all` whose joint 2 satisfies `keep`.
fn rows_where(all: &MeasurementSet, keep: impl Fn(f64) -> bool) -> MeasurementSet {
    let rows: Vec<usize> = (0..all.rows.len()).filter(|&i| keep(all.rows[i].q[1])).collect();
    all.subset(&rows)
}

#[test]
fn a_gear_series_warns_where_it_is_used_outside_the_angles_it_was_fitted_on() {
    let robot = testkit::robot("irb4400.ron");
    let cell = simulated_cell(&robot, &Perturbation::default(), 47).unwrap();
    let config = GeneratorConfig { sample_count: 900, seed: 47, ..GeneratorConfig::default() };
    let all = simulate(&cell, &Effects::default(), &joint_ranges(&robot), &config, false).unwrap();
    // Trained on joint 2 in -0.6 … -0.15 and 0.15 … 0.6 rad: a 0.3 rad gap, wider than half the
    // shortest period of order 24 (π/24 = 0.13 rad).
    let trained = |q: f64| (0.15..=0.6).contains(&q.abs());
    let train = rows_where(&all, trained);
    let options = FitOptions::default().with_effects("gear_periodic:2:24".parse().unwrap());
    let (model, _) = pipeline::fit(&robot, &train, Method::Poe, &options).unwrap();
    assert!(model.extrapolation(&train.rows).is_empty());
    let beyond = rows_where(&all, |q| q.abs() > 0.65);
    let gap = rows_where(&all, |q| q.abs() < 0.1);
    for (set, what) in [(&beyond, "beyond the range"), (&gap, "in the gap")] {
        assert!(!set.rows.is_empty(), "{what}: no rows");
        let warnings = model.extrapolation(&set.rows);
        assert_eq!(warnings.len(), 1, "{what}: {warnings:?}");
        assert_eq!((warnings[0].joint, warnings[0].rows_outside), (2, set.rows.len()), "{what}");
        // The gaps of the joint's turn (angles modulo 2π): around 0 and the rest of the circle
        // beyond ±0.6 rad.
        assert_eq!(warnings[0].gaps_rad.len(), 2, "{what}: {:?}", warnings[0].gaps_rad);
        let report = {
            let bound = model.bind(set).unwrap();
            model::EvalReport::new(&model, &bound, &model::evaluate(&model, &bound).unwrap())
        };
        assert_eq!(report.warnings, warnings, "{what}: eval --json carries them");
    }
}

/// 1,500 poses of the IRB 4400 with the gear error of joint 2 and the tracker's noise (seed 53),
/// over the whole range of every joint: the gap tests below cut gaps into it.
fn joint_2_gear_campaign(seed: u64) -> (RobotDescription, MeasurementSet) {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects {
        gear_periodic: Some(joint_2_gear_error()),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    let cell = simulated_cell(&robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: 1500, seed, ..GeneratorConfig::default() };
    let all = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();
    (robot, all)
}

/// A gear series fitted on poses that leave a 40° gap in joint 2 and stop short of its
/// range is held and faded there, so the corrected model is no worse than the geometry alone in
/// the gap and past the end (it was 4–5× worse on the real UR10 before), and better where it was
/// fitted.
#[test]
fn a_gear_series_falls_back_to_the_geometry_in_a_gap_and_past_the_end_of_its_angles() {
    let (robot, all) = joint_2_gear_campaign(53);
    // Trained on joint 2 in -0.9 … -0.35 and 0.35 … 0.9 rad: a 0.7 rad (40°) gap, and nothing
    // beyond ±0.9 rad.
    let train = rows_where(&all, |q| (0.35..=0.9).contains(&q.abs()));
    let inside = rows_where(&all, |q| (0.4..=0.85).contains(&q.abs()));
    let gap = rows_where(&all, |q| q.abs() < 0.3);
    let beyond = rows_where(&all, |q| q.abs() > 0.95);
    let fit = |effects: &str| {
        let selection: EffectSelection =
            if effects.is_empty() { EffectSelection::None } else { effects.parse().unwrap() };
        pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default().with_effects(selection)).unwrap().0
    };
    let (poe, gear) = (fit(""), fit("gear_periodic:2:24"));
    let error = |model: &model::CalibratedModel, set: &MeasurementSet| {
        model::evaluate(model, &model.bind(set).unwrap()).unwrap().summary.mean_position_error_mm
    };
    for (set, what) in [(&gap, "in the gap"), (&beyond, "past the end")] {
        assert!(set.rows.len() >= 20, "{what}: {} rows", set.rows.len());
        let (alone, corrected) = (error(&poe, set), error(&gear, set));
        eprintln!("{what}: {} rows, poe {alone:.4} mm, poe + gear {corrected:.4} mm", set.rows.len());
        assert!(corrected <= 1.1 * alone, "{what}: {corrected} mm against the geometry's {alone} mm");
    }
    let (alone, corrected) = (error(&poe, &inside), error(&gear, &inside));
    eprintln!("inside: poe {alone:.4} mm, poe + gear {corrected:.4} mm");
    assert!(corrected < 0.7 * alone, "inside: {corrected} mm against the geometry's {alone} mm");
    // Where the series is faded out, the prediction says how much of the error it leaves: a
    // standard deviation of the size of the fitted error's RMS times the joint's lever; where it
    // was fitted, none.
    let position_sigma = |set: &MeasurementSet| -> Vec<f64> {
        gear.predict(&gear.bind(set).unwrap())
            .unwrap()
            .iter()
            .map(|p| p.std.map_or(f64::NAN, |s| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()))
            .collect()
    };
    // Inside, the posterior σ of the geometry and the series alone, below the fallback limit.
    let limit = gear.effect_uncertainty.as_ref().unwrap().fallback_sigma_m;
    let inside_sigma = position_sigma(&inside);
    assert!(inside_sigma.iter().all(|&s| s > 0.0 && s <= limit), "{inside_sigma:?} against {limit}");
    let largest_inside = inside_sigma.iter().copied().fold(0.0, f64::max);
    let beyond_sigma = position_sigma(&beyond);
    let far: Vec<f64> = beyond_sigma.iter().copied().filter(|&s| s > largest_inside).collect();
    assert!(far.len() > beyond.rows.len() / 2, "{} of {} rows with a deviation", far.len(), beyond.rows.len());
    // Every model, with effects or not, says which rows lie outside the joint ranges it was fitted
    // on: here joint 2 past ±0.9 rad, on every such row, and nothing on rows it was fitted on.
    for model in [&poe, &gear] {
        let warnings = model.outside_training_range(&beyond.rows);
        let joint_2: Vec<_> = warnings.iter().filter(|w| w.input == "joint 2").collect();
        assert_eq!(joint_2.len(), 1, "{warnings:?}");
        assert_eq!((joint_2[0].rows_outside, joint_2[0].unit), (beyond.rows.len(), "rad"));
        assert!(joint_2[0].to_string().contains("outside the range the model was fitted on"));
        assert!(model.outside_training_range(&inside.rows).is_empty());
        let report = {
            let bound = model.bind(&beyond).unwrap();
            model::EvalReport::new(model, &bound, &model::evaluate(model, &bound).unwrap())
        };
        assert_eq!(report.out_of_range, warnings, "eval --json carries them");
    }
    let IdentifiedEffect::GearPeriodic(series) = &gear.effects[0] else { panic!("{:?}", gear.effects) };
    let rms = series.fitted_rms_rad.unwrap();
    // Joint 2's lever to the tool is under 3 m on this arm (reach 2 m, plus the tool).
    for s in far {
        assert!(s <= 3.0 * rms && s >= 1e-3 * rms, "{s} m against an RMS of {rms} rad");
    }
}

/// Where the effects fade and the pose falls back to the geometry fitted alone, the GP
/// falls back with it to one conditioned on what the geometry alone leaves (the same
/// hyperparameters), so that off the effects' angles `poe-gp` with effects is no worse than
/// `poe-gp` without. A smooth error in joint 3 (covered everywhere) beside joint 2's gear error:
/// before, the GP learnt only what the effects left, and in joint 2's gap and past its end joint
/// 3's error was lost with the faded effects (the UR10 B splits, `xtask/scripts/ur10_splits.py`,
/// lost 25–50 % against `poe-gp` that way).
#[test]
fn where_the_effects_fade_the_gp_falls_back_with_the_geometry() {
    let robot = testkit::robot("irb4400.ron");
    let mut periodic = joint_2_gear_error();
    periodic.harmonics.push(Harmonic { joint_index: 2, order: 1.0, amplitude_rad: 4e-4, phase_rad: 0.7 });
    periodic.harmonics.push(Harmonic { joint_index: 2, order: 2.0, amplitude_rad: 2e-4, phase_rad: -0.4 });
    let effects = Effects {
        gear_periodic: Some(periodic),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    let cell = simulated_cell(&robot, &Perturbation::default(), 59).unwrap();
    let config = GeneratorConfig { sample_count: 1000, seed: 59, ..GeneratorConfig::default() };
    let all = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();
    // Even rows train; the odd rows inside the trained angles are held out there.
    let (even, odd) = (
        all.subset(&(0..all.rows.len()).step_by(2).collect::<Vec<_>>()),
        all.subset(&(1..all.rows.len()).step_by(2).collect::<Vec<_>>()),
    );
    let train = rows_where(&even, |q| (0.35..=0.9).contains(&q.abs()));
    let off = rows_where(&all, |q| q.abs() < 0.3 || q.abs() > 0.95);
    let inside = rows_where(&odd, |q| (0.4..=0.85).contains(&q.abs()));
    assert!(off.rows.len() >= 50 && inside.rows.len() >= 50, "{} / {}", off.rows.len(), inside.rows.len());
    let fit = |effects: &str| {
        let selection: EffectSelection =
            if effects.is_empty() { EffectSelection::None } else { effects.parse().unwrap() };
        pipeline::fit(&robot, &train, Method::PoeGp, &FitOptions::default().with_effects(selection)).unwrap().0
    };
    let (gp, gp_effects) = (fit(""), fit("gear_periodic:2:12,gear_periodic:3:2"));
    assert!(gp_effects.residual_gp.as_ref().unwrap().fallback.is_some());
    let error = |model: &model::CalibratedModel, set: &MeasurementSet| {
        model::evaluate(model, &model.bind(set).unwrap()).unwrap().summary.mean_position_error_mm
    };
    let mut without_fallback = gp_effects.clone();
    without_fallback.residual_gp.as_mut().unwrap().fallback = None;
    let (alone, corrected, before) = (error(&gp, &off), error(&gp_effects, &off), error(&without_fallback, &off));
    eprintln!("off: poe-gp {alone:.4} mm, with effects {corrected:.4} mm (with the GP not falling back: {before:.4})");
    assert!(corrected <= 1.1 * alone, "off: {corrected} mm against poe-gp's {alone} mm");
    let (alone, corrected) = (error(&gp, &inside), error(&gp_effects, &inside));
    eprintln!("inside: poe-gp {alone:.4} mm, with effects {corrected:.4} mm");
    assert!(corrected < alone, "inside: {corrected} mm against poe-gp's {alone} mm");
    // The model file keeps the fallback GP and reads it back to the same poses.
    let text = model::model_text(&gp_effects, "m.ron").unwrap();
    let back = model::parse_model(&text, "m.ron").unwrap();
    let (read, fitted) = (error(&back, &off), error(&gp_effects, &off));
    assert!((read - fitted).abs() <= 1e-9 * fitted, "{read} mm read back against {fitted} mm");
}

/// The diagnosis's folds see gaps. On poses that leave a 40° gap in joint 2 and stop
/// short of its range, random folds predict the error of poses like the training ones; the arcs of
/// joint 2 held out predict what the corrected model does in the gap and past the end: never less
/// than it, and within 30 % (the aim is 25 %; seed 53 is 26 % pessimistic).
#[test]
fn the_diagnosis_predicts_the_error_in_a_gap_and_past_the_end_from_arcs_of_the_joint_held_out() {
    // Three campaigns (seeds 53, 7, 91; the diagnosis picks order 12 on each, the simulated
    // series' highest harmonic). With 10 arcs: predicted 0.2645, 0.2698, 0.2528 mm; fitted
    // 0.2243, 0.2394, 0.2441 mm (5 arcs, and order 32 on seed 53 from the random folds alone:
    // predicted 0.316, 0.305, 0.271 mm, fitted 0.2342 on seed 53: 35 % too high).
    for seed in [53, 7, 91] {
        let (robot, all) = joint_2_gear_campaign(seed);
        let train = rows_where(&all, |q| (0.35..=0.9).contains(&q.abs()));
        let off = rows_where(&all, |q| q.abs() < 0.3 || q.abs() > 0.95);
        let diagnosis = diagnose::diagnose(&robot, &train, &Default::default()).unwrap();
        let chosen = pipeline::effects_of(&diagnosis.selected);
        let selection = EffectSelection::List(chosen.clone());
        let model =
            pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default().with_effects(selection)).unwrap().0;
        let fitted = model::evaluate(&model, &model.bind(&off).unwrap()).unwrap().summary.mean_position_error_mm;
        let joint_2 = diagnosis.arcs.iter().find(|a| a.joint == 2).expect("joint 2 moves");
        eprintln!(
            "seed {seed}: chosen {chosen:?}; random folds {:.4} -> {:.4} mm; joint 2's arcs {:.4} -> {:.4} mm; fitted, off the poses: {fitted:.4} mm ({} rows)",
            diagnosis.heldout_before_mm,
            diagnosis.heldout_after_selected_mm,
            joint_2.before_mm,
            joint_2.after_mm,
            off.rows.len()
        );
        assert!(!chosen.is_empty(), "seed {seed}: the gear error is found");
        // Random folds promise about a tenth of what the fit gives there; the arcs' prediction is
        // within 25 % of the fitted error.
        assert!(diagnosis.heldout_after_selected_mm < 0.5 * fitted, "seed {seed}: random folds see the gap now?");
        assert!(
            (joint_2.after_mm - fitted).abs() <= 0.25 * fitted,
            "seed {seed}: predicted {} mm, fitted {fitted} mm",
            joint_2.after_mm
        );
    }
}

/// A drift fitted within one session was applied as a straight line eight days later.
/// Session 2 repeats session 1's drift from its own start (its placement drifts again from where
/// it began), recorded eight days later: the drift fitted on session 1 falls back to the geometry
/// there, so `--effects time_drift` is no worse than without it, where the line was far worse.
#[test]
fn a_drift_fitted_in_one_session_is_not_carried_into_another_days_later() {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects {
        time_drift: Some(TimeDriftModel { twist_per_s: [4e-8, -3e-8, 2e-8, 0.0, 1e-8, 0.0] }),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    let cell = simulated_cell(&robot, &Perturbation::default(), 61).unwrap();
    let session = |seed: u64| {
        let config = GeneratorConfig { sample_count: 250, seed, ..GeneratorConfig::default() };
        simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap()
    };
    let first = session(61);
    let mut later = session(62);
    for row in &mut later.rows {
        row.t_s = row.t_s.map(|t| t + 8.0 * 86_400.0);
    }
    let fit = |selection: &str, hold: f64| {
        let mut options = FitOptions::default().with_effects(if selection.is_empty() {
            EffectSelection::None
        } else {
            selection.parse().unwrap()
        });
        options.effects.hold_beyond_span = hold;
        // The line: no hold, and no fallback where the drift's σ grows eight days out either.
        if hold > 1e6 {
            options.effects.fallback_sigma_ratio = f64::INFINITY;
        }
        let model = pipeline::fit(&robot, &first, Method::Poe, &options).unwrap().0;
        model::evaluate(&model, &model.bind(&later).unwrap()).unwrap().summary.mean_position_error_mm
    };
    let (alone, with, line) = (fit("", 1.0), fit("time_drift", 1.0), fit("time_drift", 1e9));
    eprintln!("eight days later: poe {alone:.4} mm, with the drift {with:.4} mm, the drift as a line {line:.4} mm");
    assert!(with <= 1.02 * alone, "{with} mm against {alone} mm without the drift");
    assert!(line > 10.0 * alone, "the line carried on: {line} mm");
}

/// The effects' σ: trained on poses whose elbow follows the shoulder (`|q2 + q3| < 0.15`
/// rad), effects whose regressors depend on the arm's configuration are determined only along that
/// band. Rows inside every joint's fitted range but off the band (`|q2 + q3| > 0.6`) excite
/// parameter combinations no training row did: the posterior σ says so, and there the model falls
/// back to the geometry fitted alone, so it is no worse than the geometry by more than the noise.
/// The simulated arm has no such effect: whatever the effects fit is noise, which is what an
/// effect selected on real data with gaps fits where its poses do not reach (UR10 series D).
#[test]
fn rows_that_excite_what_no_training_row_did_have_a_large_sigma_and_fall_back_to_the_geometry() {
    let robot = testkit::robot("irb4400.ron");
    for seed in [61, 62] {
        let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..Effects::default() };
        let cell = simulated_cell(&robot, &Perturbation::default(), seed).unwrap();
        let config = GeneratorConfig { sample_count: 3000, seed, ..GeneratorConfig::default() };
        let all = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();
        let band = |q: &[f64]| (q[1] + q[2]).abs();
        let pick = |keep: &dyn Fn(&[f64]) -> bool| {
            let rows: Vec<usize> = (0..all.rows.len()).filter(|&i| keep(&all.rows[i].q)).collect();
            all.subset(&rows)
        };
        let (train, off) = (pick(&|q| band(q) < 0.15), pick(&|q| band(q) > 0.6));
        assert!(train.rows.len() > 300 && off.rows.len() > 1000, "{} / {} rows", train.rows.len(), off.rows.len());
        let fit = |effects: &str, ratio: f64| {
            let selection: EffectSelection =
                if effects.is_empty() { EffectSelection::None } else { effects.parse().unwrap() };
            let mut options = FitOptions::default().with_effects(selection);
            options.effects.fallback_sigma_ratio = ratio;
            pipeline::fit(&robot, &train, Method::Poe, &options).unwrap().0
        };
        let error = |model: &model::CalibratedModel, set: &MeasurementSet| {
            model::evaluate(model, &model.bind(set).unwrap()).unwrap().summary.mean_position_error_mm
        };
        let geometry = fit("", f64::INFINITY);
        // The simulated arm has only geometric errors: what the geometry leaves on its own
        // training rows is the tracker's noise.
        let (alone, floor) = (error(&geometry, &off), error(&geometry, &train));
        for effects in ["joint_compliance", "joint_compliance,gear_periodic:2:8,gear_periodic:3:8"] {
            let (model, never) =
                (fit(effects, FitOptions::default().effects.fallback_sigma_ratio), fit(effects, f64::INFINITY));
            let (corrected, unguarded) = (error(&model, &off), error(&never, &off));
            eprintln!(
                "seed {seed}, {effects}: off the band: geometry {alone:.4} mm, with effects {corrected:.4} mm \
                 (without the fallback {unguarded:.4} mm), noise {floor:.4} mm"
            );
            // Without the fallback, the effects make the rows off the band worse: the case exists.
            assert!(unguarded > 1.5 * alone, "seed {seed}, {effects}: {unguarded} against {alone}");
            // No worse than the geometry by more than a quarter of the noise (the blend between
            // the limit and twice it keeps a little of the effects).
            assert!(corrected <= alone + 0.25 * floor, "seed {seed}, {effects}: {corrected} against {alone}");
            // Where the model was fitted, nothing falls back: the predictions are the unguarded
            // model's, and every training row's σ is below the limit.
            let uncertainty = model.effect_uncertainty.as_ref().unwrap();
            assert!(uncertainty.training_sigma_m[1] < uncertainty.fallback_sigma_m);
            assert_eq!(error(&model, &train), error(&never, &train), "seed {seed}, {effects}");
            let fallen = model.sigma_fallback(&model.bind(&off).unwrap()).unwrap();
            let fallen = fallen.expect("rows off the band fall back");
            assert!(fallen.rows > off.rows.len() / 4, "seed {seed}, {effects}: {fallen:?}");
        }
    }
}

/// The columns the effects' σ is carried through (`EffectUncertainty::parameter_changes`) against
/// finite differences of the model's own prediction: each free kinematic parameter (a left
/// perturbation of its local transform) and each effect parameter moves the tool point and the
/// orientation as the column says.
#[test]
fn the_sigmas_columns_are_the_derivatives_of_the_prediction() {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects {
        gear_periodic: Some(joint_2_gear_error()),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    let (train, test) = split(&robot, &effects, 5);
    let options = FitOptions::default().with_effects("joint_compliance,gear_periodic:2:4".parse().unwrap());
    let (model, _) = pipeline::fit(&robot, &train, Method::Poe, &options).unwrap();
    let uncertainty = model.effect_uncertainty.clone().expect("a fit with effects keeps its uncertainty");
    // The plain sum of the parts: no fallback, so the prediction is the geometry and the effects.
    let plain = model::CalibratedModel { effect_uncertainty: None, fallback_kinematics: None, ..model.clone() };
    let first = test.rows[..3].iter().map(|r| measurements::Measurement { tool: 0, ..r.clone() }).collect();
    let bound = measurements::BoundSet::made_for_model("the first rows", first);
    let rows = bound.rows();
    let poses = |m: &model::CalibratedModel| m.geometric_poses(&bound).unwrap();
    let base = poses(&plain);
    let layout = plain.kinematics.layout().len();
    let h = 1e-7;
    let mut perturbed = Vec::new();
    for &c in &uncertainty.free {
        let mut m = plain.clone();
        let mut delta = vec![0.0; layout];
        delta[c] = h;
        m.kinematics.apply_update(&delta);
        perturbed.push(poses(&m));
    }
    let mut offset = 0;
    for k in 0..plain.effects.len() {
        for l in 0..plain.effects[k].parameter_count() {
            let mut m = plain.clone();
            let mut theta = m.effects[k].theta().to_vec();
            theta[l] += h;
            m.effects[k].set_theta(&theta);
            perturbed.push(poses(&m));
        }
        offset += plain.effects[k].parameter_count();
    }
    assert_eq!(perturbed.len(), uncertainty.free.len() + offset);
    for (i, row) in rows.iter().enumerate() {
        let changes = uncertainty.parameter_changes(&model.kinematics, &model.effects, row, 0).unwrap();
        assert_eq!(changes.len(), perturbed.len());
        for (j, (change, moved)) in changes.iter().zip(&perturbed).enumerate() {
            let dp = (moved[i].translation() - base[i].translation()) / h;
            let dr = (moved[i].rotation() * base[i].rotation().inverse()).log() / h;
            let fd = [dp.x, dp.y, dp.z, dr[0], dr[1], dr[2]];
            let norm = change.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-3);
            for k in 0..6 {
                // The columns leave out how the effects' own twist turns the kinematic columns
                // (first order in the effects' size, 1e-4 here): 1e-3 of the column.
                assert!(
                    (fd[k] - change[k]).abs() <= 1e-3 * norm,
                    "row {i}, parameter {j}, component {k}: analytic {} against {}",
                    change[k],
                    fd[k]
                );
            }
        }
    }
}

/// Order selection that sees gaps: a selected series' order minimises the weighted sum
/// of its random folds' and its arcs' held-out curves, both reported; with the weight at 0 the
/// arcs are not computed and the order is the random folds' minimum, as before. Trained with a
/// 40° gap in joint 2 (seed 53), the random folds alone pick 32 harmonics for a series whose
/// highest is 12; with the other joints' arcs the order is 12.
#[test]
fn a_series_order_weighs_the_random_folds_and_the_other_joints_arcs() {
    let (robot, all) = joint_2_gear_campaign(53);
    let train = rows_where(&all, |q| (0.35..=0.9).contains(&q.abs()));
    let argmin = |values: Vec<f64>| values.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1)).unwrap().0;
    for weight in [0.5, 0.0, 1.0] {
        let mut options = diagnose::DiagnoseOptions::default();
        options.selection.arc_order_weight = weight;
        let d = diagnose::diagnose(&robot, &train, &options).unwrap();
        let series: Vec<&diagnose::SelectedEffect> = d.selected.iter().filter(|s| s.harmonic.is_some()).collect();
        assert!(!series.is_empty(), "the gear error is selected");
        for s in series {
            let curve = &s.order_curve;
            assert!(!curve.is_empty());
            assert_eq!(curve.iter().all(|c| c.arcs_mm.is_some()), weight > 0.0, "{curve:?}");
            let combined =
                curve.iter().map(|c| (1.0 - weight) * c.random_folds_mm + weight * c.arcs_mm.unwrap_or(0.0)).collect();
            eprintln!("weight {weight}: order {:?} of {curve:?}", s.harmonic);
            assert_eq!(s.harmonic, Some(curve[argmin(combined)].order), "weight {weight}");
            if s.joints == [2] {
                let order = s.harmonic.unwrap();
                assert!(if weight == 0.0 { order > 12 } else { order == 12 }, "weight {weight}: order {order}");
            }
        }
    }
}
