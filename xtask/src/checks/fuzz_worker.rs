//! The child process of `cargo xtask fuzz`: feeds one reader a range of cases and tells the parent,
//! line by line on stdout, when each starts and how it ended. A panic is caught and reported; an
//! abort, a stack overflow, an allocation beyond the parent's memory cap or a hang ends or stalls
//! this process, and the parent, which watches, records it and starts a new one after the case.
//!
//! Each accepted file is also used the way the commands use it (a robot's model built, a model's
//! poses predicted, effects simulated), so that a reader that lets through what breaks its users
//! shows up as "accepted, then failed".

use super::fuzz_inputs::{Case, generate, regressions};
use super::fuzz_seeds::{Reader, Seed, fixture_robot, seeds};
use anyhow::{Context, Result};
use campaign::{GeneratorConfig, SimulatedCell};
use effects::EffectSelection;
use measurements::{ColumnMap, Measurement, ReadOptions};
use pipeline::FitOptions;
use robot::RobotDescription;
use std::io::Write;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// Run cases `from..to` of one reader (started by `cargo xtask fuzz`; not for direct use).
#[derive(Debug, clap::Args)]
pub struct Args {
    #[arg(long, value_enum)]
    reader: Reader,
    #[arg(long)]
    seed: u64,
    #[arg(long)]
    from: u64,
    #[arg(long)]
    to: u64,
    /// Scratch folder for the input file.
    #[arg(long)]
    scratch: PathBuf,
}

/// How one case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Read, and usable.
    Accepted,
    /// Refused with the file, a line and a column inside the file.
    Refused,
    /// Refused without the file, line and column (or with a position outside the file).
    Unlocated(String),
    /// Read, then refused or wrong where a command uses it: the reader let it through.
    Late(String),
    /// The reader panicked.
    Panic(String),
}

impl Outcome {
    /// The word the protocol and the tallies use.
    pub fn kind(&self) -> &'static str {
        match self {
            Outcome::Accepted => "accepted",
            Outcome::Refused => "refused",
            Outcome::Unlocated(_) => "unlocated",
            Outcome::Late(_) => "late",
            Outcome::Panic(_) => "panic",
        }
    }

    fn message(&self) -> &str {
        match self {
            Outcome::Accepted | Outcome::Refused => "",
            Outcome::Unlocated(m) | Outcome::Late(m) | Outcome::Panic(m) => m,
        }
    }
}

static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

/// Whether `message` starts with `file:LINE:COLUMN:` (or `--columns:1:COLUMN:`), LINE and COLUMN
/// at least 1 and LINE inside `bytes`.
pub fn located(message: &str, file: &str, bytes: &[u8]) -> bool {
    let argument = message.strip_prefix("--columns").or_else(|| message.strip_prefix("--effects"));
    let Some(rest) = message.strip_prefix(file).or(argument) else {
        return false;
    };
    let mut parts = rest.splitn(4, ':');
    let (Some(""), Some(line), Some(column), Some(_)) = (parts.next(), parts.next(), parts.next(), parts.next()) else {
        return false;
    };
    let lines = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
    match (line.parse::<usize>(), column.parse::<usize>()) {
        (Ok(line), Ok(column)) => line >= 1 && column >= 1 && line <= lines,
        _ => false,
    }
}

/// What the cases of a reader are run against.
struct Bench {
    reader: Reader,
    seeds: Vec<Seed>,
    scratch: PathBuf,
    /// The robot effects files are checked against and simulated on.
    robot: RobotDescription,
    cell: SimulatedCell,
}

impl Bench {
    fn new(reader: Reader, scratch: &Path) -> Result<Self> {
        let robot = fixture_robot("irb4400.ron")?;
        let cell = SimulatedCell::new(robot.nominal_model().context("the irb4400 model")?, robot.dynamics.clone());
        Ok(Self { reader, seeds: seeds(reader, scratch)?, scratch: scratch.to_owned(), robot, cell })
    }

    /// Writes the case where the reader reads it, reads it, and uses what it read.
    fn run(&self, case: &Case) -> Result<Outcome> {
        let seed = &self.seeds[case.seed];
        let path = self.scratch.join(format!("case.{}", seed.extension));
        std::fs::write(&path, &case.bytes).with_context(|| format!("writing {}", path.display()))?;
        let file = path.display().to_string();
        let refused = |message: String| {
            if located(&message, &file, &case.bytes) { Outcome::Refused } else { Outcome::Unlocated(message) }
        };
        Ok(match self.reader {
            Reader::Csv => {
                let columns = match case.columns.as_deref().map(str::parse::<ColumnMap>).transpose() {
                    Ok(columns) => columns.unwrap_or_default(),
                    Err(e) => return Ok(refused(e.to_string())),
                };
                let options = ReadOptions { joints: seed.joints.clone(), columns, ..ReadOptions::default() };
                match measurements::read_measurements(&path, &options) {
                    Err(e) => refused(e.to_string()),
                    Ok(set) => check_rows(&set.rows),
                }
            }
            Reader::Robot => match RobotDescription::read(&path) {
                Err(e) => refused(e.to_string()),
                Ok(robot) => use_robot(&robot),
            },
            Reader::Model => match model::read_model(&path) {
                Err(e) => refused(e.to_string()),
                Ok(model) => use_model(&model),
            },
            Reader::Effects => match campaign::read_effects(&path, &self.robot) {
                Err(e) => refused(e.to_string()),
                Ok(effects) => self.use_effects(&effects),
            },
            // A command-line argument is text: clap refuses bytes that are not UTF-8 before us.
            Reader::EffectsList => match String::from_utf8_lossy(&case.bytes).parse::<EffectSelection>() {
                Err(e) => refused(e.to_string()),
                Ok(_) => Outcome::Accepted,
            },
            Reader::Options => match FitOptions::read(&path) {
                Err(e) => refused(e.to_string()),
                Ok(options) => match options.validate() {
                    Ok(()) => Outcome::Accepted,
                    Err((field, message)) => Outcome::Late(format!("{field}: {message}")),
                },
            },
        })
    }

