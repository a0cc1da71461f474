//! Closed-form leave-one-out prediction (R&W Eqs. 5.10–5.12) and the isotropic kernel's choice by it.

mod common;

use common::{rng, uniform_points};
use faer::Mat;
use gp::{ExactGp, GpConfig, Kernel, KernelChoice, OptimiserConfig, OutputMode, PredictOptions, StationaryShape};

fn data(seed: u64, n: usize, d: usize, m: usize) -> (Mat<f64>, Mat<f64>) {
    let mut r = rng(seed);
    let x = uniform_points(&mut r, n, d, -2.0, 2.0);
    let noise = uniform_points(&mut r, n, m, -0.05, 0.05);
    let y = Mat::from_fn(n, m, |i, c| {
        (x[(i, 0)] * (1.0 + c as f64)).sin() + 0.3 * x[(i, d - 1)] * x[(i, 1)] + noise[(i, c)]
    });
    (x, y)
}

fn without_row(m: &Mat<f64>, skip: usize) -> Mat<f64> {
    Mat::from_fn(m.nrows() - 1, m.ncols(), |i, j| m[(if i < skip { i } else { i + 1 }, j)])
}

/// Each row's closed-form prediction equals the prediction of a GP refitted on the other rows
/// with the same hyperparameters (no scaling maps, which would be refitted too), for one kernel
/// per output and for a kernel shared by several outputs.
#[test]
fn closed_form_leave_one_out_equals_refitting_without_the_row() {
    let (x, y) = data(3, 40, 3, 2);
    for outputs in [OutputMode::Independent, OutputMode::Shared] {
        let config = GpConfig {
            kernel: KernelChoice::SquaredExponentialArd,
            outputs,
            standardise_inputs: false,
            normalise_outputs: false,
            optimiser: OptimiserConfig { restarts: 0, ..OptimiserConfig::default() },
            ..GpConfig::default()
        };
        let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
        let kernels: Vec<Kernel> = model.report().components.iter().map(|c| c.kernel.clone()).collect();
        let loo = model.leave_one_out().expect("leave-one-out");
        for i in [0, 17, 39] {
            let refit = ExactGp::fit_fixed(without_row(&x, i).as_ref(), without_row(&y, i).as_ref(), &kernels, &config)
                .expect("refit");
            let xi = Mat::from_fn(1, x.ncols(), |_, j| x[(i, j)]);
            let options = PredictOptions { include_noise: true, ..PredictOptions::default() };
            let p = refit.predict_with(xi.as_ref(), &options).expect("predict");
            for c in 0..y.ncols() {
                let (mean, var) = (p.mean[(0, c)], p.variance[(0, c)]);
                assert!(
                    (loo.mean[(i, c)] - mean).abs() < 1e-8,
                    "{outputs:?} row {i} output {c}: {} vs {mean}",
                    loo.mean[(i, c)]
                );
                assert!(
                    (loo.variance[(i, c)] - var).abs() < 1e-8 * var.max(1.0),
                    "{outputs:?} row {i} output {c}: {} vs {var}",
                    loo.variance[(i, c)]
                );
            }
        }
    }
}

/// Rows 0..40 and, for rows 0..12, a second measurement of the same input (a repeated pose,
/// other noise): the groups are `{i, 40 + i}` for `i < 12` and singletons otherwise.
fn twinned(seed: u64) -> (Mat<f64>, Mat<f64>, Vec<Vec<usize>>) {
    let (x0, y0) = data(seed, 40, 3, 2);
    let mut r = rng(seed + 100);
    let noise = uniform_points(&mut r, 12, 2, -0.05, 0.05);
    let x = Mat::from_fn(52, 3, |i, j| x0[(if i < 40 { i } else { i - 40 }, j)]);
    let y = Mat::from_fn(52, 2, |i, c| if i < 40 { y0[(i, c)] } else { y0[(i - 40, c)] + noise[(i - 40, c)] });
    let groups = (0..40).map(|i| if i < 12 { vec![i, 40 + i] } else { vec![i] }).collect();
    (x, y, groups)
}

