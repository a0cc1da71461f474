//! `cargo xtask blind-check`: datasets with hidden effects (or none, or one no candidate models),
//! diagnosed without the truth; per class the top-1 rate, the joints, and how far the predicted
//! shrink of the held-out error is from the true one; the confusion matrix. The classes are in
//! module `blind_check_cases`. Cases run in parallel; each is seeded on its own, so the table does
//! not depend on the order they finish in.

use super::blind_check_cases::{Case, Class, Robots, run_case};
use anyhow::{Context, Result, bail};
use diagnose::Effect;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use robot::RobotDescription;
use std::fmt::Write;
use std::path::PathBuf;

/// Diagnose simulated datasets whose hidden effect the diagnosis is not told.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of datasets; case i is of class i mod 11 (module `blind_check_cases`).
    #[arg(long, default_value_t = 100)]
    cases: usize,
    /// Seed of the whole check.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Poses per dataset.
    #[arg(long, default_value_t = 300)]
    rows: usize,
    /// Also write the report as markdown here (e.g. docs/results/blind-check.md).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Fail (non-zero exit) when the top-1 rate is below this fraction, when more than one `none`
    /// case in ten raises an alarm, or when fewer than nine coupling cases in ten say `unknown`.
    #[arg(long)]
    require_top1: Option<f64>,
    /// Run only these cases (their indices, comma separated), for a closer look.
    #[arg(long, value_delimiter = ',')]
    only: Vec<usize>,
    /// Write each case's measurements as SPEC CSV into this folder (`case<i>.csv`).
    #[arg(long)]
    dump: Option<PathBuf>,
}

/// A relative shrink error counts as right within this fraction of the true shrink.
const SHRINK_TOLERANCE: f64 = 0.2;

fn percent(a: usize, b: usize) -> String {
    if b == 0 { "–".into() } else { format!("{a}/{b} ({:.0} %)", 100.0 * a as f64 / b as f64) }
}

fn shrink_right(c: &Case) -> bool {
    (c.predicted_shrink() - c.true_shrink()).abs() <= SHRINK_TOLERANCE * c.true_shrink().abs()
}

/// The effect cases (not `none`, not coupling) whose verdict is right.
fn detected(cases: &[Case]) -> Vec<&Case> {
    cases.iter().filter(|c| !matches!(c.class, Class::None | Class::Coupling) && c.right()).collect()
}

fn report(cases: &[Case]) -> String {
    let mut out = String::new();
    summary(&mut out, cases);
    per_class(&mut out, cases);
    confusion(&mut out, cases);
    every_case(&mut out, cases);
    out
}

/// How many of `set` have the right verdict.
fn right(set: &[&Case]) -> usize {
    set.iter().filter(|c| c.right()).count()
}

/// The overall rates.
fn summary(out: &mut String, cases: &[Case]) {
    let all: Vec<&Case> = cases.iter().collect();
    let effects: Vec<&Case> = cases.iter().filter(|c| c.class != Class::None).collect();
    let strong: Vec<&Case> = effects.iter().copied().filter(|c| c.magnitude_mm >= 3.0 * c.floor_mm).collect();
    let nones: Vec<&Case> = cases.iter().filter(|c| c.class == Class::None).collect();
    let couplings: Vec<&Case> = cases.iter().filter(|c| c.class == Class::Coupling).collect();
    let found = detected(cases);
    let _ = writeln!(out, "- top-1 overall: {}", percent(right(&all), all.len()));
    let _ = writeln!(
        out,
        "- top-1 where every hidden effect is at least 3× the noise floor: {}",
        percent(right(&strong), strong.len())
    );
    let _ = writeln!(
        out,
        "- false alarms in `none` cases: {}",
        percent(nones.iter().filter(|c| c.verdict != Effect::None).count(), nones.len())
    );
    let _ = writeln!(
        out,
        "- coupling (no candidate models it) called `unknown`: {}",
        percent(right(&couplings), couplings.len())
    );
    let _ = writeln!(
        out,
        "- predicted shrink within {:.0} % of the true shrink, detected effects: {}",
        100.0 * SHRINK_TOLERANCE,
        percent(found.iter().filter(|c| shrink_right(c)).count(), found.len())
    );
}

