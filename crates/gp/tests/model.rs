//! The fitted model: determinism, several outputs, serialisation, jitter, refused input.

mod common;

use common::{rng, uniform_points};
use faer::Mat;
use gp::{
    Bounds, Error, ExactGp, GpConfig, Kernel, KernelChoice, OptimiserConfig, OutputMode, Parallelism,
    SquaredExponentialArd, StationaryShape,
};

fn data(seed: u64, n: usize, d: usize, m: usize) -> (Mat<f64>, Mat<f64>) {
    let mut r = rng(seed);
    let x = uniform_points(&mut r, n, d, -2.0, 2.0);
    let y = Mat::from_fn(n, m, |i, c| {
        (x[(i, 0)] * (1.0 + c as f64)).sin() + 0.2 * x[(i, d - 1)] * c as f64 + 0.01 * ((i * 7 + c) % 5) as f64
    });
    (x, y)
}

fn bits(m: &Mat<f64>) -> Vec<u64> {
    (0..m.nrows()).flat_map(|i| (0..m.ncols()).map(move |j| (i, j))).map(|(i, j)| m[(i, j)].to_bits()).collect()
}

#[test]
fn fit_and_prediction_are_bit_identical_serial_and_parallel() {
    let (x, y) = data(1, 120, 4, 3);
    let (xq, _) = data(2, 30, 4, 1);
    let composite =
        KernelChoice::Composite { shape: StationaryShape::Matern52, constant: true, linear: true, additive: true };
    for kernel in [KernelChoice::Quadratic, KernelChoice::SquaredExponentialArd, KernelChoice::Matern52Ard, composite] {
        let mut results = Vec::new();
        for parallelism in [Parallelism::Sequential, Parallelism::Rayon] {
            let config = GpConfig { kernel, parallelism, ..GpConfig::default() };
            let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
            let p = model.predict(xq.as_ref()).expect("predict");
            results.push((model.report().clone(), bits(&p.mean), bits(&p.variance)));
        }
        assert_eq!(results[0].0, results[1].0, "{kernel:?}: reports differ");
        assert_eq!(results[0].1, results[1].1, "{kernel:?}: means differ");
        assert_eq!(results[0].2, results[1].2, "{kernel:?}: variances differ");
    }
}

/// The calibration's configuration (restarts searched on a warm-start subset, then the full data
/// from the subset's best), fitted serially, on a one-thread rayon pool and on a four-thread pool:
/// the same report and predictions to the last bit.
#[test]
fn warm_started_fit_is_bit_identical_on_any_pool() {
    let (x, y) = data(5, 150, 4, 3);
    let (xq, _) = data(6, 25, 4, 1);
    let composite =
        KernelChoice::Composite { shape: StationaryShape::Matern52, constant: true, linear: true, additive: true };
    for kernel in [KernelChoice::SquaredExponentialArd, composite] {
        let optimiser = OptimiserConfig { restarts: 2, warm_start_rows: 60, ..OptimiserConfig::default() };
        let fit = |parallelism| {
            let config = GpConfig { kernel, parallelism, optimiser: optimiser.clone(), ..GpConfig::default() };
            let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
            let p = model.predict(xq.as_ref()).expect("predict");
            (model.report().clone(), bits(&p.mean), bits(&p.variance))
        };
        let pool = |threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        let serial = fit(Parallelism::Sequential);
        let one = pool(1).install(|| fit(Parallelism::Rayon));
        let four = pool(4).install(|| fit(Parallelism::Rayon));
        let search = serial.0.components[0].optimisation.as_ref().expect("optimised");
        assert_eq!(search.warm_start_rows, 60, "{kernel:?}: the warm start was not used");
        for (name, other) in [("one-thread pool", &one), ("four-thread pool", &four)] {
            assert_eq!(serial.0, other.0, "{kernel:?}, {name}: reports differ");
            assert_eq!(serial.1, other.1, "{kernel:?}, {name}: means differ");
            assert_eq!(serial.2, other.2, "{kernel:?}, {name}: variances differ");
        }
    }
}

