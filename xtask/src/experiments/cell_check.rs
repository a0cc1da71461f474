//! `cargo xtask cell-check`: the table for `calib register` and `calib plan`
//! (crate `cell`), in process, printed as markdown.
//!
//! - The real UR10 (Landgraf et al., CASE 2021, converted to SPEC CSV, not in this repository):
//!   the geometry fitted on all of series C, registered on 30 random rows of series D (measured
//!   four months later, the tracker 3.6 m away), evaluated on the other rows of D; beside the
//!   same base re-fit by SciPy (`xtask/scripts/register_scipy.py`) on the same predictions.
//! - Simulated known truth: a calibrated IRB 4400 (`poe-gp-load` on 300 poses of the paper's
//!   simulation), the tracker moved and a new tool mounted, 20 poses registered; held-out error
//!   against the original model's.
//! - Plans against random choices: UR10 C, `poe` on N planned or random even rows, tested on the
//!   odd rows; the simulated IRB 4400 with geometric errors and tracker noise only, 25 planned
//!   poses against 300 random ones; the time to choose 100 of 10,000 candidates; with
//!   `--effects`, 300 planned against 300 random even rows for `poe-gp --effects auto`.

use anyhow::{Context, Result};
use campaign::{Effects, GeneratorConfig, Perturbation, SimulatedCell};
use cell::{Refit, RegisterOptions};
use effects::EffectSelection;
use lie::{SE3, SO3, Vector3};
use measurements::{MeasurementSet, ReadOptions};
use model::{CalibratedModel, Method};
use pipeline::FitOptions;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use robot::RobotDescription;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Registration and planning on the real UR10 and on simulated truth.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder with the UR10 series as SPEC CSV (`ur10_C_full.csv`, `ur10_C_full_even.csv`, …,
    /// from `cargo xtask convert-ur10`).
    #[arg(long, default_value = "/work/data")]
    data: PathBuf,
    /// The UR10's description.
    #[arg(long, default_value = "fixtures/robots/ur10.ron")]
    ur10: PathBuf,
    /// The IRB 4400's description.
    #[arg(long, default_value = "fixtures/robots/irb4400.ron")]
    irb4400: PathBuf,
    /// Random draws per comparison.
    #[arg(long, default_value_t = 5)]
    seeds: u64,
    /// Also 300 planned against 300 random rows for `poe-gp --effects auto` (10 seeds; minutes).
    #[arg(long)]
    effects: bool,
    /// Planning options (RON, `planning::PlanOptions`) for every plan of the check; the criterion is
    /// set per column.
    #[arg(long)]
    plan_options: Option<String>,
    /// The UR10 series the plan-ur10 section plans from (its even rows) and tests on (its odd rows).
    #[arg(long, default_value = "C")]
    series: String,
    /// Only these sections (comma separated): register-ur10, register-simulated, plan-ur10,
    /// plan-irb4400, timing, effects [default: all but effects, and effects with --effects].
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 { values[n / 2] } else { 0.5 * (values[n / 2 - 1] + values[n / 2]) }
}

fn list(values: &[f64]) -> String {
    values.iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>().join(", ")
}

/// `count` distinct indices below `n`, drawn from `seed`, sorted.
fn draw(n: usize, count: usize, seed: u64) -> Vec<usize> {
    let mut all: Vec<usize> = (0..n).collect();
    all.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    let mut picked = all[..count.min(n)].to_vec();
    picked.sort_unstable();
    picked
}

fn read(robot: &RobotDescription, path: &Path) -> Result<MeasurementSet> {
    let kinds = robot.nominal_model()?.joints().iter().map(|j| j.kind).collect();
    measurements::read_measurements(path, &ReadOptions::for_joints(kinds)).with_context(|| path.display().to_string())
}

fn mean_error(model: &CalibratedModel, data: &MeasurementSet) -> Result<f64> {
    Ok(model::evaluate(model, &model.bind(data)?)?.summary.mean_position_error_mm)
}

fn fit_and_test(
    robot: &RobotDescription,
    train: &MeasurementSet,
    test: &MeasurementSet,
    options: &FitOptions,
    method: Method,
) -> Result<f64> {
    let (model, _) = pipeline::fit(robot, train, method, options)?;
    mean_error(&model, test)
}