/// The table of each class's rates.
fn per_class(out: &mut String, cases: &[Case]) {
    let _ = writeln!(out, "\n## Per class\n");
    let _ = writeln!(
        out,
        "| class | cases | top-1 | top-1, ≥ 3× floor | exact joints | both selected | shrink within 20 % | median size / floor |"
    );
    let _ = writeln!(out, "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for class in Class::ALL {
        let set: Vec<&Case> = cases.iter().filter(|c| c.class == class).collect();
        if set.is_empty() {
            continue;
        }
        let strong: Vec<&Case> = set.iter().copied().filter(|c| c.magnitude_mm >= 3.0 * c.floor_mm).collect();
        let with_joints: Vec<&Case> = set.iter().copied().filter(|c| c.right() && !c.joints.is_empty()).collect();
        let exact = with_joints.iter().filter(|c| c.verdict_joints == c.joints).count();
        let found: Vec<&Case> = set.iter().copied().filter(|c| c.right()).collect();
        let mut ratios: Vec<f64> = set.iter().map(|c| c.magnitude_mm / c.floor_mm).collect();
        ratios.sort_by(f64::total_cmp);
        let shrinks = if matches!(class, Class::None | Class::Coupling) {
            "–".to_owned()
        } else {
            percent(found.iter().filter(|c| shrink_right(c)).count(), found.len())
        };
        let both = if class == Class::TwoEffects {
            percent(set.iter().filter(|c| c.all_selected).count(), set.len())
        } else {
            "–".to_owned()
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {both} | {shrinks} | {:.1} |",
            class.name(),
            set.len(),
            percent(right(&set), set.len()),
            percent(right(&strong), strong.len()),
            percent(exact, with_joints.len()),
            ratios[ratios.len() / 2]
        );
    }
}

/// The confusion matrix of class against verdict.
fn confusion(out: &mut String, cases: &[Case]) {
    // Every verdict the diagnosis can give, from the one list of kinds: a kind added there gets
    // its column, so that no verdict is left out of the matrix unseen.
    let labels: Vec<Effect> = std::iter::once(Effect::None)
        .chain(loadsim::EffectKind::IDENTIFIED.iter().map(|&kind| Effect::from(kind)))
        .chain(std::iter::once(Effect::Unknown))
        .collect();
    let _ = writeln!(out, "\n## Confusion matrix (rows: class, columns: verdict)\n");
    let _ = write!(out, "| class \\ verdict |");
    for l in &labels {
        let _ = write!(out, " {} |", l.name());
    }
    let _ = write!(out, "\n| --- |{}\n", " ---: |".repeat(labels.len()));
    for class in Class::ALL {
        let set: Vec<&Case> = cases.iter().filter(|c| c.class == class).collect();
        if set.is_empty() {
            continue;
        }
        let _ = write!(out, "| {} |", class.name());
        for verdict in &labels {
            let _ = write!(out, " {} |", set.iter().filter(|c| c.verdict == *verdict).count());
        }
        out.push('\n');
    }
}

/// One row per case.
fn every_case(out: &mut String, cases: &[Case]) {
    let _ = writeln!(out, "\n## Every case\n");
    let _ = writeln!(
        out,
        "| case | class | data | truth | joints | size (mm) | floor (mm) | verdict | joints | before (mm) | after (mm) | true after (mm) |"
    );
    let _ = writeln!(out, "| ---: | --- | --- | --- | --- | ---: | ---: | --- | --- | ---: | ---: | ---: |");
    let list = |j: &[usize]| j.iter().map(usize::to_string).collect::<Vec<_>>().join(",");
    for (i, c) in cases.iter().enumerate() {
        let truth: Vec<&str> = c.truths.iter().map(|t| t.name()).collect();
        let _ = writeln!(
            out,
            "| {i} | {} | {} | {} | {} | {:.4} | {:.4} | {}{} | {} | {:.4} | {:.4} | {:.4} |",
            c.class.name(),
            if c.full_pose { "pose" } else { "position" },
            truth.join(" + "),
            list(&c.joints),
            c.magnitude_mm,
            c.floor_mm,
            c.verdict.name(),
            if c.right() { "" } else { " ✗" },
            list(&c.verdict_joints),
            c.before_mm,
            c.after_mm,
            c.oracle_mm
        );
    }
}

