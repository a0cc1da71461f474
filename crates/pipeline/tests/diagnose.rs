//! `diagnose` on simulated data whose hidden effect it is not told.

use campaign::{
    Effects, GeneratorConfig, Perturbation, Remount, TrackerNoiseModel, joint_ranges, payload_run_campaign, simulate,
    simulate_campaign, simulated_cell,
};
use diagnose::{DiagnoseOptions, Effect, NoiseSource, StructureOptions, diagnose};
use effects::CandidateOptions;
use loadsim::{CouplingFactor, CouplingModel, CouplingTerm, GearPeriodicModel, Harmonic};
use measurements::MeasurementSet;
use robot::RobotDescription;

fn simulated(robot: &RobotDescription, effects: &Effects, full_pose: bool, seed: u64) -> MeasurementSet {
    let cell = simulated_cell(robot, &Perturbation::default(), seed).unwrap();
    let config = GeneratorConfig { sample_count: 250, seed, ..GeneratorConfig::default() };
    let effects = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..effects.clone() };
    simulate(&cell, &effects, &joint_ranges(robot), &config, full_pose).unwrap()
}

/// The robot as the diagnosis gets it: no masses, no stiffness.
fn blind(robot: &RobotDescription) -> RobotDescription {
    RobotDescription { dynamics: None, ..robot.clone() }
}

#[test]
fn a_second_harmonic_on_joint_three_is_named_and_removed_position_only_and_full_pose() {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects {
        gear_periodic: Some(GearPeriodicModel {
            harmonics: vec![Harmonic { joint_index: 2, order: 2.0, amplitude_rad: 2e-4, phase_rad: 0.4 }],
        }),
        ..Effects::default()
    };
    for (seed, full_pose) in [(21, false), (22, true)] {
        let data = simulated(&robot, &effects, full_pose, seed);
        let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
        assert_eq!(d.verdict.effect, Effect::GearPeriodic, "{}", d.summary());
        assert_eq!(d.verdict.joints, vec![3], "{}", d.summary());
        // The series needs the second harmonic; joint 3 spans 125°, less than the 180° period, so
        // no period is resolved, and the size is the harmonic's RMS over the poses (about
        // 0.2 mrad / √2 where the poses cover the range evenly).
        assert!(d.selected[0].harmonic.is_some_and(|h| h >= 2), "{}", d.summary());
        let shape = d.selected[0].shape.as_ref().unwrap();
        assert!(shape.dominant.is_empty() && shape.range_deg < 180.0, "{shape:?}");
        assert!((80.0..200.0).contains(&shape.rms_urad), "{shape:?}");
        assert!(d.heldout_after_mm < 0.5 * d.heldout_before_mm, "{}", d.summary());
        // What is left is the noise: within 25 % of the floor of the tracker the simulation uses.
        assert_eq!(d.noise.source, NoiseSource::TrackerDefault);
        assert!(d.heldout_after_mm < 1.25 * d.noise.floor_mm, "{}", d.summary());
        let json: serde_json::Value = serde_json::from_str(&d.to_json().unwrap()).unwrap();
        assert_eq!(json["verdict"]["effect"], "gear_periodic");
        assert_eq!(json["verdict"]["joints"], serde_json::json!([3]));
        assert_eq!(json["noise"]["source"], "tracker_default");
        assert!(json["heldout_after_selected_mm"].is_number() && json.get("poses").is_none());
        assert!(json["candidates"].as_array().unwrap().len() > 10);
    }
}

#[test]
fn compliance_is_found_without_the_masses() {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects { joint_compliance: Some(loadsim::JointComplianceModel::default()), ..Effects::default() };
    let data = simulated(&robot, &effects, false, 23);
    let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
    assert_eq!(d.verdict.effect, Effect::JointCompliance, "{}", d.summary());
    assert!(d.heldout_after_mm < 0.5 * d.heldout_before_mm, "{}", d.summary());
}

#[test]
fn noise_alone_gives_none() {
    let robot = testkit::robot("irb4400.ron");
    for (seed, full_pose) in [(24, false), (25, true)] {
        let data = simulated(&robot, &Effects::default(), full_pose, seed);
        let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
        assert_eq!(d.verdict.effect, Effect::None, "{}", d.summary());
        assert!(d.selected.is_empty());
        assert!((d.heldout_after_mm - d.heldout_before_mm).abs() < 1e-12);
    }
}

