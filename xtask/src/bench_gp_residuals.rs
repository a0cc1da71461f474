//! The residual data sets of `cargo xtask bench-gp`: what the geometric model (`poe`) leaves on real
//! and simulated measurements, as the GP stage sees it, so that `gp` and scikit-learn are given the
//! same inputs and outputs; and the held-out error of a GP's prediction on them.

use std::path::Path;

use faer::Mat;
use pipeline::simulated::{GeneratorConfig, Perturbation, Remount, paper_effects, simulate_campaign};
use pipeline::{FitOptions, MeasurementSet, Method, ReadOptions, ResidualFrame, ResidualSet, RobotDescription};

/// Training and test residuals of one data set.
pub struct Residuals {
    /// Name in the tables.
    pub name: String,
    /// What the GP is trained on.
    pub train: ResidualSet,
    /// Where it is tested.
    pub test: ResidualSet,
}

/// Rows `0, 2, 4, …` and `1, 3, 5, …`.
fn even_odd(set: &MeasurementSet) -> (MeasurementSet, MeasurementSet) {
    let even: Vec<usize> = (0..set.rows.len()).step_by(2).collect();
    let odd: Vec<usize> = (1..set.rows.len()).step_by(2).collect();
    (set.subset(&even), set.subset(&odd))
}

/// Fits `poe` on `train` and returns the residuals it leaves on both sets.
pub fn residuals(
    name: String,
    robot: &RobotDescription,
    train: &MeasurementSet,
    test: &MeasurementSet,
    with_payload: bool,
) -> Result<Residuals, String> {
    let (model, _) = pipeline::fit(robot, train, Method::Poe, &FitOptions::default()).map_err(|e| e.to_string())?;
    let set = |data: &MeasurementSet| -> Result<ResidualSet, String> {
        let tools = pipeline::tool_indices(&model, data).map_err(|e| e.to_string())?;
        let poses = model.geometric_poses(&data.rows, &tools).map_err(|e| e.to_string())?;
        Ok(ResidualSet::new(&poses, data, with_payload, ResidualFrame::ToolPoint))
    };
    Ok(Residuals { name, train: set(train)?, test: set(test)? })
}

/// A real data set from a SPEC CSV, split into even (train) and odd (test) rows, or from two files.
pub fn real(name: &str, robot: &RobotDescription, train: &Path, test: Option<&Path>) -> Result<Residuals, String> {
    let options = ReadOptions::for_joints(robot.joint_kinds());
    let read = |p: &Path| pipeline::read_measurements(p, &options).map_err(|e| e.to_string());
    let (train_set, test_set) = match test {
        Some(t) => (read(train)?, read(t)?),
        None => even_odd(&read(train)?),
    };
    residuals(name.to_owned(), robot, &train_set, &test_set, false)
}

/// A simulated campaign with the paper's effects (joint compliance under gravity and payload,
/// tracker noise) and payloads: the first `train` poses to train on, the next `test` to test.
pub fn simulated(robot: &RobotDescription, seed: u64, train: usize, test: usize) -> Result<Residuals, String> {
    let config = GeneratorConfig { sample_count: train + test, seed, ..GeneratorConfig::default() };
    let (_, data) =
        simulate_campaign(robot, &paper_effects(), &Perturbation::default(), &Remount::default(), &config, false)
            .map_err(|e| e.to_string())?;
    let train_set = data.subset(&(0..train).collect::<Vec<_>>());
    let test_set = data.subset(&(train..train + test).collect::<Vec<_>>());
    residuals(format!("simulated {}, seed {seed}, {train} poses", robot.name), robot, &train_set, &test_set, true)
}

/// Mean position error (mm) after correcting the test residuals by the predicted means: the
/// held-out error `calib eval` reports for position-only data.
pub fn heldout_mm(mean: &Mat<f64>, test: &ResidualSet) -> f64 {
    let y = &test.outputs;
    let n = y.nrows();
    let total: f64 = (0..n).map(|i| (0..3).map(|c| (y[(i, c)] - mean[(i, c)]).powi(2)).sum::<f64>().sqrt()).sum();
    1e3 * total / n.max(1) as f64
}
