//! `cargo xtask bench-gp --paper`: the GP stage against scikit-learn on the paper's own setting
//! and on the real UR10, same residuals, same run.
//!
//! - Simulated campaigns of the paper's shape (`calib simulate --robot irb4400.ron --rows 600
//!   --seed S [--full-pose]`: joint compliance under the arm's weight and the payload, payloads
//!   1–7.5 kg, tracker noise; the first 300 poses to train on, the other 300 to test), and the
//!   same with reproduce-sim's paper-like preset (joints ten times softer, loaded by the payload
//!   alone), position only and full pose, one row per seed: the GP
//!   stage of `poe-gp-load` against scikit-learn's `C·RBF + C + DotProduct + White` (the paper's
//!   isotropic Eq. 5, standardised inputs, 2 restarts) on the position outputs.
//! - A simulated column arm (`column_arm.urdf`: a prismatic column in metres beside six revolute
//!   joints, the paper's effects without payload), 200 poses to train on and 200 to test, one row
//!   per seed: the GP stage of `poe-gp` (seven inputs of mixed units) against scikit-learn's ARD
//!   GP (`C·RBF(ARD) + C + White`, 3 restarts).
//! - The real UR10, series C, even rows → odd rows, position only and full pose: the GP stage of
//!   `poe-gp` against scikit-learn's ARD GP (`C·RBF(ARD) + C + White`, 3 restarts) on the three
//!   position outputs.
//!
//! Held-out error is the mean position error (mm) after the correction; the GP's closed-form
//! leave-one-out error on its training rows is shown beside it. Times are the GP fit alone, wall
//! clock, on the same residuals.

use anyhow::Context;
use model::ResidualGpOptions;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Duration;

use faer::Mat;
use gp::{ExactGp, Kernel};
use robot::RobotDescription;

use campaign::paper_effects;

use super::bench_gp_residuals::{
    Residuals, fit_timed_with, heldout_mm, real, simulated_campaign, simulated_without_payload,
};
use super::bench_gp_sklearn::{SklearnOptions, available, fit_predict};
use super::reproduce_sim::robot_for;
use super::reproduce_sim_params::Preset;

/// Arguments of `--paper`.
#[derive(Debug, Clone, clap::Args)]
pub struct PaperArgs {
    /// Seeds of the simulated campaigns of the paper's shape.
    #[arg(long, value_delimiter = ',', default_value = "1,2,3,4,5")]
    pub paper_seeds: Vec<u64>,
    /// Skip the simulated campaigns (UR10 only).
    #[arg(long)]
    pub paper_skip_simulated: bool,
    /// Only the sets whose name contains one of these, separated by `;` (all when none is given).
    #[arg(long, value_delimiter = ';')]
    pub paper_only: Vec<String>,
    /// Kill a scikit-learn fit after this many seconds.
    #[arg(long, default_value_t = 900.0)]
    pub paper_sklearn_timeout_s: f64,
    /// Every set against scikit-learn's ARD GP, `C·RBF(ARD) + C + White` with 3 restarts and
    /// standardised inputs (the paper's setting too, instead of its Eq. 5 kernel).
    #[arg(long)]
    pub paper_sklearn_ard: bool,
    /// The GP stage's options (`calib fit --options`' `residual_gp` section, RON; fields left out
    /// keep the stage's defaults) instead of the defaults: to compare a search policy on the
    /// same residuals.
    #[arg(long)]
    pub paper_gp_options: Option<PathBuf>,
    /// Write the sets' residuals to this folder as CSV (`NAME.train.csv`, `NAME.test.csv`) instead.
    #[arg(long)]
    pub paper_dump: Option<PathBuf>,
}

/// The first three columns (the position error).
fn positions(m: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), 3, |i, j| m[(i, j)])
}

/// Mean position error (mm) of the training rows corrected by the closed-form leave-one-out
/// prediction.
fn leave_one_out_mm(model: &ExactGp, set: &Residuals) -> anyhow::Result<f64> {
    let loo = model.leave_one_out()?;
    Ok(heldout_mm(&loo.mean, &set.train))
}

/// Runs the comparison and returns the markdown table.
pub fn run(args: &PaperArgs, ur10_data: &std::path::Path) -> anyhow::Result<String> {
    let sets = data_sets(args, ur10_data)?;
    if let Some(dir) = &args.paper_dump {
        let sets: Vec<Residuals> = sets.into_iter().map(|(set, _)| set).collect();
        super::bench_gp_residuals::dump(&sets, dir)?;
        return Ok(String::new());
    }
    let with_sklearn = available();
    if !with_sklearn {
        eprintln!(
            "scikit-learn is not importable by {}: its columns stay empty",
            super::bench_gp_sklearn::python().display()
        );
    }
    let timeout = Duration::from_secs_f64(args.paper_sklearn_timeout_s);
    let config = match &args.paper_gp_options {
        Some(path) => {
            let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
            ron::from_str::<ResidualGpOptions>(&text).with_context(|| path.display().to_string())?.gp
        }
        None => ResidualGpOptions::default().gp,
    };
    let mut md = String::new();
    let _ = writeln!(
        md,
        "| data | train / test | outputs | gp held-out (mm) | gp leave-one-out (mm) | gp training (mm) | gp fit (s) | gp CPU (s) | \
         Eq. 5 kept | scikit-learn | its held-out (mm) | its fit (s) | error ratio gp / sklearn | speed-up |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|");
    for (set, isotropic) in &sets {
        eprintln!("{} …", set.name);
        let row = row(set, &config, *isotropic && !args.paper_sklearn_ard, with_sklearn, timeout)?;
        // Each row as soon as it is measured: a long run stopped half-way keeps what it did.
        eprintln!("{row}");
        let _ = writeln!(md, "{row}");
    }
    Ok(md)
}