/// At a realistic size (n = 900), where faer splits a matrix–vector product or a one-column
/// triangular solve by the thread count (it did from about n = 700 on: `gp::dense`), one
/// likelihood with its gradient and one prediction: the same to the last bit serially and on pools
/// of two and four threads. The tests above use sizes faer never splits.
#[test]
fn likelihood_gradient_and_prediction_are_bit_identical_on_any_pool_at_a_realistic_size() {
    let (x, y) = data(7, 900, 6, 1);
    let (xq, _) = data(8, 40, 6, 1);
    let additive = KernelChoice::Composite {
        shape: StationaryShape::SquaredExponential,
        constant: false,
        linear: false,
        additive: true,
    };
    for choice in [KernelChoice::SquaredExponentialArd, additive] {
        let kernel = Kernel::start(choice, 6);
        let run = |parallelism| {
            let l = gp::log_marginal_likelihood(&kernel, x.as_ref(), y.as_ref(), true, parallelism).expect("lml");
            let config = GpConfig { kernel: choice, parallelism, ..GpConfig::default() };
            let model =
                ExactGp::fit_fixed(x.as_ref(), y.as_ref(), std::slice::from_ref(&kernel), &config).expect("fit");
            let p = model.predict(xq.as_ref()).expect("predict");
            let gradient: Vec<u64> = l.gradient.iter().map(|g| g.to_bits()).collect();
            (l.value.to_bits(), gradient, bits(&p.mean), bits(&p.variance))
        };
        let pool = |threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        let serial = run(Parallelism::Sequential);
        for threads in [2, 4] {
            let parallel = pool(threads).install(|| run(Parallelism::Rayon));
            assert_eq!(serial.0, parallel.0, "{choice:?}, {threads} threads: likelihoods differ");
            assert_eq!(serial.1, parallel.1, "{choice:?}, {threads} threads: gradients differ");
            assert_eq!(serial.2, parallel.2, "{choice:?}, {threads} threads: means differ");
            assert_eq!(serial.3, parallel.3, "{choice:?}, {threads} threads: variances differ");
        }
    }
}

#[test]
fn restarts_are_seeded_and_the_best_start_is_kept() {
    let (x, y) = data(3, 80, 3, 1);
    let config = GpConfig {
        kernel: KernelChoice::Matern52Ard,
        optimiser: OptimiserConfig { restarts: 4, seed: 42, ..OptimiserConfig::default() },
        ..GpConfig::default()
    };
    let a = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    let b = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
    assert_eq!(a.report(), b.report());
    let search = a.report().components[0].optimisation.as_ref().expect("optimised");
    assert_eq!(search.start_log_marginal_likelihoods.len(), 5);
    let best = search.start_log_marginal_likelihoods.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(search.start_log_marginal_likelihoods[search.best_start], Some(best));
    // The kept likelihood is the report's, up to the (absent) jitter.
    assert!((a.log_marginal_likelihood() - best).abs() < 1e-9 * best.abs().max(1.0));
}

#[test]
fn shared_outputs_use_one_kernel_and_independent_outputs_one_each() {
    let (x, y) = data(4, 60, 2, 3);
    let shared =
        GpConfig { outputs: OutputMode::Shared, kernel: KernelChoice::SquaredExponentialArd, ..GpConfig::default() };
    let independent = GpConfig { outputs: OutputMode::Independent, ..shared.clone() };
    let ms = ExactGp::fit(x.as_ref(), y.as_ref(), &shared).expect("fit");
    let mi = ExactGp::fit(x.as_ref(), y.as_ref(), &independent).expect("fit");
    assert_eq!(ms.report().components.len(), 1);
    assert_eq!(ms.report().components[0].outputs, vec![0, 1, 2]);
    assert_eq!(mi.report().components.len(), 3);
    // Each independent kernel maximises its own likelihood, so together they do at least as well.
    assert!(mi.log_marginal_likelihood() >= ms.log_marginal_likelihood() - 1e-6);
    // A shared model predicts each output as a single-output model with the same kernel does.
    let kernel = ms.kernel_for_output(0).expect("kernel").clone();
    let (xq, _) = data(5, 10, 2, 1);
    let ps = ms.predict(xq.as_ref()).expect("predict");
    for c in 0..3 {
        let yc = Mat::from_fn(60, 1, |i, _| y[(i, c)]);
        let single = ExactGp::fit_fixed(x.as_ref(), yc.as_ref(), std::slice::from_ref(&kernel), &shared).expect("fit");
        let p = single.predict(xq.as_ref()).expect("predict");
        for i in 0..10 {
            assert!((p.mean[(i, 0)] - ps.mean[(i, c)]).abs() < 1e-10 * (1.0 + p.mean[(i, 0)].abs()));
            assert!((p.variance[(i, 0)] - ps.variance[(i, c)]).abs() < 1e-10 * (1.0 + p.variance[(i, 0)]));
        }
    }
}

