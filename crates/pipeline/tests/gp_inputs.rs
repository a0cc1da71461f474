//! Measured signals as inputs of the GP (`calib fit --inputs`): learnt beside the
//! joints, kept in the model with their spans, required by name wherever the model is used.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoise, joint_ranges, simulate, simulated_cell};
use errors::ErrorKind;
use lie::{SE3, SO3, Vector3};
use measurements::{Inputs, MeasurementSet, parse_measurements};
use model::{CalibratedModel, Method};
use pipeline::FitOptions;
use rand::{Rng, SeedableRng};
use std::sync::{Arc, OnceLock};

const SIGNAL: &str = "tilt_x_mrad";

/// A perturbed IRB 4400 measured with a tracker's noise, its base turned about the base's x axis
/// by a tilt that changes from pose to pose and has nothing to do with the joints (±0.3 mrad: a
/// platform on a soft floor), read by an inclinometer with 2 µrad of noise into `tilt_x_mrad`.
fn tilted(rows: usize, seed: u64) -> MeasurementSet {
    let robot = testkit::robot("irb4400.ron");
    let cell = simulated_cell(&robot, &Perturbation::default(), seed).unwrap();
    let effects = Effects { tracker_noise: Some(TrackerNoise::default()), ..Effects::default() };
    let config = GeneratorConfig { sample_count: rows, seed, payloads_kg: vec![0.0], ..GeneratorConfig::default() };
    let mut data = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let names: Arc<[String]> = vec![SIGNAL.to_owned()].into();
    for row in &mut data.rows {
        let tilt: f64 = rng.random_range(-3e-4..3e-4);
        let turn = SE3::new(SO3::exp(&Vector3::new(tilt, 0.0, 0.0)), Vector3::zeros());
        let about_base = cell.tracker_from_base * turn * cell.tracker_from_base.inverse();
        row.position = about_base.transform_point(&row.position);
        let read = 1e3 * (tilt + rng.random_range(-2e-6..2e-6));
        row.inputs = Inputs::new(names.clone(), vec![read]);
    }
    data
}

fn with_signal() -> FitOptions {
    let mut options = FitOptions::default();
    options.residual_gp.inputs = vec![SIGNAL.to_owned()];
    options
}

/// The data and the two models, fitted once for every test of the file: 160 training rows, 60
/// held out.
fn fitted() -> &'static (MeasurementSet, MeasurementSet, CalibratedModel, CalibratedModel) {
    static FITTED: OnceLock<(MeasurementSet, MeasurementSet, CalibratedModel, CalibratedModel)> = OnceLock::new();
    FITTED.get_or_init(|| {
        let robot = testkit::robot("irb4400.ron");
        let all = tilted(220, 31);
        let train = all.subset(&(0..160).collect::<Vec<_>>());
        let test = all.subset(&(160..220).collect::<Vec<_>>());
        let (without, _) = pipeline::fit(&robot, &train, Method::PoeGp, &FitOptions::default()).unwrap();
        let (with, _) = pipeline::fit(&robot, &train, Method::PoeGp, &with_signal()).unwrap();
        (train, test, without, with)
    })
}

fn heldout(model: &CalibratedModel, test: &MeasurementSet) -> f64 {
    model::evaluate(model, &model.bind(test).unwrap()).unwrap().summary.mean_position_error_mm
}

#[test]
fn a_signal_the_error_follows_is_learnt_by_the_gp_given_it_as_an_input() {
    let (train, test, without, with) = fitted();
    let (plain, signal) = (heldout(without, test), heldout(with, test));
    eprintln!("held out: poe-gp {plain:.4} mm, poe-gp --inputs {SIGNAL} {signal:.4} mm");
    assert!(signal < 0.5 * plain, "with the signal {signal} mm, without {plain} mm");
    // The model keeps the input's name, unit and span, and says so in its GP part.
    let gp = with.residual_gp.as_ref().unwrap();
    assert_eq!(gp.inputs, [SIGNAL]);
    assert_eq!(gp.gp.input_dim(), 7);
    let span = with.training_range.as_ref().unwrap().input(SIGNAL).expect("the span is kept");
    assert_eq!(span.unit, Some("mrad"));
    let values = train.rows.iter().map(|r| r.inputs.values()[0]);
    let (low, high) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    assert_eq!(span.fitted, [low, high]);
    assert_eq!(with.input_names(), [SIGNAL]);
    assert!(without.input_names().is_empty() && without.residual_gp.as_ref().unwrap().gp.input_dim() == 6);
}

#[test]
fn the_model_file_keeps_the_inputs_and_refuses_a_gp_whose_inputs_do_not_match_them() {
    let (_, test, _, with) = fitted();
    let text = model::model_text(with, "model.ron").unwrap();
    let back = model::parse_model(&text, "model.ron").unwrap();
    assert_eq!(back.input_names(), [SIGNAL]);
    // The file keeps the GP to ~1e-12 mm, not every bit (`calib-python`'s `as_its_file_holds`).
    assert!((heldout(&back, test) - heldout(with, test)).abs() < 1e-9);
    // An edited file whose GP lost its input's name: the GP takes 7 inputs, the file names 6.
    let mut edited = with.clone();
    edited.residual_gp.as_mut().unwrap().inputs.clear();
    let text = model::model_text(&edited, "model.ron").unwrap();
    let error = model::parse_model(&text, "model.ron").unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::ModelCount { what: "inputs", found: 7, expected: 6, .. }), "{error}");
    // One whose training range lost the input's span.
    let mut edited = with.clone();
    edited.training_range.as_mut().unwrap().inputs.clear();
    let text = model::model_text(&edited, "model.ron").unwrap();
    let error = model::parse_model(&text, "model.ron").unwrap_err();
    assert!(error.to_string().contains("no span of the input 'tilt_x_mrad'"), "{error}");
}