/// The robots the cases draw on, from `fixtures/robots`.
fn robots() -> Result<Robots> {
    let read = |name: &str| -> Result<RobotDescription> {
        let path = PathBuf::from("fixtures/robots").join(name);
        let robot = RobotDescription::read(&path).with_context(|| path.display().to_string())?;
        if robot.dynamics.is_none() {
            bail!("{}: the simulation needs the robot's masses and stiffness (a dynamics block)", path.display());
        }
        Ok(robot)
    };
    // The column has no masses in its file: its cases draw their own (module `blind_check_cases`).
    let column_path = PathBuf::from("fixtures/robots/column_ur10.ron");
    let column = RobotDescription::read(&column_path).with_context(|| column_path.display().to_string())?;
    Ok(Robots { irb4400: read("irb4400.ron")?, iiwa7: read("iiwa7.ron")?, column })
}

pub fn run(args: &Args) -> Result<()> {
    let robots = robots()?;
    let indices: Vec<usize> = if args.only.is_empty() { (0..args.cases).collect() } else { args.only.clone() };
    if let Some(folder) = &args.dump {
        std::fs::create_dir_all(folder).with_context(|| folder.display().to_string())?;
    }
    let bar = ProgressBar::new(indices.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message("blind-check");
    let cases: Vec<Case> = indices
        .par_iter()
        .map(|&index| {
            let case = run_case(&robots, index, args.seed, args.rows, args.dump.as_deref());
            bar.inc(1);
            case
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    let text = report(&cases);
    println!("{text}");
    if let Some(path) = &args.out {
        let body = format!(
            "# Blind check\n\n`cargo xtask blind-check --cases {} --seed {} --rows {}`: simulated data sets with hidden \
             effects, diagnosed by `calib diagnose` without the truth (the robot file without masses and stiffness). \
             Classes and how each is drawn: `xtask/src/checks/blind_check_cases.rs`. \"Size\" is what a geometric calibration \
             leaves of the hidden effect on noise-free positions; \"true after\" the geometric model's held-out error on \
             the same poses and noise without any effect; \"after\" the diagnosis's held-out error with the effects it \
             selected.\n\n{text}",
            args.cases, args.seed, args.rows
        );
        std::fs::write(path, body).with_context(|| path.display().to_string())?;
    }
    if let Some(required) = args.require_top1 {
        require(&cases, required)?;
    }
    Ok(())
}

/// `--require-top1`: the top-1 rate, the false alarms in `none` cases and the coupling cases
/// called `unknown`.
fn require(cases: &[Case], required: f64) -> Result<()> {
    let right = cases.iter().filter(|c| c.right()).count();
    let nones: Vec<&Case> = cases.iter().filter(|c| c.class == Class::None).collect();
    let alarms = nones.iter().filter(|c| c.verdict != Effect::None).count();
    let couplings: Vec<&Case> = cases.iter().filter(|c| c.class == Class::Coupling).collect();
    let unknown = couplings.iter().filter(|c| c.right()).count();
    if (right as f64) < required * cases.len() as f64 {
        bail!("top-1 {right}/{} is below the required {required}", cases.len());
    }
    if alarms as f64 > 0.1 * nones.len() as f64 {
        bail!("{alarms} false alarms in {} none cases, more than one in ten", nones.len());
    }
    if (unknown as f64) < 0.9 * couplings.len() as f64 {
        bail!("{unknown} of {} coupling cases called unknown, fewer than nine in ten", couplings.len());
    }
    Ok(())
}