#[test]
fn model_survives_a_ron_round_trip_with_bit_identical_predictions() {
    let (x, y) = data(6, 50, 3, 2);
    let (xq, _) = data(7, 12, 3, 1);
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &GpConfig::default()).expect("fit");
    let before = model.predict(xq.as_ref()).expect("predict");
    let back: ExactGp = ron::from_str(&ron::to_string(&model).expect("serialise")).expect("deserialise");
    assert_eq!(back.report(), model.report());
    let after = back.predict(xq.as_ref()).expect("predict");
    assert_eq!(bits(&before.mean), bits(&after.mean));
    assert_eq!(bits(&before.variance), bits(&after.variance));

    // serde_json (without its float_roundtrip feature) may move a number by one ulp on reading, so
    // JSON only promises predictions equal to round-off.
    let json: ExactGp = serde_json::from_str(&serde_json::to_string(&model).expect("json")).expect("json back");
    let after = json.predict(xq.as_ref()).expect("predict");
    for i in 0..12 {
        for c in 0..2 {
            assert!((after.mean[(i, c)] - before.mean[(i, c)]).abs() < 1e-10 * (1.0 + before.mean[(i, c)].abs()));
            assert!((after.variance[(i, c)] - before.variance[(i, c)]).abs() < 1e-10 * (1.0 + before.variance[(i, c)]));
        }
    }
}

#[test]
fn a_stored_model_with_an_inconsistent_report_is_refused() {
    let (x, y) = data(13, 15, 2, 1);
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &GpConfig::default()).expect("fit");
    let text = ron::to_string(&model).expect("serialise");
    // Point the only kernel at an output that does not exist.
    let broken = text.replacen("outputs:[0]", "outputs:[3]", 1);
    assert_ne!(broken, text, "the stored form names the outputs of each kernel");
    assert!(ron::from_str::<ExactGp>(&broken).is_err());
    // A zero input scale would divide by zero at prediction.
    let start = text.find("scale:[").expect("the stored form has the input scales") + "scale:[".len();
    let end = start + text[start..].find([',', ']']).expect("a number");
    let zero_scale = format!("{}0.0{}", &text[..start], &text[end..]);
    assert!(matches!(ron::from_str::<ExactGp>(&zero_scale), Err(e) if e.to_string().contains("inputs")));
}

