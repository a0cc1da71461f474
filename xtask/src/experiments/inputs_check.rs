//! `cargo xtask inputs-check`: measured signals as inputs of the GP, on simulated days
//! whose error follows them. A base that tilts with the arm's gravity moment and with the floor
//! under it (each day's placement tilts it anew), read by an inclinometer with its own noise
//! (`loadsim::BaseTilt`), and thermal growth of the links with a temperature that drifts through
//! each day (`loadsim::ThermalModel`, `temp_c`), beside the tracker's noise. `poe-gp` sees only
//! the joints; `poe-gp --inputs tilt_x_mrad,tilt_y_mrad,temp_c` sees the signals too; the
//! same residuals go to scikit-learn's ARD GP with the same inputs. Held out: every other row
//! (even → odd) and the last day (trained on the others). The noise floor is the mean distance of
//! the measured test positions from the same poses simulated without tracker noise.

use super::bench_gp_residuals::heldout_mm;
use super::bench_gp_sklearn::{self, SklearnOptions};
use anyhow::Context;
use campaign::{Effects, GeneratorConfig, Perturbation, SimulatedCell, TrackerNoiseModel};
use lie::{SE3, Vector3};
use loadsim::{BaseTilt, Payload, ThermalModel};
use measurements::{Inputs, MeasurementSet};
use model::{CalibratedModel, Method, ResidualFrame, ResidualSet};
use pipeline::FitOptions;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot::RobotDescription;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

/// Measured signals as GP inputs on simulated days whose error follows them.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Robot description.
    #[arg(long, default_value = "fixtures/robots/irb4400.ron")]
    robot: PathBuf,
    /// Measuring days (each a new placement of the base, a new temperature profile).
    #[arg(long, default_value_t = 4)]
    days: usize,
    /// Poses measured per day.
    #[arg(long, default_value_t = 150)]
    poses_per_day: usize,
    /// Seed of the cell, the days and the noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The mount's compliance about the horizontal axes, rad/(N·m).
    #[arg(long, default_value_t = BaseTilt::default().compliance_rad_per_nm)]
    compliance: f64,
    /// Largest tilt of the floor under each day's placement, per horizontal axis, rad.
    #[arg(long, default_value_t = 2e-4)]
    floor_tilt: f64,
    /// Write the markdown here as well as to stdout.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the simulated days as SPEC CSV into this folder (`days.csv`, and `even.csv`/`odd.csv`,
    /// `first_days.csv`/`last_day.csv`), for the `calib` command line.
    #[arg(long)]
    dump: Option<PathBuf>,
    /// Leave scikit-learn out.
    #[arg(long)]
    no_sklearn: bool,
}

/// The signal columns the simulation writes.
const SIGNALS: [&str; 3] = ["tilt_x_mrad", "tilt_y_mrad", "temp_c"];

/// The simulated days: measured rows and the same poses without tracker noise.
struct Days {
    measured: MeasurementSet,
    noiseless: MeasurementSet,
    /// Each row's day, 0-based.
    day: Vec<usize>,
}