/// Each row of a group predicted in closed form equals the prediction of a GP refitted without
/// the whole group, same hyperparameters; and a twin's leave-one-out prediction is its twin's
/// value (what made the per-row error flatter), the grouped one is not.
#[test]
fn closed_form_leave_group_out_equals_refitting_without_the_group() {
    let (x, y, groups) = twinned(8);
    let config = GpConfig {
        kernel: KernelChoice::SquaredExponentialArd,
        standardise_inputs: false,
        normalise_outputs: false,
        optimiser: OptimiserConfig { restarts: 0, ..OptimiserConfig::default() },
        ..GpConfig::default()
    };
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    let kernels: Vec<Kernel> = model.report().components.iter().map(|c| c.kernel.clone()).collect();
    let grouped = model.leave_groups_out(&groups).expect("leave-group-out");
    let single = model.leave_one_out().expect("leave-one-out");
    for group in [&groups[0], &groups[5], &groups[20]] {
        let keep: Vec<usize> = (0..x.nrows()).filter(|i| !group.contains(i)).collect();
        let pick = |m: &Mat<f64>, rows: &[usize]| Mat::from_fn(rows.len(), m.ncols(), |a, j| m[(rows[a], j)]);
        let refit =
            ExactGp::fit_fixed(pick(&x, &keep).as_ref(), pick(&y, &keep).as_ref(), &kernels, &config).expect("refit");
        let options = PredictOptions { include_noise: true, ..PredictOptions::default() };
        let p = refit.predict_with(pick(&x, group).as_ref(), &options).expect("predict");
        for (a, &i) in group.iter().enumerate() {
            for c in 0..y.ncols() {
                let (mean, var) = (p.mean[(a, c)], p.variance[(a, c)]);
                assert!(
                    (grouped.mean[(i, c)] - mean).abs() < 1e-8,
                    "row {i} output {c}: {} vs {mean}",
                    grouped.mean[(i, c)]
                );
                assert!((grouped.variance[(i, c)] - var).abs() < 1e-8 * var.max(1.0), "row {i} output {c}");
            }
        }
    }
    // Summed over the twinned rows, the per-row error is far below the grouped one.
    let error = |m: &Mat<f64>| groups[..12].iter().flatten().map(|&i| (m[(i, 0)] - y[(i, 0)]).abs()).sum::<f64>();
    assert!(error(&single.mean) < 0.8 * error(&grouped.mean), "{} vs {}", error(&single.mean), error(&grouped.mean));
}

/// With every group one row, the grouped prediction is the leave-one-out prediction to the bit;
/// groups that are not a partition of the rows are refused with the row.
#[test]
fn singleton_groups_give_leave_one_out_and_bad_groups_are_refused() {
    let (x, y) = data(9, 30, 3, 2);
    let config = GpConfig { kernel: KernelChoice::SquaredExponentialArd, ..GpConfig::default() };
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    let singles: Vec<Vec<usize>> = (0..30).map(|i| vec![i]).collect();
    let grouped = model.leave_groups_out(&singles).expect("groups");
    let single = model.leave_one_out().expect("leave-one-out");
    assert_eq!(grouped.mean, single.mean);
    assert_eq!(grouped.variance, single.variance);
    assert_eq!(grouped.log_predictive, single.log_predictive);
    let missing: Vec<Vec<usize>> = (0..29).map(|i| vec![i]).collect();
    let twice: Vec<Vec<usize>> = (0..30).map(|i| vec![i, (i + 1) % 30]).collect();
    let beyond: Vec<Vec<usize>> = (0..30).map(|i| vec![if i == 3 { 30 } else { i }]).collect();
    for (groups, row) in [(missing, 29), (twice, 1), (beyond, 30)] {
        let result = model.leave_groups_out(&groups);
        assert!(matches!(result, Err(gp::Error::InvalidGroups { rows: 30, row: r }) if r == row), "{result:?}");
    }
}

