//! The GP methods on simulated data with a load effect: the paper's ordering on held-out rows.

use campaign::{GeneratorConfig, Perturbation, joint_ranges, paper_effects, simulate, simulated_cell};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use robot::RobotDescription;

/// Simulated tracker data of a perturbed IRB 4400 whose joints give under gravity and payload.
/// The payloads span the robot's rating (0 to 60 kg), where the load effect is of the same order
/// as the self-weight one.
fn loaded_data(robot: &RobotDescription, rows: usize, full_pose: bool, seed: u64) -> MeasurementSet {
    let cell = simulated_cell(robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig {
        sample_count: rows,
        seed,
        payloads_kg: vec![0.0, 15.0, 30.0, 45.0, 60.0],
        ..GeneratorConfig::default()
    };
    simulate(&cell, &paper_effects(), &joint_ranges(robot), &config, full_pose).unwrap()
}

#[test]
fn with_a_load_effect_poe_gp_load_beats_poe_gp_which_beats_poe() {
    let robot = testkit::robot("irb4400.ron");
    for (seed, full_pose) in [(11, true), (12, false)] {
        let all = loaded_data(&robot, 400, full_pose, seed);
        let train = all.subset(&(0..250).collect::<Vec<_>>());
        let test = all.subset(&(250..400).collect::<Vec<_>>());
        let error = |method| {
            let (model, _) = pipeline::fit(&robot, &train, method, &FitOptions::default()).unwrap();
            model::evaluate(&model, &model.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm
        };
        let (poe, gp, load) = (error(Method::Poe), error(Method::PoeGp), error(Method::PoeGpLoad));
        eprintln!("seed {seed} full pose {full_pose}: poe {poe:.4} poe-gp {gp:.4} poe-gp-load {load:.4} mm");
        assert!(gp < 0.9 * poe, "poe-gp {gp} mm should beat poe {poe} mm by 10 %");
        assert!(load < 0.9 * gp, "poe-gp-load {load} mm should beat poe-gp {gp} mm by 10 %");
    }
}

#[test]
fn identified_joint_compliance_leaves_little_more_than_the_noise() {
    let robot = testkit::robot("irb4400.ron");
    for (seed, full_pose) in [(13, true), (14, false)] {
        let all = loaded_data(&robot, 400, full_pose, seed);
        let train = all.subset(&(0..250).collect::<Vec<_>>());
        let test = all.subset(&(250..400).collect::<Vec<_>>());
        let error = |method, joint_compliance: bool| {
            let effects = if joint_compliance { "joint_compliance".parse().unwrap() } else { Default::default() };
            let options = FitOptions::default().with_effects(effects);
            let (model, _) = pipeline::fit(&robot, &train, method, &options).unwrap();
            model::evaluate(&model, &model.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm
        };
        let load = error(Method::PoeGpLoad, false);
        let compliance = error(Method::Poe, true);
        eprintln!(
            "seed {seed} full pose {full_pose}: poe-gp-load {load:.4} mm, poe + joint compliance {compliance:.4} mm"
        );
        // The Leica-like noise alone leaves about 0.03 mm.
        assert!(compliance < 0.06, "poe with joint compliance left {compliance} mm");
        assert!(compliance < 0.5 * load, "joint compliance {compliance} mm against poe-gp-load {load} mm");
    }
}

#[test]
fn a_gp_search_stopped_by_its_iteration_limit_is_reported_not_passed_off_as_converged() {
    let robot = testkit::robot("irb4400.ron");
    let data = loaded_data(&robot, 120, false, 21);
    let warned = |max_iterations: usize, method: model::GpChoice| {
        let mut options = FitOptions::default();
        options.residual_gp.gp.optimiser.max_iterations = max_iterations;
        options.residual_gp.method = method;
        let (_, report) = pipeline::fit(&robot, &data, Method::PoeGpLoad, &options).unwrap();
        report.warnings.iter().find_map(|w| match w {
            pipeline::FitWarning::GpSearchNotConverged { outputs, iterations } => Some((outputs.clone(), *iterations)),
            _ => None,
        })
    };
    for method in [model::GpChoice::Exact, model::GpChoice::Sparse] {
        let (outputs, iterations) = warned(1, method).expect("one iteration cannot meet the tolerance");
        assert!(!outputs.is_empty() && outputs.iter().all(|o| *o < 3), "{method:?}: outputs {outputs:?}");
        assert_eq!(iterations, 1, "{method:?}");
        assert_eq!(warned(200, method), None, "{method:?}: the default limit converges on these data");
    }
}

/// The GP interpolates its training poses, so its training error says little: the fit report
/// carries its leave-one-out error beside it, which lies well above the training error and near
/// the error on poses the fit never saw; on full-pose data, asked to, the rotation outputs share
/// one kernel (`rotation_follows_position`).
#[test]
fn fit_report_gives_the_gp_leave_one_out_error_near_the_held_out_error() {
    let robot = testkit::robot("irb4400.ron");
    for (seed, full_pose) in [(15, true), (16, false)] {
        let all = loaded_data(&robot, 400, full_pose, seed);
        let train = all.subset(&(0..250).collect::<Vec<_>>());
        let test = all.subset(&(250..400).collect::<Vec<_>>());
        // The shared rotation kernel is off by default (it cost rotation accuracy on the UR10):
        // switched on here so that its grouping is tested too.
        let mut options = FitOptions::default();
        options.residual_gp.rotation_follows_position = true;
        let (model, report) = pipeline::fit(&robot, &train, Method::PoeGpLoad, &options).unwrap();
        let held_out = model::evaluate(&model, &model.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm;
        let residual_gp = report.residual_gp.as_ref().expect("a GP method reports its GP");
        let loo = residual_gp.leave_one_out.as_ref().expect("the exact GP has a leave-one-out error");
        let training = report.after.mean_position_error_mm;
        eprintln!(
            "seed {seed} full pose {full_pose}: training {training:.4}, leave-one-out {:.4}, held out {held_out:.4} mm",
            loo.mean_position_error_mm
        );
        assert_eq!(loo.n, train.rows.len());
        assert!(loo.mean_position_error_mm > 1.2 * training, "leave-one-out {loo:?}, training {training}");
        let ratio = loo.mean_position_error_mm / held_out;
        assert!(
            (0.7..1.3).contains(&ratio),
            "leave-one-out {} mm against held out {held_out} mm",
            loo.mean_position_error_mm
        );
        assert_eq!(loo.mean_rotation_error_mrad.is_some(), full_pose);
        if let model::GpFitReport::Exact(gp) = &residual_gp.gp {
            let groups: Vec<&Vec<usize>> = gp.components.iter().map(|c| &c.outputs).collect();
            let expected: Vec<Vec<usize>> = if full_pose {
                vec![vec![0], vec![1], vec![2], vec![3, 4, 5]]
            } else {
                vec![vec![0], vec![1], vec![2]]
            };
            assert_eq!(groups, expected.iter().collect::<Vec<_>>());
            assert!(gp.components.iter().all(|c| c.isotropic_choice.is_some()), "the isotropic kernel was weighed");
        } else {
            panic!("250 rows are fitted with the exact GP");
        }
    }
}

/// Every training configuration measured twice (a third of UR10 series B's rows): a
/// row left out alone keeps its twin, whose value the GP returns, so the per-row leave-one-out
/// error flatters the model; the model keeps the error with each configuration left out whole,
/// near what fresh poses measure, and the report gives both.
#[test]
fn repeated_configurations_are_left_out_together_in_the_stored_heldout_estimate() {
    use rand::{Rng, SeedableRng};
    let robot = testkit::robot("irb4400.ron");
    for seed in [17, 18] {
        let all = loaded_data(&robot, 400, false, seed);
        let once = all.subset(&(0..120).collect::<Vec<_>>());
        let test = all.subset(&(250..400).collect::<Vec<_>>());
        // The twin: the same joints and payload, the tracker's noise drawn again (±0.05 mm).
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut train = once.clone();
        for row in &once.rows {
            let mut twin = row.clone();
            for c in 0..3 {
                twin.position[c] += rng.random_range(-5e-5..5e-5);
            }
            train.rows.push(twin);
        }
        let (model, report) = pipeline::fit(&robot, &train, Method::PoeGpLoad, &FitOptions::default()).unwrap();
        let held_out = model::evaluate(&model, &model.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm;
        let gp = report.residual_gp.as_ref().expect("a GP method reports its GP");
        let per_row = gp.leave_one_out.as_ref().expect("exact GP").mean_position_error_mm;
        let grouped = gp.leave_group_out.as_ref().expect("repeats give a grouped error").mean_position_error_mm;
        let stored = model.heldout.expect("the fit keeps an estimate");
        eprintln!("seed {seed}: leave-one-out {per_row:.4}, leave-group-out {grouped:.4}, held out {held_out:.4} mm");
        assert_eq!((gp.repeated_rows, gp.repeated_configurations), (240, 120));
        assert_eq!(stored.source, model::HeldoutSource::GpLeaveGroupOut);
        assert_eq!(stored.mean_position_error_mm, grouped);
        let ratio = grouped / held_out;
        assert!((0.7..1.3).contains(&ratio), "leave-group-out {grouped} mm against held out {held_out} mm");
        assert!(
            per_row < 0.7 * held_out,
            "the twins no longer flatter the per-row error: {per_row} against {held_out}"
        );
    }
}

/// Where the GP's training rows say nothing of a pose, its correction fades and the
/// model is the geometry it was fitted with, with a σ that counts what it no longer corrects; at
/// the training poses nothing fades.
#[test]
fn where_the_gp_knows_nothing_its_correction_fades_to_the_geometry() {
    let robot = testkit::robot("irb4400.ron");
    let all = loaded_data(&robot, 200, true, 21);
    let (model, _) = pipeline::fit(&robot, &all, Method::PoeGp, &FitOptions::default()).unwrap();
    let gp = model.residual_gp.as_ref().unwrap();
    let fade = gp.fade.expect("the default options fade");
    assert_eq!(Some(fade.above), FitOptions::default().residual_gp.fade_above_variance_ratio);
    assert!((0.0..1.0).contains(&fade.training_share), "{fade:?}");
    assert!(model.gp_fade(&all.rows).unwrap().is_none(), "no training row fades");
    // Every joint a whole radian beyond its sampled range: nothing the GP has seen.
    let mut far = all.subset(&(0..20).collect::<Vec<_>>());
    let top: Vec<f64> = (0..6).map(|j| all.rows.iter().map(|r| r.q[j]).fold(f64::NEG_INFINITY, f64::max)).collect();
    for row in &mut far.rows {
        for (q, top) in row.q.iter_mut().zip(&top) {
            *q = top + 1.0 + 0.1 * (*q).sin();
        }
    }
    let faded = model.gp_fade(&far.rows).unwrap().expect("the far rows fade");
    assert_eq!((faded.rows, faded.of_rows), (20, 20), "{faded}");
    let weights = gp.weights(&far.rows).unwrap();
    assert!(weights.iter().filter(|(w, _)| *w < 0.05).count() >= 18, "{weights:?}");
    let predict = |m: &model::CalibratedModel| m.predict(&m.bind(&far).unwrap()).unwrap();
    let with = predict(&model);
    let mut geometry = model.clone();
    geometry.residual_gp = None;
    let mut never = model.clone();
    never.residual_gp.as_mut().unwrap().fade = None;
    let (alone, unfaded) = (predict(&geometry), predict(&never));
    let gap = |a: &[model::PredictedPose], b: &[model::PredictedPose], i: usize| {
        (a[i].pose.translation() - b[i].pose.translation()).norm()
    };
    let mut moved = 0.0_f64;
    for i in 0..far.rows.len() {
        let w = gp.weights(&far.rows[i..=i]).unwrap()[0].0;
        // The correction scales with the weight: none where it is 0.
        assert!(gap(&with, &alone, i) <= w * gap(&unfaded, &alone, i) * (1.0 + 1e-3) + 1e-12, "row {i}: weight {w}");
        moved = moved.max(gap(&unfaded, &alone, i));
        // What is not corrected is in the σ.
        let (sigma, sigma_never) = (with[i].std.unwrap(), unfaded[i].std.unwrap());
        assert!((0..3).all(|k| sigma[k] >= sigma_never[k] - 1e-15), "row {i}: {sigma:?} {sigma_never:?}");
    }
    assert!(moved > 1e-7, "without the fade the GP moves the far poses: {moved} m (the test is not vacuous)");
}

/// The fade's training share ([`model::GpFadeRule::training_share`]) is what its rule says: the
/// median, over the GP's training rows, of the share of the prior variance of the position
/// outputs (pooled) that the posterior keeps at each row left out of it, the noise taken off
/// (R&W Eq. 5.12). Recomputed here from the GP's own leave-one-out, so that a share taken at the
/// row with it in, with the noise, over all six outputs, or a mean for the median, fails.
#[test]
fn the_fades_training_share_is_the_median_share_the_left_out_training_rows_keep() {
    let robot = testkit::robot("irb4400.ron");
    // An odd count: the median is one row's share, whichever way it is taken.
    let all = loaded_data(&robot, 61, true, 23);
    let (model, _) = pipeline::fit(&robot, &all, Method::PoeGp, &FitOptions::default()).unwrap();
    let gp = model.residual_gp.as_ref().unwrap();
    let fade = gp.fade.expect("the default options fade");
    let model::GpModel::Exact(exact) = &gp.gp else { panic!("61 rows: the exact GP") };
    assert!(gp.fallback.is_none() && gp.inputs.is_empty());
    let joints = all.rows[0].q.len();
    let x = faer::Mat::from_fn(all.rows.len(), exact.input_dim(), |i, c| {
        if c < joints { all.rows[i].q[c] } else { all.rows[i].payload_kg }
    });
    let loo = exact.leave_one_out().unwrap();
    let prior = exact.prior_variance(x.as_ref()).unwrap();
    let scale = &exact.output_normaliser().scale;
    let mut noise = vec![0.0; exact.output_count()];
    for component in &exact.report().components {
        for &out in &component.outputs {
            noise[out] = component.kernel.noise_variance() * scale[out] * scale[out];
        }
    }
    let mut shares: Vec<f64> = (0..all.rows.len())
        .map(|i| {
            let kept: f64 = (0..3).map(|c| (loo.variance[(i, c)] - noise[c]).max(0.0)).sum();
            let whole: f64 = (0..3).map(|c| prior[(i, c)]).sum();
            (kept / whole).min(1.0)
        })
        .collect();
    shares.sort_by(f64::total_cmp);
    let median = shares[shares.len() / 2];
    eprintln!(
        "training share {} against the median {median} (from {} to {})",
        fade.training_share, shares[0], shares[60]
    );
    assert!(shares[0] < shares[60], "the shares differ between rows: {shares:?}");
    assert!(
        (fade.training_share - median).abs() <= 1e-9 * median.max(1e-12),
        "{} against {median}",
        fade.training_share
    );
}