#[test]
fn duplicated_points_without_noise_are_rescued_by_reported_jitter() {
    let (x0, y0) = data(8, 20, 2, 1);
    // Every point twice with different outputs and nearly no noise: K is exactly singular.
    let x = Mat::from_fn(40, 2, |i, j| x0[(i % 20, j)]);
    let y = Mat::from_fn(40, 1, |i, _| y0[(i % 20, 0)] + if i < 20 { 0.01 } else { -0.01 });
    let kernel = Kernel::SquaredExponentialArd(SquaredExponentialArd {
        signal_variance: 1.0,
        length_scales: vec![1.0, 1.0],
        noise_variance: 1e-300,
    });
    let model =
        ExactGp::fit_fixed(x.as_ref(), y.as_ref(), std::slice::from_ref(&kernel), &GpConfig::default()).expect("fit");
    let jitter = model.report().components[0].jitter;
    assert!(jitter.added > 0.0 && jitter.failed_attempts >= 1, "{jitter:?}");
    let p = model.predict(x.as_ref()).expect("predict");
    assert!(p.mean.col(0).iter().all(|v| v.is_finite()));
    // The stored model rebuilds with the same jitter.
    let back: ExactGp = ron::from_str(&ron::to_string(&model).expect("ron")).expect("back");
    assert_eq!(back.report().components[0].jitter, jitter);

    // Allowing no jitter makes the same fit fail with the pivot and the jitter tried.
    let strict = GpConfig { jitter: gp::JitterConfig { max_attempts: 0, ..Default::default() }, ..GpConfig::default() };
    match ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &[kernel], &strict) {
        Err(Error::CholeskyFailed { size: 40, jitter_tried, .. }) => assert_eq!(jitter_tried, 0.0),
        other => panic!("expected CholeskyFailed, got {other:?}"),
    }
}

#[test]
fn bad_training_input_is_refused_with_its_numbers() {
    let (x, y) = data(9, 10, 2, 1);
    let config = GpConfig::default();
    let short = Mat::from_fn(9, 1, |i, _| y[(i, 0)]);
    assert_eq!(
        ExactGp::fit(x.as_ref(), short.as_ref(), &config).err(),
        Some(Error::RowCountMismatch { input_rows: 10, output_rows: 9 })
    );
    let empty_x = Mat::<f64>::zeros(0, 2);
    let empty_y = Mat::<f64>::zeros(0, 1);
    assert_eq!(
        ExactGp::fit(empty_x.as_ref(), empty_y.as_ref(), &config).err(),
        Some(Error::TooFewPoints { rows: 0, required: 1 })
    );
    let mut nan_x = x.clone();
    nan_x[(3, 1)] = f64::NAN;
    assert_eq!(
        ExactGp::fit(nan_x.as_ref(), y.as_ref(), &config).err(),
        Some(Error::NonFiniteData { row: 3, column: 1, in_outputs: false })
    );
    let mut inf_y = y.clone();
    inf_y[(5, 0)] = f64::INFINITY;
    assert_eq!(
        ExactGp::fit(x.as_ref(), inf_y.as_ref(), &config).err(),
        Some(Error::NonFiniteData { row: 5, column: 0, in_outputs: true })
    );
    let no_outputs = Mat::<f64>::zeros(10, 0);
    assert_eq!(ExactGp::fit(x.as_ref(), no_outputs.as_ref(), &config).err(), Some(Error::NoOutputs));
}

#[test]
fn bad_configuration_is_refused_with_its_numbers() {
    let (x, y) = data(10, 10, 2, 2);
    let inverted = GpConfig {
        kernel: KernelChoice::SquaredExponentialArd,
        bounds: Some(Bounds { lower: vec![1.0, 2.0, 1.0, 1e-3], upper: vec![2.0, 1.0, 3.0, 1.0] }),
        ..GpConfig::default()
    };
    assert_eq!(
        ExactGp::fit(x.as_ref(), y.as_ref(), &inverted).err(),
        Some(Error::InvalidBounds { index: 1, lower: 2.0, upper: 1.0 })
    );
    let short_bounds = GpConfig { bounds: Some(Bounds { lower: vec![1.0], upper: vec![2.0] }), ..inverted.clone() };
    assert_eq!(
        ExactGp::fit(x.as_ref(), y.as_ref(), &short_bounds).err(),
        Some(Error::ParameterCountMismatch { expected: 4, found: 1 })
    );
    let wrong_dim = Kernel::start(KernelChoice::Matern52Ard, 3);
    assert_eq!(
        ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &[wrong_dim], &GpConfig::default()).err(),
        Some(Error::InputDimensionMismatch { expected: 3, found: 2 })
    );
    let k = Kernel::start(KernelChoice::Quadratic, 2);
    let shared = GpConfig { outputs: OutputMode::Shared, ..GpConfig::default() };
    assert_eq!(
        ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &[k.clone(), k.clone()], &shared).err(),
        Some(Error::InvalidConfig { field: "kernels", value: 2.0 })
    );
    let negative = k.with_parameters(&[1.0, -1.0, 1.0, 1.0, 1.0]).err();
    assert_eq!(negative, Some(Error::InvalidHyperparameter { index: 1, value: -1.0 }));
    let bad_growth = GpConfig { jitter: gp::JitterConfig { growth: 1.0, ..Default::default() }, ..GpConfig::default() };
    assert_eq!(
        ExactGp::fit(x.as_ref(), y.as_ref(), &bad_growth).err(),
        Some(Error::InvalidOption { field: "jitter.growth", value: 1.0, expected: "a finite number above 1" })
    );
}