pub fn run(args: &Args) -> Result<()> {
    let mut md = String::from("# Re-registration and planned poses\n\nProduced by `cargo xtask cell-check`.\n");
    let wanted = |name: &str| {
        if args.only.is_empty() { name != "effects" || args.effects } else { args.only.iter().any(|o| o == name) }
    };
    type Section = fn(&Args, &mut String) -> Result<()>;
    let sections: [(&str, Section); 6] = [
        ("register-ur10", register_ur10),
        ("register-simulated", register_simulated),
        ("plan-ur10", plan_ur10),
        ("plan-irb4400", plan_irb4400),
        ("timing", plan_timing),
        ("effects", plan_effects),
    ];
    for (name, section) in sections {
        if wanted(name) {
            section(args, &mut md)?;
        }
    }
    println!("{md}");
    Ok(())
}

/// The SciPy reference's mean error on the rows not in `picked`, where Python with SciPy runs.
fn scipy_reference(
    model: &CalibratedModel,
    data: &MeasurementSet,
    path: &Path,
    picked: &[usize],
    rotation_weight: f64,
) -> Result<Option<f64>> {
    let predicted = model.predict(&model.bind(data)?)?;
    let dir = std::env::temp_dir().join(format!("cell-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let file = dir.join("predicted.csv");
    let mut text = String::from("x_mm,y_mm,z_mm,qw,qx,qy,qz\n");
    for p in &predicted {
        let t = p.pose.translation() * 1e3;
        let [w, x, y, z] = p.pose.rotation().to_quaternion();
        let _ = writeln!(text, "{},{},{},{w},{x},{y},{z}", t.x, t.y, t.z);
    }
    std::fs::write(&file, text)?;
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/register_scipy.py");
    let lines: Vec<String> = picked.iter().map(ToString::to_string).collect();
    let out = std::process::Command::new(super::bench_gp_sklearn::python())
        .arg(&script)
        .arg(&file)
        .arg(path)
        .arg(lines.join(","))
        .arg(rotation_weight.to_string())
        .output();
    let _ = std::fs::remove_dir_all(&dir);
    let Ok(out) = out else { return Ok(None) };
    if !out.status.success() {
        return Ok(None);
    }
    let json: serde_json::Value = serde_json::from_slice(&out.stdout)?;
    Ok(json["mean_position_error_mm"].as_f64())
}

fn register_ur10(args: &Args, md: &mut String) -> Result<()> {
    let robot = RobotDescription::read(&args.ur10)?;
    let _ = writeln!(
        md,
        "\n## UR10: fitted on series C, registered on 30 random rows of series D\n\n`poe` on all rows of C; its \
         held-out error (`poe` on the even rows of C, tested on the odd rows) is given as `--heldout-mm`. Registration \
         re-fits the base only; the SciPy column re-fits the same transform with `scipy.optimize.least_squares` on \
         the same predictions and with the rotation weight registration ended with (`xtask/scripts/register_scipy.py`).\n"
    );
    let _ = writeln!(
        md,
        "| data | seed | held-out of C (mm) | residual on the 30 (mm) | verdict | D rest (mm) | SciPy on D rest (mm) | ratio |"
    );
    let _ = writeln!(md, "| --- | ---: | ---: | ---: | --- | ---: | ---: | ---: |");
    for (label, suffix) in [("full pose", "_full"), ("position", "")] {
        let file = |series: &str, part: &str| args.data.join(format!("ur10_{series}{suffix}{part}.csv"));
        let c = read(&robot, &file("C", ""))?;
        let d_path = file("D", "");
        let d = read(&robot, &d_path)?;
        let options = FitOptions::default();
        let heldout = fit_and_test(
            &robot,
            &read(&robot, &file("C", "_even"))?,
            &read(&robot, &file("C", "_odd"))?,
            &options,
            Method::Poe,
        )?;
        let (model, _) = pipeline::fit(&robot, &c, Method::Poe, &options)?;
        for seed in 1..=args.seeds {
            let picked = draw(d.rows.len(), 30, seed);
            let rest: Vec<usize> = (0..d.rows.len()).filter(|i| picked.binary_search(i).is_err()).collect();
            let refit = Refit { base: true, tools: false };
            let registered =
                cell::register(&model, &d.subset(&picked), refit, Some(heldout), &RegisterOptions::default())?;
            let ours = mean_error(&registered.model, &d.subset(&rest))?;
            let weight = registered.report.rotation_weight_m_per_rad;
            let reference = scipy_reference(&model, &d, &d_path, &picked, weight)?;
            let _ = writeln!(
                md,
                "| {label} | {seed} | {heldout:.4} | {:.4} | {:?} | {ours:.4} | {} | {} |",
                registered.report.residual.mean_position_error_mm,
                registered.report.verdict,
                reference.map_or("–".into(), |r| format!("{r:.4}")),
                reference.map_or("–".into(), |r| format!("{:.3}", ours / r)),
            );
        }
    }
    Ok(())
}

fn register_simulated(args: &Args, md: &mut String) -> Result<()> {
    let robot = RobotDescription::read(&args.irb4400)?;
    let _ = writeln!(
        md,
        "\n## Simulated truth: the tracker moved and a new tool, 20 poses registered\n\nIRB 4400 of the paper's \
         simulation (every local frame off by up to 1 mm and 1 mrad, joint compliance under the arm and a payload, \
         tracker noise); `poe-gp-load` on 300 poses; held-out on 1,000 poses of the same cell. Then the tracker \
         placed anew (3–5 m away, any bearing) and, where the tool is new, replaced by one 10 cm and 0.3 rad away; \
         20 poses registered (`--refit base,tools` with the new tool, `--refit base` without), held-out on 1,000 \
         poses of the moved cell. A position-only model knows the flange orientation only as far as its tool point \
         shows it, so a new tool point is refused by the verdict and warned about (the last row).\n"
    );
    let _ = writeln!(
        md,
        "| seed | data | tool | original held-out (mm) | registered held-out (mm) | ratio | residual on the 20 (mm) | verdict | warnings |"
    );
    let _ = writeln!(md, "| ---: | --- | --- | ---: | ---: | ---: | ---: | --- | --- |");
    for seed in 1..=args.seeds {
        let original = campaign::simulated_cell(&robot, &Perturbation::default(), seed)?;
        let mut same_tool = original.clone();
        same_tool.tracker_from_base = campaign::tracker_placement(&mut ChaCha8Rng::seed_from_u64(seed + 100));
        let mut new_tool = same_tool.clone();
        let tool = original.robot.tools()[original.tool]
            * SE3::new(SO3::exp(&Vector3::new(0.0, 0.3, 0.1)), Vector3::new(0.06, -0.05, 0.06));
        new_tool.robot.set_tools(vec![tool]);
        new_tool.tool = 0;
        for (full_pose, new) in [(true, true), (true, false), (false, false), (false, true)] {
            let moved = if new { &new_tool } else { &same_tool };
            register_row(md, &robot, &original, moved, seed, full_pose, new)?;
        }
    }
    Ok(())
}

/// One row: `poe-gp-load` fitted on the original cell, registered on 20 poses of the `moved` one
/// (with its new tool when `new`), both tested on 1,000 poses.
fn register_row(
    md: &mut String,
    robot: &RobotDescription,
    original: &SimulatedCell,
    moved: &SimulatedCell,
    seed: u64,
    full_pose: bool,
    new: bool,
) -> Result<()> {
    let ranges = campaign::joint_ranges(robot);
    let effects = campaign::paper_effects();
    let config = |rows: usize, offset: u64| GeneratorConfig {
        sample_count: rows,
        seed: seed * 10 + offset,
        ..GeneratorConfig::default()
    };
    let train = campaign::simulate(original, &effects, &ranges, &config(300, 0), full_pose)?;
    let test = campaign::simulate(original, &effects, &ranges, &config(1000, 1), full_pose)?;
    let (model, _) = pipeline::fit(robot, &train, Method::PoeGpLoad, &FitOptions::default())?;
    let before = mean_error(&model, &test)?;
    let renamed = |mut set: MeasurementSet| {
        if new {
            set.tools = vec!["probe2".into()];
        }
        set
    };
    let few = renamed(campaign::simulate(moved, &effects, &ranges, &config(20, 2), full_pose)?);
    let moved_test = renamed(campaign::simulate(moved, &effects, &ranges, &config(1000, 3), full_pose)?);
    let refit = Refit { base: true, tools: new };
    let registered = cell::register(&model, &few, refit, Some(before), &RegisterOptions::default())?;
    let after = mean_error(&registered.model, &moved_test)?;
    let warnings: Vec<String> = registered.report.warnings.iter().map(|w| format!("{w:?}")).collect();
    let _ = writeln!(
        md,
        "| {seed} | {} | {} | {before:.4} | {after:.4} | {:.3} | {:.4} | {:?} | {} |",
        if full_pose { "full pose" } else { "position" },
        if new { "new" } else { "same" },
        after / before,
        registered.report.residual.mean_position_error_mm,
        registered.report.verdict,
        warnings.join(", ")
    );
    Ok(())
}

/// The planning options of `--plan-options`, or the defaults.
fn plan_options(args: &Args) -> Result<planning::PlanOptions> {
    Ok(match &args.plan_options {
        Some(text) => planning::PlanOptions::parse(text, "--plan-options")?,
        None => planning::PlanOptions::default(),
    })
}

fn plan_rows(
    robot: &RobotDescription,
    set: &MeasurementSet,
    n: usize,
    full_pose: bool,
    options: &planning::PlanOptions,
) -> Result<Vec<usize>> {
    let candidates = planning::file_candidates(set, robot, None)?;
    Ok(planning::plan(&candidates.model, &candidates.candidates, n, full_pose, options)?.order)
}

fn plan_ur10(args: &Args, md: &mut String) -> Result<()> {
    let robot = RobotDescription::read(&args.ur10)?;
    let series = &args.series;
    let even = read(&robot, &args.data.join(format!("ur10_{series}_full_even.csv")))?;
    let odd = read(&robot, &args.data.join(format!("ur10_{series}_full_odd.csv")))?;
    let options = FitOptions::default();
    let all = fit_and_test(&robot, &even, &odd, &options, Method::Poe)?;
    let _ = writeln!(
        md,
        "\n## UR10 {series}: what a geometric fit needs\n\n`poe` on N rows of the even rows of series {series}, tested on \
         the {} odd rows; all {} even rows give {all:.4} mm. Planned: `calib plan --full-pose` from the even rows \
         (criterion i, the default, and d; options: {}).\n",
        odd.rows.len(),
        even.rows.len(),
        args.plan_options.as_deref().unwrap_or("the defaults")
    );
    let _ = writeln!(
        md,
        "| N | random, median of {} (mm) | random draws (mm) | planned i (mm) | planned d (mm) |",
        args.seeds
    );
    let _ = writeln!(md, "| ---: | ---: | --- | ---: | ---: |");
    for n in [30, 50, 100] {
        let random: Vec<f64> = (1..=args.seeds)
            .map(|seed| {
                fit_and_test(&robot, &even.subset(&draw(even.rows.len(), n, seed)), &odd, &options, Method::Poe)
            })
            .collect::<Result<_>>()?;
        let mut planned = Vec::new();
        for criterion in [planning::Criterion::I, planning::Criterion::D] {
            let plan_options = planning::PlanOptions { criterion, ..plan_options(args)? };
            let order = plan_rows(&robot, &even, n, true, &plan_options)?;
            planned.push(fit_and_test(&robot, &even.subset(&order), &odd, &options, Method::Poe)?);
        }
        let _ = writeln!(
            md,
            "| {n} | {:.4} | {} | {:.4} | {:.4} |",
            median(random.clone()),
            list(&random),
            planned[0],
            planned[1]
        );
    }
    Ok(())
}

fn plan_irb4400(args: &Args, md: &mut String) -> Result<()> {
    let robot = RobotDescription::read(&args.irb4400)?;
    let ranges = campaign::joint_ranges(&robot);
    let effects = Effects { tracker_noise: Some(Default::default()), ..Effects::default() };
    let cell = campaign::simulated_cell(&robot, &Perturbation::default(), 7)?;
    let config = |rows: usize, seed: u64| GeneratorConfig {
        sample_count: rows,
        seed,
        payloads_kg: vec![0.0],
        ..GeneratorConfig::default()
    };
    let candidates = campaign::simulate(&cell, &effects, &ranges, &config(5000, 70), false)?;
    let test = campaign::simulate(&cell, &effects, &ranges, &config(5000, 71), false)?;
    let options = FitOptions::default();
    let random = |n: usize| -> Result<Vec<f64>> {
        (1..=args.seeds)
            .map(|seed| fit_and_test(&robot, &candidates.subset(&draw(5000, n, seed)), &test, &options, Method::Poe))
            .collect()
    };
    let (random_300, random_25) = (random(300)?, random(25)?);
    let _ = writeln!(
        md,
        "\n## Simulated IRB 4400, geometric errors and tracker noise only\n\n`poe` on position-only poses, tested on \
         5,000 others; candidates: 5,000 drawn poses.\n"
    );
    let _ = writeln!(md, "| poses | mean error (mm) | ratio to random 300 |");
    let _ = writeln!(md, "| --- | ---: | ---: |");
    let reference = median(random_300.clone());
    let _ = writeln!(md, "| 300 random (median of {}: {}) | {reference:.4} | 1 |", args.seeds, list(&random_300));
    let r25 = median(random_25.clone());
    let _ = writeln!(
        md,
        "| 25 random (median of {}: {}) | {r25:.4} | {:.3} |",
        args.seeds,
        list(&random_25),
        r25 / reference
    );
    for criterion in [planning::Criterion::I, planning::Criterion::D] {
        let plan_options = planning::PlanOptions { criterion, ..plan_options(args)? };
        let order = plan_rows(&robot, &candidates, 25, false, &plan_options)?;
        let planned = fit_and_test(&robot, &candidates.subset(&order), &test, &options, Method::Poe)?;
        let _ = writeln!(md, "| 25 planned ({criterion:?}) | {planned:.4} | {:.3} |", planned / reference);
    }
    Ok(())
}

fn plan_timing(args: &Args, md: &mut String) -> Result<()> {
    let _ = writeln!(
        md,
        "\n## Time to choose 100 of 10,000 candidates\n\nCandidates drawn within the joint limits \
         (`calib plan` without `--candidates`), this machine (2 cores shared with other jobs, so the wall time \
         varies; the CPU time is every thread's), rayon on every core.\n"
    );
    let _ = writeln!(md, "| robot | rows | criterion | wall (s) | CPU (s) |");
    let _ = writeln!(md, "| --- | --- | --- | ---: | ---: |");
    for (name, path) in [("UR10", &args.ur10), ("IRB 4400", &args.irb4400)] {
        let robot = RobotDescription::read(path)?;
        let set = planning::generated_candidates(&robot, None, 10_000, 0)?;
        for full_pose in [false, true] {
            for criterion in [planning::Criterion::I, planning::Criterion::D] {
                let options = planning::PlanOptions { criterion, ..plan_options(args)? };
                let (start, cpu) = (Instant::now(), super::ur10::process_cpu_seconds());
                planning::plan(&set.model, &set.candidates, 100, full_pose, &options)?;
                let _ = writeln!(
                    md,
                    "| {name} | {} | {criterion:?} | {:.2} | {:.2} |",
                    if full_pose { "full pose" } else { "position" },
                    start.elapsed().as_secs_f64(),
                    super::ur10::process_cpu_seconds() - cpu
                );
            }
        }
    }
    Ok(())
}

fn plan_effects(args: &Args, md: &mut String) -> Result<()> {
    let robot = RobotDescription::read(&args.ur10)?;
    let even = read(&robot, &args.data.join("ur10_C_full_even.csv"))?;
    let odd = read(&robot, &args.data.join("ur10_C_full_odd.csv"))?;
    let mut options = FitOptions::default();
    options.effects.selection = EffectSelection::Auto;
    let random: Vec<f64> = (1..=10)
        .map(|seed| {
            fit_and_test(&robot, &even.subset(&draw(even.rows.len(), 300, seed)), &odd, &options, Method::PoeGp)
        })
        .collect::<Result<_>>()?;
    let order = plan_rows(&robot, &even, 300, true, &plan_options(args)?)?;
    let planned = fit_and_test(&robot, &even.subset(&order), &odd, &options, Method::PoeGp)?;
    let _ = writeln!(
        md,
        "\n## UR10 C: what the effects need\n\n`poe-gp --effects auto` on 300 even rows, tested on the odd rows.\n\n\
         | poses | mean error (mm) |\n| --- | ---: |\n| 300 random, median of 10 ({}) | {:.4} |\n| 300 planned | {planned:.4} |",
        list(&random),
        median(random.clone())
    );
    Ok(())
}