/// With the isotropic candidate on, each kernel's report says which kernel was kept and why, the
/// model's kernel is that one, and the criterion recorded for the kept kernel is the leave-one-out
/// log predictive probability of the model as fitted.
#[test]
fn isotropic_choice_keeps_the_kernel_with_the_higher_leave_one_out_probability() {
    let (x, y) = data(4, 60, 4, 3);
    let kernel = KernelChoice::Composite {
        shape: StationaryShape::SquaredExponential,
        constant: false,
        linear: false,
        additive: true,
    };
    let config = GpConfig { kernel, additive_by_bic: true, isotropic_by_loo: true, ..GpConfig::default() };
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    let loo = model.leave_one_out().expect("leave-one-out");
    for c in &model.report().components {
        let choice = c.isotropic_choice.as_ref().expect("choice made");
        assert_eq!(choice.kept_isotropic, choice.isotropic > choice.searched);
        assert_eq!(choice.kept_isotropic, matches!(c.kernel, Kernel::Quadratic(_)));
        let kept = if choice.kept_isotropic { choice.isotropic } else { choice.searched };
        let out = c.outputs[0];
        assert!(
            (loo.log_predictive[out] - kept).abs() < 1e-6 * kept.abs().max(1.0),
            "{} vs {kept}",
            loo.log_predictive[out]
        );
    }
}

/// `n` rows of six inputs and two pairs of outputs: the isotropic kernel's own kind (a smooth
/// function of the sum of the inputs, so of a distance, with a linear trend) and one short-scale
/// input the ARD kernel sees.
fn radial_and_sharp(n: usize) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
    let d = 6;
    let mut r = rng(11);
    let x = uniform_points(&mut r, n, d, -2.0, 2.0);
    let noise = uniform_points(&mut r, n, 2, -0.02, 0.02);
    let radial = Mat::from_fn(n, 2, |i, c| {
        let s: f64 = (0..d).map(|j| x[(i, j)]).sum();
        0.5 * s + (0.2 * s).sin() + noise[(i, c)]
    });
    let sharp = Mat::from_fn(n, 2, |i, c| (4.0 * x[(i, 2)]).sin() + noise[(i, c)]);
    (x, radial, sharp)
}

/// Data drawn from the isotropic kernel's own family (a smooth function of the distance, a
/// constant and a linear trend) on few rows with many inputs: the isotropic kernel is kept for
/// some output, and data with one short-scale input the ARD kernel sees keep the searched kernel.
#[test]
fn isotropic_choice_follows_the_data() {
    let (x, radial, sharp) = radial_and_sharp(50);
    let config =
        GpConfig { kernel: KernelChoice::SquaredExponentialArd, isotropic_by_loo: true, ..GpConfig::default() };
    let kept = |y: &Mat<f64>| {
        let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
        model.report().components.iter().filter(|c| matches!(c.kernel, Kernel::Quadratic(_))).count()
    };
    assert!(kept(&radial) > 0, "the isotropic kernel lost on its own kind of data");
    assert_eq!(kept(&sharp), 0, "the isotropic kernel won on data with one short length scale");
}

