//! The residual data sets of `cargo xtask bench-gp`: what the geometric model (`poe`) leaves on real
//! and simulated measurements, as the GP stage sees it, so that `gp` and scikit-learn are given the
//! same inputs and outputs; and the held-out error of a GP's prediction on them.

use anyhow::Context;
use std::path::Path;
use std::time::Instant;

use campaign::{GeneratorConfig, Perturbation, Remount, paper_effects, payload_run_campaign, simulate_campaign};
use faer::Mat;
use gp::ExactGp;
use lie::SE3;
use measurements::{MeasurementSet, ReadOptions};
use model::{Method, ResidualFrame, ResidualGpOptions, ResidualSet};
use pipeline::FitOptions;
use robot::RobotDescription;

/// Training and test residuals of one data set.
pub struct Residuals {
    /// Name in the tables.
    pub name: String,
    /// What the GP is trained on.
    pub train: ResidualSet,
    /// Where it is tested.
    pub test: ResidualSet,
    /// The geometric model's poses at the test rows: what a predicted residual corrects.
    pub test_poses: Vec<SE3>,
}

/// The GP stage (`ResidualGpOptions::default()`'s GP) fitted on `set`'s training rows, and the
/// wall seconds of that fit alone.
pub fn fit_timed(set: &Residuals) -> anyhow::Result<(ExactGp, f64)> {
    fit_timed_with(set, &ResidualGpOptions::default().gp).map(|(model, wall, _)| (model, wall))
}

/// [`fit_timed`] with the GP `config`, and the CPU seconds of this process (all threads) during
/// the fit: on a shared machine the CPU time says what the fit costs where the wall clock says
/// how busy the others were.
pub fn fit_timed_with(set: &Residuals, config: &gp::GpConfig) -> anyhow::Result<(ExactGp, f64, f64)> {
    let (t, cpu) = (Instant::now(), super::ur10::process_cpu_seconds());
    let model = ExactGp::fit(set.train.inputs.as_ref(), set.train.outputs.as_ref(), config)
        .with_context(|| set.name.clone())?;
    Ok((model, t.elapsed().as_secs_f64(), super::ur10::process_cpu_seconds() - cpu))
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
) -> anyhow::Result<Residuals> {
    let (model, _) = pipeline::fit(robot, train, Method::Poe, &FitOptions::default())?;
    let poses = |data: &MeasurementSet| -> anyhow::Result<Vec<SE3>> { Ok(model.geometric_poses(&model.bind(data)?)?) };
    let set =
        |poses: &[SE3], data: &MeasurementSet| ResidualSet::new(poses, data, with_payload, ResidualFrame::ToolPoint);
    let test_poses = poses(test)?;
    Ok(Residuals { name, train: set(&poses(train)?, train), test: set(&test_poses, test), test_poses })
}

/// A real data set from a SPEC CSV, split into even (train) and odd (test) rows, or from two files.
pub fn real(name: &str, robot: &RobotDescription, train: &Path, test: Option<&Path>) -> anyhow::Result<Residuals> {
    let options = ReadOptions::for_joints(robot.joint_kinds());
    let read = |p: &Path| measurements::read_measurements(p, &options).map_err(anyhow::Error::from);
    let (train_set, test_set) = match test {
        Some(t) => (read(train)?, read(t)?),
        None => even_odd(&read(train)?),
    };
    residuals(name.to_owned(), robot, &train_set, &test_set, false)
}

/// A simulated campaign with the paper's effects (joint compliance under gravity and payload,
/// tracker noise) and payloads: the first `train` poses to train on, the next `test` to test.
pub fn simulated(robot: &RobotDescription, seed: u64, train: usize, test: usize) -> anyhow::Result<Residuals> {
    simulated_campaign(robot, &paper_effects(), "", seed, train, test, false)
}

/// [`simulated`] with `effects`, position only or full pose: with [`paper_effects`] the rows
/// `calib simulate --rows TRAIN+TEST --seed SEED [--full-pose]` writes, the first `train` to train
/// on and the rest to test. `label` goes into the name after the robot's.
pub fn simulated_campaign(
    robot: &RobotDescription,
    effects: &loadsim::Effects,
    label: &str,
    seed: u64,
    train: usize,
    test: usize,
    full_pose: bool,
) -> anyhow::Result<Residuals> {
    let config = GeneratorConfig { sample_count: train + test, seed, ..GeneratorConfig::default() };
    let (_, data) =
        simulate_campaign(robot, effects, &Perturbation::default(), &Remount::default(), &config, full_pose)?;
    let train_set = data.subset(&(0..train).collect::<Vec<_>>());
    let test_set = data.subset(&(train..train + test).collect::<Vec<_>>());
    let kind = if full_pose { ", full pose" } else { "" };
    let name = format!("simulated {}{label}, seed {seed}, {train} poses{kind}", robot.name);
    residuals(name, robot, &train_set, &test_set, true)
}