#[test]
fn a_report_has_a_plot_per_joint_and_the_tables() {
    let robot = testkit::robot("irb4400.ron");
    let data = simulated(&robot, &Effects::default(), false, 26);
    let options = DiagnoseOptions {
        structure: StructureOptions { enabled: false, ..StructureOptions::default() },
        noise_mm: Some(0.01),
        ..DiagnoseOptions::default()
    };
    let d = diagnose(&blind(&robot), &data, &options).unwrap();
    let names: Vec<String> = d.error_plots().into_iter().map(|plot| plot.file_name).collect();
    for j in 1..=6 {
        assert!(names.contains(&format!("joint{j}.svg")), "{names:?}");
    }
    assert!(names.contains(&"payload.svg".to_owned()) && names.contains(&"temperature.svg".to_owned()));
    let md = d.markdown(&names);
    assert!(md.contains("## Where") && md.contains("| joint 2 |") && md.contains("![joint1.svg](joint1.svg)"));
    assert_eq!(d.noise.source, NoiseSource::Given);
}

#[test]
fn too_few_rows_are_refused() {
    let robot = testkit::robot("irb4400.ron");
    let data = simulated(&robot, &Effects::default(), false, 27);
    let small = data.subset(&(0..30).collect::<Vec<_>>());
    let error = diagnose(&robot, &small, &DiagnoseOptions::default()).unwrap_err();
    assert!(
        matches!(
            error.kind::<::diagnose::ErrorKind>(),
            Some(::diagnose::ErrorKind::TooFewRows { rows: 30, needed: 50, .. })
        ),
        "{error}"
    );
}

/// A real 7-axis campaign's shape: joints 1 and 2 move, the others sit at 0 within 2 mrad;
/// four payload runs (0, 1.25, 2.5, 5 kg) with the probe remounted for each; full pose; measured
/// torques. Only joint 2 is compliant.
#[test]
fn the_seven_axis_two_moving_joint_campaign_names_compliance_on_joint_two() {
    let robot = testkit::robot("iiwa7.ron");
    let mut soft = robot.clone();
    if let Some(d) = soft.dynamics.as_mut() {
        for (j, k) in d.stiffness_nm_per_rad.iter_mut().enumerate() {
            if j != 1 {
                *k = 1e15;
            }
        }
    }
    let effects = Effects {
        joint_compliance: Some(loadsim::JointComplianceModel::default()),
        tracker_noise: Some(TrackerNoiseModel::default()),
        ..Effects::default()
    };
    for seed in [31, 32] {
        let config = payload_run_campaign(240, seed);
        let (_, data) =
            simulate_campaign(&soft, &effects, &Perturbation::default(), &Remount::default(), &config, true).unwrap();
        let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
        assert_eq!(d.verdict.effect, Effect::JointCompliance, "{}", d.summary());
        assert_eq!(d.verdict.joints, vec![2], "{}", d.summary());
        assert_eq!(d.moving_joints, vec![1, 2], "{}", d.summary());
        assert!(d.heldout_after_mm < 0.3 * d.heldout_before_mm, "{}", d.summary());
        // Regions bin only the joints that move.
        assert!(
            d.regions
                .iter()
                .all(|r| !r.dimension.starts_with("joint") || r.dimension == "joint 1" || r.dimension == "joint 2")
        );
    }
}

/// Joint 3's error depends on the angles of joints 2 and 4 (a coupling no candidate models): the
/// verdict is `unknown`, and it points at joints 2 and 4.
#[test]
fn a_coupling_between_joints_is_unknown_with_the_joints_it_depends_on() {
    let robot = testkit::robot("irb4400.ron");
    let effects = Effects {
        coupling: Some(CouplingModel {
            terms: vec![CouplingTerm {
                joint_index: 2,
                amplitude_rad: 1e-3,
                factors: vec![
                    CouplingFactor { source_joint_index: 1, order: 2.0, phase_rad: 0.3 },
                    CouplingFactor { source_joint_index: 3, order: 1.0, phase_rad: 1.0 },
                ],
            }],
        }),
        ..Effects::default()
    };
    for (seed, full_pose) in [(33, false), (34, true)] {
        let data = simulated(&robot, &effects, full_pose, seed);
        let d = diagnose(&blind(&robot), &data, &DiagnoseOptions::default()).unwrap();
        assert_eq!(d.verdict.effect, Effect::Unknown, "{}", d.summary());
        assert_eq!(d.verdict.joints, vec![2, 4], "{}", d.summary());
        assert_eq!(d.heldout_after_mm, d.heldout_before_mm);
        assert!(d.explainable.as_ref().is_some_and(|gp| gp.significant), "{}", d.summary());
    }
}

