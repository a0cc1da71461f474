//! `cargo xtask bench-identify`: the local POE identification against what a user would write
//! instead — `scipy.optimize.least_squares` on the same residual with a finite-difference
//! Jacobian (`xtask/scripts/identify_scipy.py`) — on the same data in the same run.
//!
//! The data: the IRB 4400 fixture with every local frame off by up to 2 mm / 2 mrad, seen from a
//! tracker metres away, full-pose measurements with 0.02 mm / 0.02 mrad noise. Both start from the
//! same closed-form registration.

use anyhow::Context;
use campaign::{Perturbation, simulated_cell};
use lie::{Matrix4, SE3, Vector3};
use poe::identify::{IdentificationOptions, Observation, ParameterMask, Target, identify, register};
use poe::{JointKind, LocalPoe};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robot::RobotDescription;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Time the identification against SciPy.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Numbers of measured poses.
    #[arg(long, value_delimiter = ',', default_value = "100,300,1000")]
    rows: Vec<usize>,
    /// Fits timed per size (the median is reported).
    #[arg(long, default_value_t = 5)]
    repeats: usize,
    /// Robot description.
    #[arg(long, default_value = "fixtures/robots/irb4400.ron")]
    robot: PathBuf,
    /// Also write the table here.
    #[arg(long)]
    out: Option<PathBuf>,
}

const SIGMA: f64 = 2e-5;

fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    use rand_distr::{Distribution, StandardNormal};
    StandardNormal.sample(rng)
}

fn matrix(t: &SE3) -> Vec<Vec<f64>> {
    let m: Matrix4 = t.to_matrix();
    (0..4).map(|r| (0..4).map(|c| m[(r, c)]).collect()).collect()
}

/// What `xtask/scripts/identify_scipy.py` is given: the same start, joints and measurements.
#[derive(Debug, serde::Serialize)]
struct ScipyProblem {
    local_transforms: Vec<Vec<Vec<f64>>>,
    q: Vec<Vec<f64>>,
    /// Measured poses; for position-only data the rotation part is the identity and unused.
    measured: Vec<Vec<Vec<f64>>>,
    /// Whether the orientation residual is fitted too (position only otherwise).
    full_pose: bool,
    position_sigma_m: f64,
    rotation_sigma_rad: f64,
}

/// What it answers.
#[derive(Debug, serde::Deserialize)]
pub struct ScipyResult {
    /// Seconds of one `least_squares` (the median of the repeats).
    pub seconds: f64,
    /// Function evaluations of the last fit.
    pub evaluations: u64,
    /// RMS position error of the fitted model on the rows it was fitted to, m.
    pub rms_position_m: f64,
}

/// The identification as a SciPy user writes it (`xtask/scripts/identify_scipy.py` run by
/// `python`): every local transform of `start` and its one tool fitted by `least_squares` to
/// `observations` (all poses or all points), weighted by the two sigmas; `repeats` fits, the median
/// timed. The script turns every joint about its local z axis, so only revolute joints moved
/// directly (scale 1) are accepted.
pub fn scipy_identify(
    python: &Path,
    start: &LocalPoe,
    observations: &[Observation],
    position_sigma_m: f64,
    rotation_sigma_rad: f64,
    repeats: usize,
) -> anyhow::Result<ScipyResult> {
    if let Some(i) = start.joints().iter().position(|j| j.kind != JointKind::Revolute || j.scale != 1.0) {
        anyhow::bail!("joint {}: identify_scipy.py models revolute joints of scale 1 only", i + 1);
    }
    if start.tools().len() != 1 || observations.iter().any(|o| o.tool != 0) {
        anyhow::bail!("identify_scipy.py models one tool; the data have {}", start.tools().len());
    }
    let full_pose = observations.iter().all(|o| matches!(o.target, Target::Pose(_)));
    let local = start.joints().iter().map(|j| matrix(&j.previous_from_joint_zero));
    let problem = ScipyProblem {
        local_transforms: local.chain(std::iter::once(matrix(&start.tools()[0]))).collect(),
        q: observations.iter().map(|o| o.q.clone()).collect(),
        measured: observations
            .iter()
            .map(|o| match o.target {
                Target::Pose(p) if full_pose => matrix(&p),
                Target::Pose(p) => matrix(&SE3::from_translation(p.translation())),
                Target::Point(p) => matrix(&SE3::from_translation(p)),
            })
            .collect(),
        full_pose,
        position_sigma_m,
        rotation_sigma_rad,
    };
    let path = std::env::temp_dir().join(format!("calib-identify-{}-{}.json", std::process::id(), observations.len()));
    std::fs::write(&path, serde_json::to_string(&problem)?).with_context(|| path.display().to_string())?;
    let script = crate::workspace_root().join("xtask/scripts/identify_scipy.py");
    let output = Command::new(python)
        .arg(&script)
        .arg(&path)
        .arg(repeats.max(1).to_string())
        .output()
        .with_context(|| format!("running {}", python.display()))?;
    let _ = std::fs::remove_file(&path);
    if !output.status.success() {
        anyhow::bail!("{}: {}", script.display(), String::from_utf8_lossy(&output.stderr));
    }
    serde_json::from_slice(&output.stdout).context("reading SciPy's answer")
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = RobotDescription::read(&args.robot)?;
    let nominal = robot.nominal_model()?;
    let perturbation = Perturbation { translation_m: 2e-3, rotation_rad: 2e-3, tool_m: 0.2 };
    let cell = simulated_cell(&robot, &perturbation, 7)?;
    let truth = {
        let mut t = cell.robot.clone();
        t.change_reference(cell.tracker_from_base);
        t
    };
    let python = Command::new("python3").args(["-c", "import scipy"]).output().is_ok_and(|o| o.status.success());
    let options = IdentificationOptions { position_sigma_m: SIGMA, rotation_sigma_rad: SIGMA, ..Default::default() };
    let mut table = String::from(
        "| poses | calib (ms) | iterations | RMS (mm) | SciPy least_squares (ms) | evaluations | RMS (mm) | speed-up |\n\
         | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for &rows in &args.rows {
        let observations = noisy_poses(&robot, &cell.robot, &truth, rows)?;
        let start = register(&nominal, &observations)?;
        timed_row(&mut table, args, rows, &start, &observations, &options, python)?;
    }
    println!("{table}");
    if let Some(path) = &args.out {
        let body = format!(
            "# Identification against SciPy\n\n`cargo xtask bench-identify`: the local POE identification of a perturbed IRB 4400 \
(every local frame off by up to 2 mm / 2 mrad, full-pose data, 0.02 mm / 0.02 mrad noise) from the same closed-form \
registration, calib's iterative least squares (one core) against `scipy.optimize.least_squares` (trf, \
finite-difference Jacobian) on the same weighted residual. Median of the timed fits.\n\n{table}"
        );
        std::fs::write(path, body).with_context(|| path.display().to_string())?;
    }
    Ok(())
}

