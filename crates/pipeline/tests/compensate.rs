//! Compensated joint targets: the calibrated model (geometry, effects and GP, with the payload)
//! reaches what each row means; every refusal says why, and the targets file's refusals name the
//! file, line and column.

use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoiseModel};
use cell::{CompensateOptions, InverseOptions, PoseTarget, TargetFrame, TargetStatus};
use errors::Error;
use lie::{SE3, Vector3};
use measurements::{ColumnMap, MeasurementSet};
use model::{CalibratedModel, Method};
use pipeline::FitOptions;
use robot::RobotDescription;
use std::path::{Path, PathBuf};

fn fitted(
    method: Method,
    effects: Effects,
    full_pose: bool,
    payloads: Vec<f64>,
) -> (RobotDescription, CalibratedModel, MeasurementSet) {
    let irb = testkit::robot("irb4400.ron");
    let cell = campaign::simulated_cell(&irb, &Perturbation::default(), 21).unwrap();
    let config = GeneratorConfig { sample_count: 160, seed: 21, payloads_kg: payloads, ..GeneratorConfig::default() };
    let set = campaign::simulate(&cell, &effects, &campaign::joint_ranges(&irb), &config, full_pose).unwrap();
    let (model, _) = pipeline::fit(&irb, &set, method, &FitOptions::default()).unwrap();
    (irb, model, set)
}

fn noise_only() -> Effects {
    Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..Effects::default() }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn predicted(model: &CalibratedModel, q: &[f64], payload_kg: f64) -> SE3 {
    let row = measurements::Measurement { payload_kg, ..measurements::Measurement::at(q.to_vec(), Vector3::zeros()) };
    model.predict(&measurements::BoundSet::made_for_model("a pose", vec![row])).unwrap()[0].pose
}

const PROGRAM: &str = "q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,payload_kg,speed,tool\n\
                       10,20,-10,30,40,50,0,v100,\n\
                       -40,5,15,-60,-35,10,0,v200,\n\
                       80,-30,40,100,70,-150,0,fine,\n";

#[test]
fn a_program_taught_on_the_nominal_model_is_rewritten_to_reach_its_poses() {
    let (irb, model, _) = fitted(Method::Poe, noise_only(), true, vec![0.0]);
    let dir = tempfile::tempdir().unwrap();
    let file = cell::read_targets(&write(dir.path(), "program.csv", PROGRAM), &model, ColumnMap::default()).unwrap();
    let options = CompensateOptions::default();
    let (targets, registered) =
        cell::pose_targets(&model, &file, Some((&irb, "irb4400.ron")), TargetFrame::Tracker, &options).unwrap();
    let registered = registered.unwrap();
    assert!(registered.rms_m > 1e-4 && registered.rms_m < 5e-3, "{}", registered.rms_m);
    let (solved, summary) =
        cell::compensate(&model, &file, Some((&irb, "irb4400.ron")), TargetFrame::Tracker, &options).unwrap();
    assert_eq!((summary.rows, summary.ok), (3, 3), "{summary:?}");
    assert!(summary.before_mean_mm > 0.1, "{summary:?}");
    for ((solved, target), row) in solved.iter().zip(&targets).zip(&file.set.rows) {
        assert!(solved.status.is_ok(), "{}", solved.status);
        let reached = predicted(&model, &solved.q, 0.0);
        assert!((reached.translation() - target.pose.translation()).norm() < 1e-9);
        assert!((reached.rotation() * target.pose.rotation().inverse()).log().norm() < 1e-9);
        assert!(solved.residual_m < 1e-9 && solved.residual_rad.unwrap() < 1e-9, "{solved:?}");
        // A calibration moves joints by milliradians, not more.
        let moved = solved.q.iter().zip(&row.q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(moved > 1e-5 && moved < 0.02, "{moved}");
        assert!(solved.iterations <= 6, "{}", solved.iterations);
    }
    // The CSV: compensated joints first, the input columns as written, then the residuals.
    let mut csv = Vec::new();
    cell::write_compensated(&mut csv, &file, &solved).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,nominal_q1_deg,nominal_q2_deg,nominal_q3_deg,nominal_q4_deg,\
         nominal_q5_deg,nominal_q6_deg,payload_kg,speed,tool,residual_mm,residual_mrad,status,line"
    );
    let first: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&first[6..15], ["10", "20", "-10", "30", "40", "50", "0", "v100", ""]);
    assert_eq!((first[15], first[16], first[17]), ("0.000000", "0.000000", "ok"));
    assert!((first[0].parse::<f64>().unwrap() - 10f64.to_radians()).abs() < 0.02);
}