/// The days of one cell: each drawn by the generator with its own seed and temperature profile,
/// then tilted about the base origin by the gravity moment and the day's floor, the inclinometer
/// reading that tilt with its noise; `t_s` counts from the first day's start.
fn simulate_days(robot: &RobotDescription, args: &Args, tilt: &BaseTilt) -> anyhow::Result<Days> {
    let cell: SimulatedCell = campaign::simulated_cell(robot, &Perturbation::default(), args.seed)?;
    let dynamics = cell.dynamics.clone().context("the robot file has no masses: the base tilt needs them")?;
    let thermal = Some(ThermalModel::default());
    let noisy =
        Effects { tracker_noise: Some(TrackerNoiseModel::default()), thermal: thermal.clone(), ..Effects::default() };
    let quiet = Effects { thermal, ..Effects::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let names: Arc<[String]> = SIGNALS.iter().map(|s| (*s).to_owned()).collect();
    let mut measured = Vec::new();
    let mut noiseless = Vec::new();
    let mut day_of = Vec::new();
    for day in 0..args.days {
        let config = GeneratorConfig {
            sample_count: args.poses_per_day,
            seed: args.seed * 1000 + day as u64,
            payloads_kg: vec![0.0],
            temperature: loadsim::TemperatureProfile {
                start_c: 17.0 + 2.0 * day as f64,
                rise_c: 4.0,
                time_constant_s: 7200.0,
            },
            ..GeneratorConfig::default()
        };
        let ranges = campaign::joint_ranges(robot);
        let with_noise = campaign::simulate(&cell, &noisy, &ranges, &config, false)?;
        let without = campaign::simulate(&cell, &quiet, &ranges, &config, false)?;
        let floor = Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 0.0) * args.floor_tilt;
        for (a, b) in with_noise.rows.into_iter().zip(without.rows) {
            let payload = Payload::at_tool(a.payload_kg);
            let theta = tilt.tilt(&cell.robot, &dynamics, &a.q, cell.tool, &payload)? + floor;
            let turn = cell.tracker_from_base
                * SE3::new(BaseTilt::rotation(&theta), Vector3::zeros())
                * cell.tracker_from_base.inverse();
            let mut read = |k: usize| 1e3 * (theta[k] + tilt.inclinometer_noise_rad * gaussian(&mut rng));
            let temp = a.temp_c.unwrap_or(20.0);
            let inputs = Inputs::new(names.clone(), vec![read(0), read(1), temp]);
            let t_s = a.t_s.map(|t| t + day as f64 * 86_400.0);
            let line = measured.len() as u64 + 2;
            measured.push(measurements::Measurement {
                line,
                position: turn.transform_point(&a.position),
                t_s,
                inputs: inputs.clone(),
                ..a
            });
            noiseless.push(measurements::Measurement {
                line,
                position: turn.transform_point(&b.position),
                t_s,
                inputs,
                ..b
            });
            day_of.push(day);
        }
    }
    let set = |rows| MeasurementSet::from_rows("simulated days", rows, Vec::new());
    Ok(Days { measured: set(measured), noiseless: set(noiseless), day: day_of })
}

/// A standard normal draw.
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(rand_distr::StandardNormal)
}

/// Mean position error of `model` on `test`, mm.
fn heldout(model: &CalibratedModel, test: &MeasurementSet) -> anyhow::Result<f64> {
    Ok(model::evaluate(model, &model.bind(test)?)?.summary.mean_position_error_mm)
}

/// One held-out split's numbers.
struct Row {
    split: &'static str,
    floor_mm: f64,
    poe_mm: f64,
    gp_mm: f64,
    gp_inputs_mm: f64,
    sklearn_mm: Option<f64>,
    calib_on_residuals_mm: f64,
}