    fn use_effects(&self, effects: &campaign::Effects) -> Outcome {
        let config = GeneratorConfig { sample_count: 3, ..GeneratorConfig::default() };
        match campaign::simulate(&self.cell, effects, &campaign::joint_ranges(&self.robot), &config, true) {
            Err(e) => Outcome::Late(e.to_string()),
            Ok(set) => check_rows(&set.rows),
        }
    }
}

/// Every number of every row finite: what was accepted is usable.
fn check_rows(rows: &[Measurement]) -> Outcome {
    for row in rows {
        let numbers = row.q.iter().chain(row.position.iter()).chain(row.torques_nm.iter().flatten());
        let finite = numbers.chain([&row.payload_kg]).all(|v| v.is_finite())
            && row.orientation.is_none_or(|o| o.matrix().iter().all(|v| v.is_finite()));
        if !finite || row.payload_kg < 0.0 {
            return Outcome::Late(format!("row at line {} accepted with a non-finite value: {row:?}", row.line));
        }
    }
    Outcome::Accepted
}

/// The robot's nominal model, its limits and its forward kinematics at a few configurations.
fn use_robot(robot: &RobotDescription) -> Outcome {
    let model = match robot.nominal_model() {
        Ok(model) => model,
        Err(e) => return Outcome::Late(e.to_string()),
    };
    let ranges = campaign::joint_ranges(robot);
    for k in 0..3 {
        let q: Vec<f64> =
            ranges.iter().map(|r| r.lower_rad + (r.upper_rad - r.lower_rad) * (k as f64 + 0.5) / 3.0).collect();
        match model.forward(&q, 0) {
            Ok(pose) if pose.translation().iter().all(|v| v.is_finite()) => {}
            Ok(pose) => return Outcome::Late(format!("non-finite forward kinematics {pose:?} at q = {q:?}")),
            Err(e) => return Outcome::Late(e.to_string()),
        }
    }
    Outcome::Accepted
}

/// The model's predictions at a few configurations, every tool, with a payload.
fn use_model(model: &model::CalibratedModel) -> Outcome {
    let n = model.joint_count();
    let tools = model.kinematics.tool_count();
    let rows: Vec<Measurement> = (0..4)
        .map(|k| Measurement {
            line: k + 2,
            tool: k as usize % tools.max(1),
            payload_kg: 2.0,
            temp_c: Some(20.0),
            t_s: Some(k as f64),
            ..Measurement::at(
                (0..n).map(|j| 0.1 * (k as f64 + 1.0) * ((j % 3) as f64 - 1.0)).collect(),
                lie::Vector3::zeros(),
            )
        })
        .collect();
    match model.predict(&measurements::BoundSet::made_for_model("the fuzz rows", rows)) {
        Err(e) => Outcome::Late(e.to_string()),
        Ok(poses) if poses.iter().all(|p| p.pose.translation().iter().all(|v| v.is_finite())) => Outcome::Accepted,
        Ok(poses) => Outcome::Late(format!("non-finite prediction {:?}", poses[0].pose)),
    }
}

/// The process's peak resident memory, kB (`VmHWM`), where Linux tells it.
fn peak_kb() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let line = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap_or("");
    line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or(0)
}

/// One line of the protocol, flushed at once (the parent times the case from its `start`).
fn say(out: &mut impl Write, line: &str) -> Result<()> {
    writeln!(out, "{line}")?;
    out.flush().context("writing to the parent")
}

pub fn run(args: &Args) -> Result<()> {
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut last) = LAST_PANIC.lock() {
            *last = Some(info.to_string());
        }
    }));
    let bench = Bench::new(args.reader, &args.scratch)?;
    let regressions = regressions(&bench.seeds, args.reader);
    let mut out = std::io::stdout().lock();
    say(&mut out, "ready")?;
    for number in args.from..args.to {
        let case = generate(&bench.seeds, &regressions, args.reader, args.seed, number);
        say(&mut out, &format!("start {number}"))?;
        let started = Instant::now();
        let outcome = match catch_unwind(AssertUnwindSafe(|| bench.run(&case))) {
            Ok(outcome) => outcome?,
            Err(_) => {
                let message = LAST_PANIC.lock().ok().and_then(|mut m| m.take());
                Outcome::Panic(message.unwrap_or_else(|| "a panic without a message".into()))
            }
        };
        let micros = started.elapsed().as_micros();
        let message = outcome.message().replace(['\n', '\r'], " ");
        say(&mut out, &format!("done {number} {} {micros} {message}", outcome.kind()))?;
    }
    say(&mut out, &format!("peak {}", peak_kb()))
}

#[cfg(test)]
mod tests {
    use super::located;

    #[test]
    fn a_refusal_is_located_only_with_a_line_inside_the_file_and_a_column() {
        let bytes = b"a\nb\n";
        assert!(located("/t/case.csv:3:1: missing", "/t/case.csv", bytes));
        assert!(located("--columns:1:8: 'x' is not", "/t/case.csv", bytes));
        assert!(!located("/t/case.csv:4:1: beyond the end", "/t/case.csv", bytes));
        assert!(!located("/t/case.csv:0:1: line 0", "/t/case.csv", bytes));
        assert!(!located("/t/case.csv: no position", "/t/case.csv", bytes));
        assert!(!located("load model: joint 9", "/t/case.csv", bytes));
    }
}