/// The simulated campaigns (unless skipped) and the UR10 sets found under `ur10_data`, kept by
/// `--paper-only`; each with whether scikit-learn's kernel is the isotropic Eq. 5 one.
fn data_sets(args: &PaperArgs, ur10_data: &std::path::Path) -> anyhow::Result<Vec<(Residuals, bool)>> {
    let robot =
        |file: &str| RobotDescription::read(&PathBuf::from("fixtures/robots").join(file)).map_err(anyhow::Error::from);
    // (residuals, the scikit-learn kernel compared with).
    let mut sets: Vec<(Residuals, bool)> = Vec::new();
    if !args.paper_skip_simulated {
        let file = PathBuf::from("fixtures/robots/irb4400.ron");
        let irb = robot("irb4400.ron")?;
        let paper_like = robot_for(&irb, Preset::PaperLike, &file)?;
        let campaigns = [
            (&irb, paper_effects(), ""),
            (&paper_like, Preset::PaperLike.effects(), " (reproduce-sim's paper-like joints, payload only)"),
        ];
        for (robot, effects, label) in &campaigns {
            for full_pose in [false, true] {
                for &seed in &args.paper_seeds {
                    sets.push((simulated_campaign(robot, effects, label, seed, 300, 300, full_pose)?, true));
                }
            }
        }
    }
    if !args.paper_skip_simulated {
        let column_arm = column_arm(robot("column_arm.urdf")?);
        for &seed in &args.paper_seeds {
            sets.push((simulated_without_payload(&column_arm, seed, 200, 200)?, false));
        }
    }
    let ur10 = robot("ur10.ron")?;
    for (name, stem) in [("UR10 C even → odd", "ur10_C"), ("UR10 C full pose, even → odd", "ur10_C_full")] {
        let (train, test) = (ur10_data.join(format!("{stem}_even.csv")), ur10_data.join(format!("{stem}_odd.csv")));
        if train.exists() && test.exists() {
            sets.push((real(name, &ur10, &train, Some(&test))?, false));
        } else {
            eprintln!("{}: not found, {name} skipped", train.display());
        }
    }
    let patterns: Vec<&str> = args.paper_only.iter().map(|p| p.trim()).filter(|p| !p.is_empty()).collect();
    sets.retain(|(set, _)| patterns.is_empty() || patterns.iter().any(|p| set.name.contains(p)));
    if sets.is_empty() {
        anyhow::bail!("--paper-only {:?} matches no data set", args.paper_only);
    }
    Ok(sets)
}

/// The column arm with joint stiffnesses, which a URDF cannot carry (joint compliance needs them):
/// the column's in N/m (its own deflection under the arm's weight stays in the tens of µm), the
/// revolute joints' in N·m/rad at the order of a 10 kg-payload arm's reducers, so that compliance
/// leaves errors of a few tenths of a millimetre, the size of what the GP corrects on real arms.
fn column_arm(mut robot: RobotDescription) -> RobotDescription {
    if let Some(dynamics) = robot.dynamics.as_mut() {
        dynamics.stiffness_nm_per_rad = vec![5.0e7, 1.5e5, 1.5e5, 8.0e4, 2.0e4, 2.0e4, 2.0e4];
    }
    robot
}

/// One set's row: our GP's errors and fit time beside scikit-learn's.
fn row(
    set: &Residuals,
    config: &gp::GpConfig,
    isotropic: bool,
    with_sklearn: bool,
    timeout: Duration,
) -> anyhow::Result<String> {
    let (model, ours_s, ours_cpu) = fit_timed_with(set, config)?;
    let ours = heldout_mm(&model.predict_mean(set.test.inputs.as_ref())?, &set.test);
    let training = heldout_mm(&model.predict_mean(set.train.inputs.as_ref())?, &set.train);
    let loo = leave_one_out_mm(&model, set)?;
    let components = &model.report().components;
    let kept = components.iter().filter(|c| matches!(c.kernel, Kernel::Quadratic(_))).count();
    let options = SklearnOptions {
        linear: false,
        isotropic,
        restarts: if isotropic { 2 } else { 3 },
        independent: true,
        processes: 2,
        timeout,
    };
    let kernel =
        if isotropic { "C·RBF + C + DotProduct + White, 2 restarts" } else { "C·RBF(ARD) + C + White, 3 restarts" };
    let sk = if with_sklearn {
        fit_predict(&set.train.inputs, &positions(&set.train.outputs), &set.test.inputs, &options)?
    } else {
        None
    };
    let (sk_err, sk_s, ratio, speedup) = match &sk {
        Some(r) => {
            let e = heldout_mm(&r.mean, &set.test);
            (
                format!("{e:.4}"),
                format!("{:.1}", r.fit_s),
                format!("{:.3}", ours / e),
                format!("{:.1}×", r.fit_s / ours_s),
            )
        }
        None if with_sklearn => ("–".into(), format!("> {}", timeout.as_secs()), "–".into(), "–".into()),
        None => ("–".into(), "–".into(), "–".into(), "–".into()),
    };
    Ok(format!(
        "| {} | {} / {} | {} | {ours:.4} | {loo:.4} | {training:.4} | {ours_s:.2} | {ours_cpu:.2} | {kept} of {} | {kernel} | {sk_err} | {sk_s} | {ratio} | {speedup} |",
        set.name,
        set.train.inputs.nrows(),
        set.test.inputs.nrows(),
        set.train.outputs.ncols(),
        components.len(),
    ))
}