fn split(
    name: &'static str,
    robot: &RobotDescription,
    days: &Days,
    train: &[usize],
    test: &[usize],
    sklearn: bool,
) -> anyhow::Result<Row> {
    let (train_set, test_set) = (days.measured.subset(train), days.measured.subset(test));
    let floor_mm =
        test.iter().map(|&i| (days.measured.rows[i].position - days.noiseless.rows[i].position).norm()).sum::<f64>()
            * 1e3
            / test.len().max(1) as f64;
    let plain = FitOptions::default();
    let mut with_inputs = FitOptions::default();
    with_inputs.residual_gp.inputs = SIGNALS.iter().map(|s| (*s).to_owned()).collect();
    eprintln!("{name}: poe");
    let (poe, _) = pipeline::fit(robot, &train_set, Method::Poe, &plain)?;
    eprintln!("{name}: poe-gp");
    let (gp, _) = pipeline::fit(robot, &train_set, Method::PoeGp, &plain)?;
    eprintln!("{name}: poe-gp --inputs {}", SIGNALS.join(","));
    let (gp_inputs, _) = pipeline::fit(robot, &train_set, Method::PoeGp, &with_inputs)?;
    // The same residuals (what `poe` leaves) with the same inputs: `gp`'s exact GP as the fit
    // configures it, and scikit-learn's ARD GP.
    let residuals = |data: &MeasurementSet| -> anyhow::Result<ResidualSet> {
        let poses = poe.geometric_poses(&poe.bind(data)?)?;
        Ok(ResidualSet::with_inputs(&poses, data, false, &with_inputs.residual_gp.inputs, ResidualFrame::ToolPoint)?)
    };
    let (r_train, r_test) = (residuals(&train_set)?, residuals(&test_set)?);
    let exact = gp::ExactGp::fit(r_train.inputs.as_ref(), r_train.outputs.as_ref(), &with_inputs.residual_gp.gp)?;
    let calib_on_residuals_mm = heldout_mm(&exact.predict(r_test.inputs.as_ref())?.mean, &r_test);
    let sklearn_mm = if sklearn {
        eprintln!("{name}: scikit-learn");
        let options = SklearnOptions {
            linear: false,
            isotropic: false,
            restarts: 0,
            independent: true,
            processes: 1,
            timeout: Duration::from_secs(3600),
        };
        bench_gp_sklearn::fit_predict(&r_train.inputs, &r_train.outputs, &r_test.inputs, &options)?
            .map(|r| heldout_mm(&r.mean, &r_test))
    } else {
        None
    };
    Ok(Row {
        split: name,
        floor_mm,
        poe_mm: heldout(&poe, &test_set)?,
        gp_mm: heldout(&gp, &test_set)?,
        gp_inputs_mm: heldout(&gp_inputs, &test_set)?,
        sklearn_mm,
        calib_on_residuals_mm,
    })
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = RobotDescription::read(&args.robot)?;
    let tilt = BaseTilt { compliance_rad_per_nm: args.compliance, ..BaseTilt::default() };
    let days = simulate_days(&robot, args, &tilt)?;
    let n = days.measured.rows.len();
    let even: Vec<usize> = (0..n).step_by(2).collect();
    let odd: Vec<usize> = (1..n).step_by(2).collect();
    let last = args.days.saturating_sub(1);
    let first_days: Vec<usize> = (0..n).filter(|&i| days.day[i] < last).collect();
    let last_day: Vec<usize> = (0..n).filter(|&i| days.day[i] == last).collect();
    if let Some(dir) = &args.dump {
        let all: Vec<usize> = (0..n).collect();
        let splits =
            [("days", &all), ("even", &even), ("odd", &odd), ("first_days", &first_days), ("last_day", &last_day)];
        dump(dir, &days, &splits)?;
    }
    let sklearn = !args.no_sklearn && bench_gp_sklearn::available();
    let rows = [
        split("even → odd rows", &robot, &days, &even, &odd, sklearn)?,
        split("days 1–3 → day 4", &robot, &days, &first_days, &last_day, sklearn)?,
    ];
    let out = markdown(args, &days, &tilt, &rows);
    print!("{out}");
    if let Some(path) = &args.out {
        std::fs::write(path, &out).with_context(|| path.display().to_string())?;
    }
    Ok(())
}

/// Every row, the rows of each split and of each day as SPEC CSVs in `dir`.
fn dump(dir: &Path, days: &Days, splits: &[(&str, &Vec<usize>)]) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
    for (name, rows) in splits {
        let path = dir.join(format!("{name}.csv"));
        let mut text = Vec::new();
        days.measured.subset(rows).write_csv(&mut text)?;
        std::fs::write(&path, text).with_context(|| path.display().to_string())?;
    }
    Ok(())
}

/// The command, the signals' spans, and one table row per split.
fn markdown(args: &Args, days: &Days, tilt: &BaseTilt, rows: &[Row]) -> String {
    let n = days.measured.rows.len();
    let span = |k: usize| {
        let values = days.measured.rows.iter().map(|r| r.inputs.values()[k]);
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        format!("{lo:.3} … {hi:.3}")
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "`cargo xtask inputs-check --robot {} --days {} --poses-per-day {} --seed {} --compliance {:e} --floor-tilt {:e}`\n",
        args.robot.display(),
        args.days,
        args.poses_per_day,
        args.seed,
        args.compliance,
        args.floor_tilt
    );
    let _ = writeln!(
        out,
        "{n} rows; signals over all days: tilt_x {} mrad, tilt_y {} mrad, temp_c {} °C; inclinometer noise {} µrad.\n",
        span(0),
        span(1),
        span(2),
        tilt.inclinometer_noise_rad * 1e6
    );
    out.push_str(
        "| held out | noise floor | poe | poe-gp | poe-gp --inputs | ratio to floor (poe-gp / with inputs) | gp ExactGp on poe residuals, same inputs | scikit-learn ARD, same residuals and inputs |\n",
    );
    out.push_str("|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let sk = r.sklearn_mm.map_or("–".to_owned(), |v| format!("{v:.4}"));
        let _ = writeln!(
            out,
            "| {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2}× / {:.2}× | {:.4} | {sk} |",
            r.split,
            r.floor_mm,
            r.poe_mm,
            r.gp_mm,
            r.gp_inputs_mm,
            r.gp_mm / r.floor_mm,
            r.gp_inputs_mm / r.floor_mm,
            r.calib_on_residuals_mm
        );
    }
    out
}