#[test]
fn pose_targets_from_a_seed_are_reached_on_the_seeds_branch() {
    let (_, model, _) = fitted(Method::Poe, noise_only(), true, vec![0.0]);
    let q = [0.3, 0.2, -0.1, 0.8, 0.9, -0.4];
    let pose = predicted(&model, &q, 0.0);
    let seed: Vec<f64> = q.iter().map(|v| v + 0.15).collect();
    let targets = [
        PoseTarget {
            seed: seed.clone(),
            pose,
            orientation: true,
            payload_kg: 0.0,
            tool: 0,
            inputs: Default::default(),
        },
        PoseTarget { seed, pose, orientation: false, payload_kg: 0.0, tool: 0, inputs: Default::default() },
    ];
    let solved = cell::solve_targets(&model, &targets, None, &InverseOptions::default()).unwrap();
    assert!(solved[0].status.is_ok(), "{}", solved[0].status);
    let off = solved[0].q.iter().zip(&q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(off < 1e-8, "{off}");
    assert!(solved[1].status.is_ok() && solved[1].residual_rad.is_none(), "{:?}", solved[1]);
    assert!((predicted(&model, &solved[1].q, 0.0).translation() - pose.translation()).norm() < 1e-9);
}

#[test]
fn a_gp_model_with_payload_is_compensated_through_its_whole_prediction() {
    let (_, model, _) = fitted(Method::PoeGpLoad, campaign::paper_effects(), false, vec![0.0, 5.0, 10.0]);
    assert!(model.residual_gp.is_some());
    let q = vec![0.2, 0.4, -0.2, 0.5, 0.7, 0.1];
    let pose = predicted(&model, &q, 0.0);
    let targets: Vec<PoseTarget> = [0.0, 10.0]
        .iter()
        .map(|&payload_kg| PoseTarget {
            seed: q.clone(),
            pose,
            orientation: false,
            payload_kg,
            tool: 0,
            inputs: Default::default(),
        })
        .collect();
    let solved = cell::solve_targets(&model, &targets, None, &InverseOptions::default()).unwrap();
    for (s, t) in solved.iter().zip(&targets) {
        assert!(s.status.is_ok(), "{}", s.status);
        assert!((predicted(&model, &s.q, t.payload_kg).translation() - pose.translation()).norm() < 1e-9);
    }
    let apart = solved[0].q.iter().zip(&solved[1].q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(apart > 1e-5, "the payload changed nothing: {apart}");
}

#[test]
fn rows_that_cannot_be_compensated_say_why() {
    let (irb, model, _) = fitted(Method::Poe, noise_only(), true, vec![0.0]);
    let q = vec![0.3, 0.2, -0.1, 0.8, 0.9, -0.4];
    let pose = predicted(&model, &q, 0.0);
    let far = SE3::from_translation(Vector3::new(10.0, 0.0, 0.0)) * pose;
    let singular_q = vec![0.3, 0.2, -0.1, 0.8, 0.0, -0.4];
    let targets = [
        PoseTarget {
            seed: q.clone(),
            pose: far,
            orientation: true,
            payload_kg: 0.0,
            tool: 0,
            inputs: Default::default(),
        },
        PoseTarget {
            seed: singular_q.clone(),
            pose: predicted(&model, &singular_q, 0.0),
            orientation: true,
            payload_kg: 0.0,
            tool: 0,
            inputs: Default::default(),
        },
        PoseTarget { seed: q.clone(), pose, orientation: true, payload_kg: 0.0, tool: 0, inputs: Default::default() },
    ];
    let mut limits = irb.limits();
    limits[3].1 = 0.5;
    let solved = cell::solve_targets(&model, &targets, Some(&limits), &InverseOptions::default()).unwrap();
    assert!(matches!(solved[0].status, TargetStatus::NoConvergence { iterations: 30, .. }), "{}", solved[0].status);
    assert!(solved[0].status.to_string().starts_with("no convergence: "), "{}", solved[0].status);
    assert!(matches!(solved[1].status, TargetStatus::Singular { .. }), "{}", solved[1].status);
    assert!(solved[1].status.to_string().starts_with("singular: "), "{}", solved[1].status);
    assert_eq!(
        solved[2].status.to_string(),
        format!(
            "outside limits: joint 4 at {:.3} deg, limits -200.000 to {:.3} deg",
            solved[2].q[3].to_degrees(),
            0.5f64.to_degrees()
        )
    );
}

#[test]
fn the_tool_jacobian_is_the_derivative_of_the_models_pose() {
    let (_, model, _) = fitted(Method::Poe, noise_only(), true, vec![0.0]);
    let q = [0.3, 0.2, -0.1, 0.8, 0.9, -0.4];
    let jacobian = loadsim::tool_point_jacobian(&model.kinematics, &q, 0).unwrap();
    let pose = predicted(&model, &q, 0.0);
    let h = 1e-6;
    for j in 0..6 {
        let mut moved = q;
        moved[j] += h;
        let next = predicted(&model, &moved, 0.0);
        let point = (next.translation() - pose.translation()) / h;
        let rotation = (next.rotation() * pose.rotation().inverse()).log() / h;
        for r in 0..3 {
            assert!((jacobian[(r, j)] - point[r]).abs() < 1e-5, "joint {j} row {r}");
            assert!((jacobian[(r + 3, j)] - rotation[r]).abs() < 1e-5, "joint {j} row {}", r + 3);
        }
    }
}

fn refusal(result: Result<impl std::fmt::Debug, Error>) -> String {
    match result {
        Err(e) => e.to_string(),
        Ok(v) => panic!("expected a refusal, got {v:?}"),
    }
}

#[test]
fn targets_files_that_cannot_be_compensated_are_refused_at_their_place() {
    let (irb, model, _) = fitted(Method::Poe, noise_only(), false, vec![0.0]);
    let dir = tempfile::tempdir().unwrap();
    let read =
        |name: &str, text: &str| cell::read_targets(&write(dir.path(), name, text), &model, ColumnMap::default());
    let message = refusal(read("nojoints.csv", "x_mm,y_mm,z_mm\n1,2,3\n"));
    assert!(message.contains("nojoints.csv:1:4: 0 joint columns, the robot has 6 joints"), "{message}");
    let header = "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad";
    let message = refusal(read(
        "orientation.csv",
        &format!("{header},x_mm,y_mm,z_mm,qw,qx,qy,qz\n0,0,0,0,0.5,0,1,2,3,1,0,0,0\n"),
    ));
    assert!(message.contains("orientation.csv:1:10: the model was fitted on positions only"), "{message}");
    let message = refusal(read("alone.csv", &format!("{header},qw,qx,qy,qz\n0,0,0,0,0.5,0,1,0,0,0\n")));
    assert!(message.contains("alone.csv:1:7: an orientation without x_mm"), "{message}");

    let joints = read("joints.csv", &format!("{header}\n0.1,0.2,0.1,0.3,0.5,0.2\n")).unwrap();
    let options = CompensateOptions::default();
    let message = refusal(cell::compensate(&model, &joints, None, TargetFrame::Tracker, &options));
    assert!(message.contains("joints.csv:1:1: joint targets are a program taught on the nominal model"), "{message}");
    let message = refusal(cell::compensate(
        &model,
        &joints,
        Some((&testkit::robot("ur10.ron"), "ur10.ron")),
        TargetFrame::Tracker,
        &options,
    ));
    assert!(message.starts_with("ur10.ron: this robot, placed on the model by base and tool, stays"), "{message}");
    let poses = read("poses.csv", &format!("{header},x_mm,y_mm,z_mm\n0.1,0.2,0.1,0.3,0.5,0.2,1000,0,1500\n")).unwrap();
    let message = refusal(cell::compensate(&model, &poses, None, TargetFrame::Base, &options));
    assert!(message.contains("poses.csv:1:1: poses in the base frame need the robot description"), "{message}");
    let (solved, _) =
        cell::compensate(&model, &poses, Some((&irb, "irb4400.ron")), TargetFrame::Base, &options).unwrap();
    assert_eq!(solved.len(), 1);
}

/// A prismatic joint's compensated value is in metres and its column says so (`qK_m`), so that
/// the output reads back as a targets file (it was written `q1_rad`, which the reader refuses on
/// a prismatic joint).
#[test]
fn a_prismatic_joints_compensated_column_is_in_metres_and_reads_back() {
    let robot = testkit::robot("column_ur10.ron");
    let cell = campaign::simulated_cell(&robot, &Perturbation::default(), 23).unwrap();
    let config = GeneratorConfig { sample_count: 120, seed: 23, ..GeneratorConfig::default() };
    let set = campaign::simulate(&cell, &noise_only(), &campaign::joint_ranges(&robot), &config, true).unwrap();
    let (model, _) = pipeline::fit(&robot, &set, Method::Poe, &FitOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let program = "q1_mm,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,q7_deg\n300,10,-60,40,-30,40,20\n";
    let file = cell::read_targets(&write(dir.path(), "program.csv", program), &model, ColumnMap::default()).unwrap();
    let (solved, summary) = cell::compensate(
        &model,
        &file,
        Some((&robot, "column_ur10.ron")),
        TargetFrame::Tracker,
        &CompensateOptions::default(),
    )
    .unwrap();
    assert_eq!((summary.rows, summary.ok), (1, 1), "{summary:?}");
    let mut csv = Vec::new();
    cell::write_compensated(&mut csv, &file, &solved).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    assert!(csv.starts_with("q1_m,q2_rad,"), "{csv}");
    let q1: f64 = csv.lines().nth(1).unwrap().split(',').next().unwrap().parse().unwrap();
    assert!((q1 - 0.3).abs() < 0.01, "{q1} m");
    let back = cell::read_targets(&write(dir.path(), "out.csv", &csv), &model, ColumnMap::default()).unwrap();
    assert!((back.set.rows[0].q[0] - q1).abs() < 1e-12);
}
