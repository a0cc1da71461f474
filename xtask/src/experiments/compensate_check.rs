//! `cargo xtask compensate-check`: compensated programs executed on the *true* simulated robot.
//!
//! A simulated IRB 4400 cell with known truth (every local frame off by up to 1 mm / 1 mrad, a
//! tracker 3–5 m away). For each case a model is fitted on one data set and its held-out error
//! measured on another; then a program of joint targets taught on the nominal model (with the
//! case's payloads) is compensated with the model and executed on the true robot with its effects
//! but without tracker noise. The intended poses are those of `calib compensate`: the nominal
//! model placed on the calibrated one by base and tool. Also the throughput of 10,000 targets
//! against SciPy's `least_squares` per target (`xtask/scripts/compensate_scipy.py`). Writes
//! `compensate.md` into `--out`.

use anyhow::Context;
use campaign::{Effects, GeneratorConfig, Perturbation, SimulatedCell, TrackerNoiseModel};
use cell::{CompensateOptions, InverseOptions, PoseTarget};
use indicatif::{ProgressBar, ProgressStyle};
use lie::{Matrix4, SE3};
use loadsim::{Payload, PoseContext};
use model::{CalibratedModel, Method};
use pipeline::FitOptions;
use robot::RobotDescription;
use std::fmt::Write;
use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

/// Compensate simulated programs and execute them on the true robot; time 10,000 targets.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Robot description (with the load data the compliance needs).
    #[arg(long, default_value = "fixtures/robots/irb4400.ron")]
    robot: PathBuf,
    /// Seed of the cell, the data sets and the program.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Training poses.
    #[arg(long, default_value_t = 400)]
    train: usize,
    /// Held-out poses.
    #[arg(long, default_value_t = 400)]
    test: usize,
    /// Program targets executed on the true robot.
    #[arg(long, default_value_t = 1000)]
    program: usize,
    /// Targets timed.
    #[arg(long, default_value_t = 10000)]
    throughput: usize,
    /// Targets SciPy solves (its time per target is scaled to `--throughput`).
    #[arg(long, default_value_t = 1000)]
    scipy_targets: usize,
    /// Where `compensate.md` goes.
    #[arg(long, default_value = "docs/results")]
    out: PathBuf,
}

struct Case {
    label: &'static str,
    method: Method,
    effects: Effects,
    payloads_kg: Vec<f64>,
}

struct Outcome {
    label: &'static str,
    method: Method,
    heldout_mm: f64,
    heldout_mrad: f64,
    before_mm: f64,
    before_mrad: f64,
    after_mm: f64,
    after_mrad: f64,
    after_max_mm: f64,
    refused: usize,
    max_iterations: usize,
}

fn cases() -> Vec<Case> {
    let noise = Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..Effects::default() };
    let paper = campaign::paper_effects();
    let payloads = GeneratorConfig::default().payloads_kg;
    vec![
        Case {
            label: "geometry and tracker noise, no payload",
            method: Method::Poe,
            effects: noise,
            payloads_kg: vec![0.0],
        },
        Case {
            label: "compliance under the paper's payloads, tracker noise",
            method: Method::Poe,
            effects: paper.clone(),
            payloads_kg: payloads.clone(),
        },
        Case {
            label: "compliance under the paper's payloads, tracker noise",
            method: Method::PoeGpLoad,
            effects: paper,
            payloads_kg: payloads,
        },
    ]
}

/// Mean point and rotation distance of `reached` from `wanted`, and the largest point distance.
fn distances(reached: &[SE3], wanted: &[SE3]) -> (f64, f64, f64) {
    let n = reached.len().max(1) as f64;
    let points: Vec<f64> =
        reached.iter().zip(wanted).map(|(a, b)| (a.translation() - b.translation()).norm()).collect();
    let rotations: f64 =
        reached.iter().zip(wanted).map(|(a, b)| (a.rotation() * b.rotation().inverse()).log().norm()).sum();
    (points.iter().sum::<f64>() / n, rotations / n, points.iter().copied().fold(0.0, f64::max))
}