#[test]
fn a_query_of_the_wrong_dimension_is_refused() {
    let (x, y) = data(11, 10, 2, 1);
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &GpConfig::default()).expect("fit");
    let q = Mat::<f64>::zeros(3, 5);
    assert_eq!(model.predict(q.as_ref()).err(), Some(Error::InputDimensionMismatch { expected: 2, found: 5 }));
}

#[test]
fn standardisation_is_stored_and_applied_at_prediction() {
    // Inputs on wildly different scales; the model must give the same prediction as one fitted on
    // the hand-standardised inputs with standardisation off.
    let (x, y) = data(12, 40, 2, 1);
    let raw = Mat::from_fn(40, 2, |i, j| if j == 0 { 1000.0 + 500.0 * x[(i, 0)] } else { 1e-3 * x[(i, 1)] });
    let model = ExactGp::fit(raw.as_ref(), y.as_ref(), &GpConfig::default()).expect("fit");
    let s = model.input_standardiser().clone();
    let standardised = Mat::from_fn(40, 2, |i, j| (raw[(i, j)] - s.mean[j]) / s.scale[j]);
    let kernel = model.kernel_for_output(0).expect("kernel").clone();
    let off = GpConfig { standardise_inputs: false, ..GpConfig::default() };
    let manual = ExactGp::fit_fixed(standardised.as_ref(), y.as_ref(), &[kernel], &off).expect("fit");
    let q = Mat::from_fn(5, 2, |i, j| raw[(i * 7, j)] * 1.01);
    let qs = Mat::from_fn(5, 2, |i, j| (q[(i, j)] - s.mean[j]) / s.scale[j]);
    let a = model.predict(q.as_ref()).expect("predict");
    let b = manual.predict(qs.as_ref()).expect("predict");
    for i in 0..5 {
        assert!((a.mean[(i, 0)] - b.mean[(i, 0)]).abs() < 1e-10);
        assert!((a.variance[(i, 0)] - b.variance[(i, 0)]).abs() < 1e-10);
    }
}

