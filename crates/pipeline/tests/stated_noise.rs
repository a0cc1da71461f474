//! The tracker's stated uncertainty of each row: read from `std_x_mm` … `std_rz_mrad`,
//! kept by the writer, weighting the identification, naming a row stated far above the rest, and
//! setting the diagnosis's noise floor.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoise, joint_ranges, simulate, simulated_cell};
use errors::ErrorKind;
use measurements::{MeasurementSet, ReadOptions, StatedSigma, parse_measurements};
use model::Method;
use pipeline::{FitOptions, FitWarning};
use rand::{Rng, SeedableRng};

#[test]
fn stated_uncertainties_are_read_written_and_refused_where_partial_or_not_positive() {
    let text = "q1_rad,x_mm,y_mm,z_mm,std_x_mm,std_y_mm,std_z_mm,std_rx_mrad,std_ry_mrad,std_rz_mrad\n\
                0.1,1,2,3,0.01,0.02,0.03,0.1,0.2,0.3\n";
    let set = parse_measurements(text.as_bytes(), "t.csv", &ReadOptions::default()).unwrap();
    let std = set.rows[0].std.expect("stated");
    let p = std.position_m.unwrap();
    assert!((p[1] - 2e-5).abs() < 1e-18 && (std.rotation_rad.unwrap()[2] - 3e-4).abs() < 1e-18, "{std:?}");
    assert!(set.ignored_columns.is_empty(), "{:?}", set.ignored_columns);
    assert!(set.read_summary().contains("stated uncertainty"), "{}", set.read_summary());
    // Written and read back.
    let mut csv = Vec::new();
    set.write_csv(&mut csv).unwrap();
    let back = parse_measurements(csv.as_slice(), "back.csv", &ReadOptions::default()).unwrap();
    let b = back.rows[0].std.unwrap();
    for (x, y) in
        b.position_m.unwrap().iter().chain(&b.rotation_rad.unwrap()).zip(p.iter().chain(&std.rotation_rad.unwrap()))
    {
        assert!((x - y).abs() <= 1e-15 * y.abs(), "{x} {y}");
    }
    // Two axes of three: refused by the missing one's name, at the end of the header.
    let partial = "q1_rad,x_mm,y_mm,z_mm,std_x_mm,std_z_mm\n0.1,1,2,3,0.01,0.03\n";
    let error = parse_measurements(partial.as_bytes(), "t.csv", &ReadOptions::default()).unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::MissingColumn { name } if name == "std_y_mm"), "{error}");
    assert_eq!(error.position(), Some((1, 7)));
    // A zero σ: at its line and column.
    let zero = "q1_rad,x_mm,y_mm,z_mm,std_x_mm,std_y_mm,std_z_mm\n0.1,1,2,3,0.01,0.02,0.03\n0.2,1,2,3,0.01,0,0.03\n";
    let error = parse_measurements(zero.as_bytes(), "t.csv", &ReadOptions::default()).unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::NotAStandardDeviation { name, .. } if name == "std_y_mm"), "{error}");
    assert!(error.to_string().starts_with("t.csv:3:6: std_y_mm is 0"), "{error}");
    // A stated σ is not an input of the model.
    let options = ReadOptions::default().with_inputs(vec!["std_x_mm".into()]);
    let error = parse_measurements(text.as_bytes(), "t.csv", &options).unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::NotAnInput { .. }) && error.position() == Some((1, 5)), "{error}");
}