/// The program: joint targets and payloads of a seeded set of configurations.
fn program(
    cell: &SimulatedCell,
    robot: &RobotDescription,
    count: usize,
    seed: u64,
    payloads: &[f64],
) -> anyhow::Result<Vec<(Vec<f64>, f64)>> {
    let config =
        GeneratorConfig { sample_count: count, seed, payloads_kg: payloads.to_vec(), ..GeneratorConfig::default() };
    let set = campaign::simulate(cell, &Effects::default(), &campaign::joint_ranges(robot), &config, false)?;
    Ok(set.rows.into_iter().map(|r| (r.q, r.payload_kg)).collect())
}

/// The targets `calib compensate` makes of joint targets.
fn targets(
    model: &CalibratedModel,
    robot: &RobotDescription,
    rows: &[(Vec<f64>, f64)],
) -> anyhow::Result<Vec<PoseTarget>> {
    let registered = cell::registered_nominal(model, robot, "robot", &CompensateOptions::default())?;
    rows.iter()
        .map(|(q, payload_kg)| {
            Ok(PoseTarget {
                seed: q.clone(),
                pose: registered.model.forward(q, 0)?,
                orientation: model.full_pose,
                payload_kg: *payload_kg,
                tool: 0,
                inputs: Default::default(),
            })
        })
        .collect()
}

fn run_case(
    case: &Case,
    robot: &RobotDescription,
    cell: &SimulatedCell,
    args: &Args,
) -> anyhow::Result<(Outcome, CalibratedModel)> {
    let ranges = campaign::joint_ranges(robot);
    let data = |count: usize, seed: u64| {
        let config = GeneratorConfig {
            sample_count: count,
            seed,
            payloads_kg: case.payloads_kg.clone(),
            ..GeneratorConfig::default()
        };
        campaign::simulate(cell, &case.effects, &ranges, &config, true)
    };
    let (train, test) = (data(args.train, args.seed)?, data(args.test, args.seed + 1000)?);
    let (model, _) = pipeline::fit(robot, &train, case.method, &FitOptions::default())?;
    let heldout = model::evaluate(&model, &model.bind(&test)?)?.summary;
    let rows = program(cell, robot, args.program, args.seed + 2000, &case.payloads_kg)?;
    let targets = targets(&model, robot, &rows)?;
    let solved = cell::solve_targets(&model, &targets, Some(&robot.limits()), &InverseOptions::default())?;
    let truth = Effects { tracker_noise: None, ..case.effects.clone() };
    let (mut before, mut after, mut wanted) = (Vec::new(), Vec::new(), Vec::new());
    for ((target, solved), (q, payload_kg)) in targets.iter().zip(&solved).zip(&rows) {
        if !solved.status.is_ok() {
            continue;
        }
        let context = PoseContext { payload: Payload::at_tool(*payload_kg), ..PoseContext::default() };
        before.push(truth.true_pose(cell, q, &context)?);
        after.push(truth.true_pose(cell, &solved.q, &context)?);
        wanted.push(target.pose);
    }
    let (before_mm, before_mrad, _) = distances(&before, &wanted);
    let (after_mm, after_mrad, after_max_mm) = distances(&after, &wanted);
    let outcome = Outcome {
        label: case.label,
        method: case.method,
        heldout_mm: heldout.mean_position_error_mm,
        heldout_mrad: heldout.mean_rotation_error_mrad.unwrap_or(f64::NAN),
        before_mm: before_mm * 1e3,
        before_mrad: before_mrad * 1e3,
        after_mm: after_mm * 1e3,
        after_mrad: after_mrad * 1e3,
        after_max_mm: after_max_mm * 1e3,
        refused: solved.iter().filter(|s| !s.status.is_ok()).count(),
        max_iterations: solved.iter().map(|s| s.iterations).max().unwrap_or(0),
    };
    Ok((outcome, model))
}

/// Seconds `calib compensate`'s pipeline takes for `count` joint targets (registration included).
fn time_targets(
    model: &CalibratedModel,
    robot: &RobotDescription,
    rows: &[(Vec<f64>, f64)],
) -> anyhow::Result<(f64, usize)> {
    let begin = Instant::now();
    let targets = targets(model, robot, rows)?;
    let solved = cell::solve_targets(model, &targets, Some(&robot.limits()), &InverseOptions::default())?;
    Ok((begin.elapsed().as_secs_f64(), solved.iter().filter(|s| s.status.is_ok()).count()))
}