/// With a warm-start subset, the isotropic kernel is screened on the subset's own rows first:
/// where it loses there, the choice records the subset's sums and rows and no comparison on all
/// rows is made; where it wins there (data of its own kind), it is compared on all rows as without
/// a subset, and kept where it wins there too.
#[test]
fn isotropic_choice_is_screened_on_the_warm_start_subset() {
    let warm = 45;
    let (x, radial, sharp) = radial_and_sharp(90);
    let config = GpConfig {
        kernel: KernelChoice::SquaredExponentialArd,
        isotropic_by_loo: true,
        optimiser: OptimiserConfig { warm_start_rows: warm, ..OptimiserConfig::default() },
        ..GpConfig::default()
    };
    let choices = |y: &Mat<f64>| {
        let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
        let loo = model.leave_one_out().expect("leave-one-out");
        let mut choices = Vec::new();
        for c in &model.report().components {
            let choice = c.isotropic_choice.clone().expect("choice made");
            assert_eq!(choice.kept_isotropic, matches!(c.kernel, Kernel::Quadratic(_)), "{choice:?}");
            match choice.compared_rows {
                Some(rows) => {
                    assert_eq!((rows, choice.kept_isotropic), (warm, false), "{choice:?}");
                    assert!(choice.isotropic <= choice.searched, "{choice:?}");
                }
                None => {
                    let kept = if choice.kept_isotropic { choice.isotropic } else { choice.searched };
                    let out = loo.log_predictive[c.outputs[0]];
                    assert!((out - kept).abs() < 1e-6 * kept.abs().max(1.0), "{out} vs {kept}");
                }
            }
            choices.push(choice);
        }
        choices
    };
    let radial = choices(&radial);
    assert!(radial.iter().any(|c| c.kept_isotropic), "the isotropic kernel lost on its own kind of data: {radial:?}");
    let sharp = choices(&sharp);
    assert!(sharp.iter().all(|c| c.compared_rows == Some(warm)), "not screened on the subset: {sharp:?}");
}

/// A model written before the choice existed (no `isotropic_choice` in its report) still reads.
#[test]
fn model_without_isotropic_choice_still_reads() {
    let (x, y) = data(5, 20, 2, 1);
    let config = GpConfig { kernel: KernelChoice::SquaredExponentialArd, ..GpConfig::default() };
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    let text = serde_json::to_string(&model).expect("write");
    assert!(!text.contains("isotropic_choice"));
    let back: ExactGp = serde_json::from_str(&text).expect("read");
    assert_eq!(back.report(), model.report());
}

/// A follower group whose outputs are the first output scaled (identical once normalised) is
/// served by one kernel, started from the first output's, and ends at that kernel's likelihood:
/// the refinement starts at the optimum.
#[test]
fn follower_group_starts_from_the_leader_that_explains_it() {
    let (x, y0) = data(6, 50, 3, 2);
    let y = Mat::from_fn(50, 4, |i, c| match c {
        0 | 1 => y0[(i, c)],
        _ => y0[(i, 0)] * (c as f64) + 1.0,
    });
    let config = GpConfig {
        kernel: KernelChoice::SquaredExponentialArd,
        follower_groups: vec![vec![2, 3]],
        ..GpConfig::default()
    };
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    let components = &model.report().components;
    assert_eq!(components.len(), 3);
    let follower = components.iter().find(|c| c.outputs == vec![2, 3]).expect("one kernel serves the group");
    let leader = components.iter().find(|c| c.outputs == vec![0]).expect("output 0 alone");
    let search = follower.optimisation.as_ref().expect("searched");
    assert_eq!(search.start_log_marginal_likelihoods.len(), 1, "one start: the leader's kernel");
    // Two copies of output 0: twice its likelihood.
    let expected = 2.0 * leader.log_marginal_likelihood;
    assert!(
        (follower.log_marginal_likelihood - expected).abs() < 1e-3 * expected.abs(),
        "{} vs {expected}",
        follower.log_marginal_likelihood
    );
}

/// Follower groups that name a column twice, a column that does not exist, no column, or every
/// column (no leader left) are refused.
#[test]
fn invalid_follower_groups_are_refused() {
    let (x, y) = data(7, 20, 2, 3);
    for groups in [vec![vec![1, 1]], vec![vec![3]], vec![vec![]], vec![vec![0, 1, 2]], vec![vec![1], vec![1, 2]]] {
        let config = GpConfig { follower_groups: groups.clone(), ..GpConfig::default() };
        let result = ExactGp::fit(x.as_ref(), y.as_ref(), &config);
        assert!(
            matches!(result, Err(gp::Error::InvalidConfig { field: "follower_groups", .. })),
            "{groups:?}: {result:?}"
        );
    }
}