/// `rows` poses of the true robot (`truth`, in the tracker frame) with SIGMA of noise on each
/// component, at configurations drawn for `true_base` (the true robot in its base frame).
fn noisy_poses(
    robot: &RobotDescription,
    true_base: &LocalPoe,
    truth: &LocalPoe,
    rows: usize,
) -> anyhow::Result<Vec<Observation>> {
    let mut rng = ChaCha8Rng::seed_from_u64(rows as u64);
    let configurations = loadsim::sample_configurations(
        true_base,
        0,
        &campaign::joint_ranges(robot),
        &loadsim::GeneratorConfig { sample_count: rows, seed: rows as u64, ..Default::default() },
    )?;
    Ok(configurations
        .into_iter()
        .map(|q| {
            let pose = truth.forward(&q, 0).expect("six joints");
            let dp = Vector3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng)) * SIGMA;
            let dr = Vector3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng)) * SIGMA;
            let noisy = SE3::new(lie::SO3::exp(&dr) * pose.rotation(), pose.translation() + dp);
            Observation { q, tool: 0, target: Target::Pose(noisy), stated_sigma: None }
        })
        .collect())
}

/// One size's row: the median of `--repeats` timed fits from `start`, and SciPy's (when `python`).
fn timed_row(
    table: &mut String,
    args: &Args,
    rows: usize,
    start: &LocalPoe,
    observations: &[Observation],
    options: &IdentificationOptions,
    python: bool,
) -> anyhow::Result<()> {
    let mask = ParameterMask::all(start.layout());
    // One core, as the SciPy fit runs.
    faer::set_global_parallelism(faer::Par::Seq);
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..args.repeats.max(1) {
        let begin = Instant::now();
        let fit = identify(start, observations, &mask, options)?;
        times.push(begin.elapsed().as_secs_f64());
        last = Some(fit);
    }
    times.sort_by(f64::total_cmp);
    let ours_s = times[times.len() / 2];
    let fit = last.context("no fit")?;
    let ours_rms = fit.report.iterations.last().map_or(f64::NAN, |r| r.rms_position_m);
    let _ =
        write!(table, "| {rows} | {:.2} | {} | {:.4} |", ours_s * 1e3, fit.report.iteration_count(), ours_rms * 1e3);
    if python {
        let repeats = if rows > 300 { 1 } else { args.repeats.clamp(1, 3) };
        let result = scipy_identify(Path::new("python3"), start, observations, SIGMA, SIGMA, repeats)?;
        let theirs = result.seconds;
        let _ = writeln!(
            table,
            " {:.1} | {} | {:.4} | {:.0}× |",
            theirs * 1e3,
            result.evaluations,
            result.rms_position_m * 1e3,
            theirs / ours_s
        );
    } else {
        let _ = writeln!(table, " – | – | – | – |");
    }
    Ok(())
}