fn matrix(t: &SE3) -> Vec<Vec<f64>> {
    let m: Matrix4 = t.to_matrix();
    (0..4).map(|r| (0..4).map(|c| m[(r, c)]).collect()).collect()
}

/// SciPy's seconds per target and the largest point residual, or `None` without SciPy.
fn scipy(model: &CalibratedModel, targets: &[PoseTarget]) -> anyhow::Result<Option<(f64, f64)>> {
    let python = Command::new("python3").args(["-c", "import scipy"]).output().is_ok_and(|o| o.status.success());
    if !python {
        return Ok(None);
    }
    let kinematics = &model.kinematics;
    let local = kinematics.joints().iter().map(|j| matrix(&j.previous_from_joint_zero));
    let problem = ScipyProblem {
        local_transforms: local.chain(std::iter::once(matrix(&kinematics.tools()[0]))).collect(),
        seeds: targets.iter().map(|t| t.seed.clone()).collect(),
        targets: targets.iter().map(|t| matrix(&t.pose)).collect(),
    };
    let path = std::env::temp_dir().join("calib-compensate-scipy.json");
    std::fs::write(&path, serde_json::to_string(&problem)?)?;
    let script = crate::workspace_root().join("xtask/scripts/compensate_scipy.py");
    let output = Command::new("python3").arg(&script).arg(&path).output().context("running python3")?;
    if !output.status.success() {
        anyhow::bail!("{}: {}", script.display(), String::from_utf8_lossy(&output.stderr));
    }
    let result: ScipyResult = serde_json::from_slice(&output.stdout).context("reading SciPy's answer")?;
    Ok(Some((result.seconds / targets.len().max(1) as f64, result.max_residual_m)))
}

/// What `xtask/scripts/compensate_scipy.py` is given: the geometric model, seeds and targets.
#[derive(Debug, serde::Serialize)]
struct ScipyProblem {
    local_transforms: Vec<Vec<Vec<f64>>>,
    seeds: Vec<Vec<f64>>,
    targets: Vec<Vec<Vec<f64>>>,
}

/// What it answers.
#[derive(Debug, serde::Deserialize)]
struct ScipyResult {
    seconds: f64,
    max_residual_m: f64,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = RobotDescription::read(&args.robot)?;
    let cell = campaign::simulated_cell(&robot, &Perturbation::default(), args.seed)?;
    let Measurements { outcomes, timings, scipy: scipy_result } = measure(args, &robot, &cell)?;