/// `additive_by_bic`: a one-dimensional short-scale feature (a gear's periodic error along one
/// input) keeps the additive term; a smooth function of all inputs together does not pay its
/// `½ · 2d · ln n` and gets the kernel without it. Either way the report holds both likelihoods.
#[test]
fn the_additive_term_is_kept_only_where_bic_says_it_pays() {
    let n = 160;
    let d = 3;
    let mut r = rng(11);
    let x = uniform_points(&mut r, n, d, -2.0, 2.0);
    let noise = |i: usize| 0.01 * (((i * 37) % 11) as f64 - 5.0);
    let smooth = |i: usize| (0.7 * x[(i, 0)] + 0.4 * x[(i, 1)] - 0.3 * x[(i, 2)]).sin();
    let periodic = Mat::from_fn(n, 1, |i, _| smooth(i) + 0.5 * (12.0 * x[(i, 2)]).sin() + noise(i));
    let plain = Mat::from_fn(n, 1, |i, _| smooth(i) + noise(i));
    let kernel = KernelChoice::Composite {
        shape: StationaryShape::SquaredExponential,
        constant: false,
        linear: false,
        additive: true,
    };
    let config = GpConfig { kernel, additive_by_bic: true, ..GpConfig::default() };
    let choice = |y: &Mat<f64>| {
        let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit");
        let report = &model.report().components[0];
        let c = report.additive_choice.clone().expect("the choice is reported");
        assert!((c.penalty - 0.5 * (2 * d) as f64 * (n as f64).ln()).abs() < 1e-12, "{c:?}");
        assert_eq!(c.kept, c.with_additive - c.without_additive > c.penalty, "{c:?}");
        let has_additive = matches!(&report.kernel, Kernel::Composite(k) if k.additive.is_some());
        assert_eq!(has_additive, c.kept, "{c:?}");
        c
    };
    let periodic_choice = choice(&periodic);
    assert!(periodic_choice.kept, "{periodic_choice:?}");
    let plain_choice = choice(&plain);
    assert!(!plain_choice.kept, "{plain_choice:?}");
    assert_eq!((periodic_choice.rows, plain_choice.rows), (n, n));
    // With a warm-start subset the choice is made on the subset, and only the chosen kernel is
    // searched on all rows.
    let warm =
        GpConfig { optimiser: OptimiserConfig { warm_start_rows: 120, ..config.optimiser.clone() }, ..config.clone() };
    for (y, expect_kept) in [(&periodic, true), (&plain, false)] {
        let model = ExactGp::fit(x.as_ref(), y.as_ref(), &warm).expect("fit");
        let report = &model.report().components[0];
        let c = report.additive_choice.clone().expect("the choice is reported");
        assert_eq!((c.rows, c.kept), (120, expect_kept), "{c:?}");
        assert!((c.penalty - 0.5 * (2 * d) as f64 * 120f64.ln()).abs() < 1e-12, "{c:?}");
        assert_eq!(report.optimisation.as_ref().map(|o| o.warm_start_rows), Some(120));
        assert_eq!(matches!(&report.kernel, Kernel::Composite(k) if k.additive.is_some()), expect_kept);
    }
    let off =
        ExactGp::fit(x.as_ref(), plain.as_ref(), &GpConfig { additive_by_bic: false, ..config.clone() }).expect("fit");
    assert!(off.report().components[0].additive_choice.is_none());
}

/// `refine_max_iterations` bounds the full-data search after a warm-start subset: `Some(0)` keeps
/// the subset's optimum (no evaluation on all rows, the subset stage unchanged), `Some(1)` takes
/// one iteration, and the unbounded search climbs higher on all rows than either.
#[test]
fn refine_budget_bounds_the_full_data_search_after_the_subset() {
    let (x, y) = data(5, 150, 4, 1);
    let fit = |budget: Option<usize>| {
        let optimiser = OptimiserConfig {
            restarts: 0,
            warm_start_rows: 60,
            refine_max_iterations: budget,
            ..OptimiserConfig::default()
        };
        let config = GpConfig {
            kernel: KernelChoice::SquaredExponentialArd,
            optimiser,
            parallelism: Parallelism::Sequential,
            ..GpConfig::default()
        };
        ExactGp::fit(x.as_ref(), y.as_ref(), &config).expect("fit")
    };
    let (kept, one, full) = (fit(Some(0)), fit(Some(1)), fit(None));
    let search = |m: &ExactGp| m.report().components[0].optimisation.clone().expect("optimised");
    let (k, o, f) = (search(&kept), search(&one), search(&full));
    assert_eq!((k.iterations, k.evaluations, k.warm_start_rows), (0, 0, 60), "{k:?}");
    assert_eq!(k.start_log_marginal_likelihoods, f.start_log_marginal_likelihoods, "the subset stage changed");
    assert_eq!(k.warm_start_evaluations, f.warm_start_evaluations);
    assert!(o.iterations <= 1 && o.evaluations >= 1, "{o:?}");
    assert!(f.iterations > 1, "the unbounded search stopped at once: the test cannot tell the budgets apart");
    let (lk, lo, lf) = (kept.log_marginal_likelihood(), one.log_marginal_likelihood(), full.log_marginal_likelihood());
    assert!(lk < lo && lo <= lf, "likelihoods on all rows: kept {lk}, one iteration {lo}, unbounded {lf}");
}