#[test]
fn a_file_without_the_models_input_is_refused_by_its_name_and_a_nan_at_its_line_and_column() {
    let (_, test, _, with) = fitted();
    let mut csv = Vec::new();
    test.subset(&[0, 1, 2]).write_csv(&mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    let options = with.read_options(Default::default());
    // Read for the model, the file as written has the column and gives the rows their values.
    let read = parse_measurements(text.as_bytes(), "test.csv", &options).unwrap();
    assert_eq!(read.rows[1].inputs.get(SIGNAL), test.rows[1].inputs.get(SIGNAL));
    assert!(!read.ignored_columns.iter().any(|c| c == SIGNAL));
    // Without the column: refused by name, at the end of the header.
    let header = text.lines().next().unwrap();
    let column = header.split(',').position(|c| c == SIGNAL).unwrap();
    let drop = |line: &str| {
        let mut cells: Vec<&str> = line.split(',').collect();
        cells.remove(column);
        cells.join(",")
    };
    let without: String = text.lines().map(|l| drop(l) + "\n").collect();
    let error = parse_measurements(without.as_bytes(), "test.csv", &options).unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::MissingColumn { name } if name == SIGNAL), "{error}");
    let width = header.split(',').count() - 1;
    assert_eq!(error.position(), Some((1, width + 1)), "{error}");
    // A NaN in it: at its line (an editor's: the header is line 1) and column.
    let nan: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut cells: Vec<String> = l.split(',').map(str::to_owned).collect();
            if i == 2 {
                cells[column] = "NaN".to_owned();
            }
            cells.join(",") + "\n"
        })
        .collect();
    let error = parse_measurements(nan.as_bytes(), "test.csv", &options).unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::NotANumber { name, .. } if name == SIGNAL), "{error}");
    assert_eq!(error.position(), Some((3, column + 1)), "{error}");
    assert!(error.to_string().starts_with(&format!("test.csv:3:{}:", column + 1)), "{error}");
    // Rows made in memory without it are refused by the GP at their line, naming the input.
    let bare = MeasurementSet {
        rows: test.rows.iter().map(|r| measurements::Measurement { inputs: Inputs::default(), ..r.clone() }).collect(),
        ..test.clone()
    };
    let error = with.predict(&with.bind(&bare).unwrap()).unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::MissingInput { name } if name == SIGNAL), "{error}");
    assert_eq!(error.position().map(|p| p.0), Some(test.rows[0].line));
}

#[test]
fn rows_outside_an_inputs_fitted_span_are_counted_and_the_gp_fades_there() {
    let (_, test, _, with) = fitted();
    let span = with.training_range.as_ref().unwrap().input(SIGNAL).unwrap().fitted;
    let names: Arc<[String]> = vec![SIGNAL.to_owned()].into();
    // Ten rows read 20 mrad beyond the span: sixty times its width away (some of the others lie
    // just outside it by chance).
    let outside = |rows: &[measurements::Measurement]| {
        rows.iter().filter(|r| r.inputs.values().iter().any(|v| *v < span[0] || *v > span[1])).count()
    };
    let already = outside(&test.rows[10..]);
    let mut far = test.clone();
    for row in far.rows.iter_mut().take(10) {
        row.inputs = Inputs::new(names.clone(), vec![span[1] + 20.0]);
    }
    let warnings = with.outside_training_range(&far.rows);
    let warning = warnings.iter().find(|w| w.input == SIGNAL).expect("the input is counted");
    assert_eq!((warning.rows_outside, warning.rows, warning.first_line), (10 + already, 60, far.rows[0].line));
    assert_eq!(warning.unit, "mrad");
    assert!(warning.to_string().contains("put tilt_x_mrad outside the range"), "{warning}");
    let faded = with.gp_fade(&far.rows[..10]).unwrap().expect("the GP knows nothing there");
    assert_eq!(faded.rows, 10, "{faded}");
    assert!(with.gp_fade(&test.rows).unwrap().is_none_or(|f| f.rows < 3));
}

#[test]
fn an_input_that_is_the_pose_a_joint_or_the_tool_is_refused_at_its_header_column() {
    let text = "q1_rad,x_mm,y_mm,z_mm,tool,tilt_x_mrad\n0.1,1,2,3,a,0.5\n";
    let refuse = |name: &str| {
        let options = measurements::ReadOptions::default().with_inputs(vec![name.to_owned()]);
        parse_measurements(text.as_bytes(), "cell.csv", &options).unwrap_err()
    };
    for (name, column) in [("q1_rad", 1), ("y_mm", 3), ("tool", 5)] {
        let error = refuse(name);
        assert!(matches!(error.kind(), ErrorKind::NotAnInput { name: n, .. } if n == name), "{error}");
        assert_eq!(error.position(), Some((1, column)), "{error}");
    }
    let options = measurements::ReadOptions::default().with_inputs(vec![SIGNAL.to_owned()]);
    let read = parse_measurements(text.as_bytes(), "cell.csv", &options).unwrap();
    assert_eq!(read.rows[0].inputs.get(SIGNAL), Some(0.5));
    assert!(read.read_summary().contains("inputs: tilt_x_mrad (mrad)"), "{}", read.read_summary());
}