    let mut md = String::new();
    let _ = writeln!(md, "# Compensated programs on the true simulated robot\n");
    let _ = writeln!(
        md,
        "`cargo xtask compensate-check --seed {}`: a simulated {} (every local frame off by up to 1 mm / 1 mrad, a 0.2 m \
         tool, a tracker 3–5 m away, full-pose measurements). Each model is fitted on {} poses and tested on {} others \
         (held-out mean, tracker noise included). A program of {} joint targets taught on the nominal model, with the \
         case's payloads, is compensated with the model (`calib compensate`: the intended pose of a joint target is the \
         nominal model's, placed on the calibrated one by base and tool) and executed on the true robot with its effects \
         but no tracker noise. Errors are means over the rows compensated (`ok`), against the intended poses.\n",
        args.seed, robot.name, args.train, args.test, args.program
    );
    let _ = writeln!(
        md,
        "| method | effects | held-out (mm / mrad) | program as it is (mm / mrad) | compensated (mm / mrad) | compensated max (mm) | compensated / held-out | refused | steps (max) |"
    );
    let _ = writeln!(md, "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let failed = outcome_rows(&mut md, &outcomes);
    throughput_section(&mut md, args, &timings, scipy_result);
    let path = args.out.join("compensate.md");
    std::fs::write(&path, &md).with_context(|| path.display().to_string())?;
    println!("{md}");
    if !failed.is_empty() {
        anyhow::bail!("compensated error above 1.2× the held-out error: {}", failed.join("; "));
    }
    Ok(())
}

/// What the time of one model on the throughput targets gave: the method, seconds, targets compensated.
type Timing = (Method, f64, usize);

/// What `measure` gives.
struct Measurements {
    /// Every case's outcome.
    outcomes: Vec<Outcome>,
    /// Each model's time on the throughput targets (all but the first case's).
    timings: Vec<Timing>,
    /// SciPy's seconds per target and largest residual on the first geometric model, or `None`
    /// without SciPy.
    scipy: Option<(f64, f64)>,
}

/// Every case, then the throughput targets, then SciPy.
fn measure(args: &Args, robot: &RobotDescription, cell: &SimulatedCell) -> anyhow::Result<Measurements> {
    let cases = cases();
    let bar = ProgressBar::new(cases.len() as u64 + 2);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut outcomes = Vec::new();
    let mut models = Vec::new();
    for case in &cases {
        bar.set_message(format!("{}: {}", case.method, case.label));
        let (outcome, model) = run_case(case, robot, cell, args)?;
        outcomes.push(outcome);
        models.push(model);
        bar.inc(1);
    }
    bar.set_message("throughput");
    let rows = program(cell, robot, args.throughput, args.seed + 3000, &[0.0, 2.5, 5.0])?;
    let mut timings = Vec::new();
    for (case, model) in cases.iter().zip(&models).skip(1) {
        let (seconds, ok) = time_targets(model, robot, &rows)?;
        timings.push((case.method, seconds, ok));
    }
    bar.inc(1);
    bar.set_message("SciPy");
    let geometric = &models[1];
    let scipy_rows: Vec<(Vec<f64>, f64)> = rows.iter().take(args.scipy_targets).cloned().collect();
    let scipy_result = scipy(geometric, &targets(geometric, robot, &scipy_rows)?)?;
    bar.finish_and_clear();
    Ok(Measurements { outcomes, timings, scipy: scipy_result })
}

/// One row per case; returns the cases whose compensated error exceeds 1.2× their held-out error.
fn outcome_rows(md: &mut String, outcomes: &[Outcome]) -> Vec<String> {
    let mut failed = Vec::new();
    for o in outcomes {
        let ratio = o.after_mm / o.heldout_mm;
        let verdict = if ratio <= 1.2 { "≤ 1.2" } else { "**> 1.2**" };
        if ratio > 1.2 {
            failed.push(format!("{} ({}): {ratio:.2}", o.method, o.label));
        }
        let _ = writeln!(
            md,
            "| `{}` | {} | {:.4} / {:.4} | {:.4} / {:.4} | {:.4} / {:.4} | {:.4} | {ratio:.2} ({verdict}) | {} | {} |",
            o.method,
            o.label,
            o.heldout_mm,
            o.heldout_mrad,
            o.before_mm,
            o.before_mrad,
            o.after_mm,
            o.after_mrad,
            o.after_max_mm,
            o.refused,
            o.max_iterations
        );
    }
    failed
}

/// The throughput table and the comparison with SciPy.
fn throughput_section(md: &mut String, args: &Args, timings: &[Timing], scipy_result: Option<(f64, f64)>) {
    let _ = writeln!(
        md,
        "\n## Throughput\n\n{} joint targets (payloads 0, 2.5, 5 kg), registration of the nominal model included, this \
         machine, `cargo xtask` (the workspace's numeric crates at opt-level 3), rayon over the available cores:\n",
        args.throughput
    );
    let _ = writeln!(md, "| model | time (s) | targets per second | compensated |");
    let _ = writeln!(md, "| --- | ---: | ---: | ---: |");
    for (method, seconds, ok) in timings {
        let _ = writeln!(md, "| `{method}` | {seconds:.3} | {:.0} | {ok} |", args.throughput as f64 / seconds);
    }
    match scipy_result {
        Some((per_target, residual)) => {
            let ours = timings.first().map_or(f64::NAN, |t| t.1 / args.throughput as f64);
            let _ = writeln!(
                md,
                "\nWhat a user would write instead: `scipy.optimize.least_squares` per target on the same geometric model \
                 (numpy forward kinematics, finite-difference Jacobian; `xtask/scripts/compensate_scipy.py`), {} targets, \
                 one core: {:.2} ms per target, {:.1} s scaled to {} (largest residual {:.1e} m), {:.0}× the time of \
                 `poe` above.",
                args.scipy_targets,
                per_target * 1e3,
                per_target * args.throughput as f64,
                args.throughput,
                residual,
                per_target / ours
            );
        }
        None => {
            let _ = writeln!(md, "\n(SciPy is not installed here: no comparison.)");
        }
    }
}