/// A prismatic joint (a lifting column) is reported in millimetres, gets no series of
/// its "angle", and a fit asked for one refuses, naming the joint; a revolute joint's series on
/// the same arm is still found.
#[test]
fn a_lifting_column_is_reported_in_millimetres_and_offered_no_series_of_its_angle() {
    let robot = testkit::robot("column_ur10.ron");
    assert_eq!(robot.joints[0].kind, poe::JointKind::Prismatic);
    let periodic = GearPeriodicModel {
        harmonics: vec![Harmonic { joint_index: 2, order: 3.0, amplitude_rad: 4e-4, phase_rad: 0.3 }],
    };
    let data = simulated(&robot, &Effects { gear_periodic: Some(periodic), ..Effects::default() }, false, 5);
    let diagnosis = diagnose(&robot, &data, &DiagnoseOptions::default()).unwrap();
    assert_eq!(diagnosis.prismatic_joints, vec![1]);
    let column: Vec<_> = diagnosis.regions.iter().filter(|r| r.dimension == "joint 1").collect();
    assert!(!column.is_empty() && column.iter().all(|r| r.bin.ends_with("mm")), "{column:?}");
    assert!(
        !diagnosis.candidates.iter().any(|c| c.effect == Effect::GearPeriodic && c.joints == [1]),
        "a series of the column's position was offered"
    );
    assert!(diagnosis.selected.iter().any(|s| s.effect == Effect::GearPeriodic && s.joints == [3]), "{diagnosis:?}");
    let options = pipeline::FitOptions::default().with_effects("gear_periodic:1:3".parse().unwrap());
    let error = pipeline::fit(&robot, &data, model::Method::Poe, &options).unwrap_err();
    assert_eq!(
        error.to_string(),
        "gear_periodic on joint 1: joint 1 is prismatic, and a gear_periodic is a function of a revolute joint's angle \
         (a linear axis's periodic error per screw or rack pitch is screw_periodic:JOINT:PITCH_MM:HARMONICS)"
    );
}

/// The spans below which temperature and time offer no candidate are options: above the data's
/// spans thermal growth and drift are not tried, at the defaults they are, and a negative or NaN
/// threshold is refused.
#[test]
fn thermal_and_drift_are_candidates_only_where_their_input_varies_more_than_the_option() {
    let robot = testkit::robot("irb4400.ron");
    let data = simulated(&robot, &Effects::default(), false, 27);
    let tried = |candidates: CandidateOptions| {
        let options = DiagnoseOptions {
            structure: StructureOptions { enabled: false, ..StructureOptions::default() },
            candidates,
            ..DiagnoseOptions::default()
        };
        let d = diagnose(&blind(&robot), &data, &options).unwrap();
        let has = |effect: Effect| d.candidates.iter().any(|c| c.effect == effect);
        (has(Effect::Thermal), has(Effect::TimeDrift))
    };
    assert_eq!(tried(CandidateOptions::default()), (true, true));
    let never = CandidateOptions { thermal_min_span_k: 1e6, drift_min_offset_s: 1e12 };
    assert_eq!(tried(never), (false, false));
    for bad in [-0.1, f64::NAN] {
        let options = DiagnoseOptions {
            candidates: CandidateOptions { thermal_min_span_k: bad, ..CandidateOptions::default() },
            ..DiagnoseOptions::default()
        };
        let error = diagnose(&blind(&robot), &data, &options).unwrap_err().to_string();
        assert!(error.contains("candidates.thermal_min_span_k"), "{error}");
    }
}