/// A perturbed IRB 4400 measured by a tracker whose noise is 5 µm on most rows, 25 µm on every
/// fourth (a reflector seen at a grazing angle) and 0.3 mm on every eighth (one half occluded),
/// each row stating its own σ; the rows from `noisy` on are measured without noise (held out: the
/// model's own error shows there).
fn mixed_noise(rows: usize, noisy: usize, seed: u64) -> MeasurementSet {
    let robot = testkit::robot("irb4400.ron");
    let cell = simulated_cell(&robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: rows, seed, payloads_kg: vec![0.0], ..GeneratorConfig::default() };
    let quiet = Effects {
        tracker_noise: Some(TrackerNoise {
            radial_sigma_m: 0.0,
            transverse_sigma_m: 0.0,
            transverse_sigma_per_m: 0.0,
            orientation_sigma_rad: 0.0,
        }),
        ..Effects::default()
    };
    let mut data = simulate(&cell, &quiet, &joint_ranges(&robot), &config, false).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for (i, row) in data.rows.iter_mut().enumerate() {
        let sigma = match i {
            _ if i % 8 == 0 => 3e-4,
            _ if i % 4 == 1 => 2.5e-5,
            _ => 5e-6,
        };
        for c in 0..3 {
            // Box–Muller.
            let (u, v): (f64, f64) = (rng.random_range(f64::MIN_POSITIVE..1.0), rng.random_range(0.0..1.0));
            if i < noisy {
                row.position[c] += sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos();
            }
        }
        row.std = Some(StatedSigma { position_m: Some([sigma; 3]), rotation_rad: None });
    }
    data
}

#[test]
fn rows_are_weighted_by_their_stated_uncertainty_and_one_stated_far_above_the_rest_is_named() {
    let robot = testkit::robot("irb4400.ron");
    let all = mixed_noise(200, 140, 41);
    let train = all.subset(&(0..140).collect::<Vec<_>>());
    let test = all.subset(&(140..200).collect::<Vec<_>>());
    let fitted = |options: &FitOptions| {
        let (model, report) = pipeline::fit(&robot, &train, Method::Poe, options).unwrap();
        (model::evaluate(&model, &model.bind(&test).unwrap()).unwrap().summary.mean_position_error_mm, report)
    };
    let (weighted, report) = fitted(&FitOptions::default());
    let mut off = FitOptions::default();
    off.identification.stated_noise.weight = false;
    let (plain, plain_report) = fitted(&off);
    eprintln!("held out, noise-free: weighted {weighted:.5} mm, unweighted {plain:.5} mm");
    assert!(weighted < 0.7 * plain, "weighted {weighted} mm, unweighted {plain} mm");
    let stated = report.identification.stated_noise.as_ref().expect("the rows state their σ");
    assert_eq!(stated.stated, 140);
    // Noise alone: no scatter beyond the stated σ worth a tenth of the median's.
    assert!(stated.excess_position_m < 0.5e-6, "{}", stated.excess_position_m);
    assert!(plain_report.identification.stated_noise.is_none());
    // Sixty times the median: the 18 rows named by line, not weighted to nothing unnoticed.
    let named = report.warnings.iter().find_map(|w| match w {
        FitWarning::StatedUncertaintyFarAbove { rows, far_above_median } => Some((rows.clone(), *far_above_median)),
        _ => None,
    });
    let (rows, limit) = named.expect("the noisy rows are named");
    assert_eq!((rows.len(), limit), (18, 10.0));
    assert!(rows.iter().all(|(line, ratio)| (line - 2) % 8 == 0 && *ratio > 50.0), "{rows:?}");
    // Told that sixty times is within reason, the fit names none.
    let mut lenient = FitOptions::default();
    lenient.identification.stated_noise.far_above_median = 100.0;
    let (_, report) = fitted(&lenient);
    assert!(!report.warnings.iter().any(|w| matches!(w, FitWarning::StatedUncertaintyFarAbove { .. })));
}

#[test]
fn the_diagnosis_takes_its_noise_floor_from_the_stated_uncertainty() {
    let robot = testkit::robot("irb4400.ron");
    let data = mixed_noise(120, 120, 43);
    let diagnosis = diagnose::diagnose(&robot, &data, &diagnose::DiagnoseOptions::default()).unwrap();
    assert_eq!(diagnosis.noise.source, diagnose::NoiseSource::Stated);
    // √((15 · 0.3² + 30 · 0.025² + 75 · 0.005²) / 120) mm per axis.
    let expected = ((15.0 * 0.3f64.powi(2) + 30.0 * 0.025f64.powi(2) + 75.0 * 0.005f64.powi(2)) / 120.0).sqrt();
    assert!((diagnosis.noise.sigma_mm - expected).abs() < 1e-9, "{} against {expected}", diagnosis.noise.sigma_mm);
}