/// A simulated arm without payload as an input: `calib simulate --robot ROBOT --payloads 0
/// --rows TRAIN+TEST --seed SEED` with the paper's effects (joint compliance under the arm's own
/// weight, tracker noise), the first `train` poses to train on and the rest to test; the GP takes
/// the joints alone, as `poe-gp` fits it. On the column arm (`column_arm.urdf`: a prismatic column
/// in metres beside six revolute joints) these are the mixed-unit inputs of a construction robot.
pub fn simulated_without_payload(
    robot: &RobotDescription,
    seed: u64,
    train: usize,
    test: usize,
) -> anyhow::Result<Residuals> {
    let config =
        GeneratorConfig { sample_count: train + test, seed, payloads_kg: vec![0.0], ..GeneratorConfig::default() };
    let (_, data) =
        simulate_campaign(robot, &paper_effects(), &Perturbation::default(), &Remount::default(), &config, false)?;
    let train_set = data.subset(&(0..train).collect::<Vec<_>>());
    let test_set = data.subset(&(train..train + test).collect::<Vec<_>>());
    let name = format!("simulated {}, seed {seed}, {train} poses", robot.name);
    residuals(name, robot, &train_set, &test_set, false)
}

/// The shape of a real 7-axis campaign ([`payload_run_campaign`]: joints 1 and 2 moving, four
/// payload runs with a tool each) with the paper's effects: `train + test` poses, every run in both
/// sets (the training rows spread evenly over the campaign), so that no payload is seen only at
/// test time.
pub fn simulated_payload_runs(
    robot: &RobotDescription,
    seed: u64,
    train: usize,
    test: usize,
) -> anyhow::Result<Residuals> {
    let total = train + test;
    let config = payload_run_campaign(total, seed);
    let (_, data) =
        simulate_campaign(robot, &paper_effects(), &Perturbation::default(), &Remount::default(), &config, false)?;
    // Row i is a training row when ⌊(i + 1)·train/total⌋ > ⌊i·train/total⌋: `train` rows spread
    // evenly over the campaign.
    let is_train = |i: usize| (i + 1) * train / total > i * train / total;
    let train_rows: Vec<usize> = (0..total).filter(|&i| is_train(i)).collect();
    let test_rows: Vec<usize> = (0..total).filter(|&i| !is_train(i)).collect();
    residuals(
        format!("simulated {} payload runs, seed {seed}, {train} poses", robot.name),
        robot,
        &data.subset(&train_rows),
        &data.subset(&test_rows),
        true,
    )
}

/// Mean position error (mm) after correcting the test residuals by the predicted means: the
/// held-out error `calib eval` reports for position-only data.
pub fn heldout_mm(mean: &Mat<f64>, test: &ResidualSet) -> f64 {
    let y = &test.outputs;
    let n = y.nrows();
    let total: f64 = (0..n).map(|i| (0..3).map(|c| (y[(i, c)] - mean[(i, c)]).powi(2)).sum::<f64>().sqrt()).sum();
    1e3 * total / n.max(1) as f64
}

/// Writes every set as `DIR/NAME.train.csv` and `DIR/NAME.test.csv` (name made file-safe): columns
/// `x0 … x{d−1}`, then `y0 … y{m−1}`, full precision.
pub fn dump(sets: &[Residuals], dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
    for set in sets {
        let stem: String = set.name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
        for (part, r) in [("train", &set.train), ("test", &set.test)] {
            let (d, m) = (r.inputs.ncols(), r.outputs.ncols());
            let mut text =
                (0..d).map(|j| format!("x{j}")).chain((0..m).map(|j| format!("y{j}"))).collect::<Vec<_>>().join(",");
            text.push('\n');
            for i in 0..r.inputs.nrows() {
                let row: Vec<String> = (0..d)
                    .map(|j| format!("{:e}", r.inputs[(i, j)]))
                    .chain((0..m).map(|j| format!("{:e}", r.outputs[(i, j)])))
                    .collect();
                text.push_str(&row.join(","));
                text.push('\n');
            }
            let path = dir.join(format!("{stem}.{part}.csv"));
            std::fs::write(&path, text).with_context(|| path.display().to_string())?;
            eprintln!("{}", path.display());
        }
    }
    Ok(())
}
