//! `cargo xtask bench-gp --kernels`: which kernel the GP stage should use by default. Every
//! candidate kernel on the residuals of the real UR10 series (C even → odd, B and D split the same
//! way) and of simulated soft joints with payloads (several seeds), held-out error in mm.

use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

use gp::{ExactGp, KernelChoice, OutputMode, StationaryShape};
use indicatif::{ProgressBar, ProgressStyle};
use pipeline::{CompensationOptions, RobotDescription};

use crate::bench_gp_residuals::{Residuals, heldout_mm, real, simulated, simulated_payload_runs};

/// Where the data are.
#[derive(Debug, Clone, clap::Args)]
pub struct KernelArgs {
    /// Folder with `ur10_C_even.csv`, `ur10_C_odd.csv`, `ur10_B.csv`, `ur10_D.csv` (SPEC CSV from
    /// `cargo xtask convert-ur10`); real data are skipped when it does not exist.
    #[arg(long, default_value = "../shared/data/ipa-ur10")]
    pub ur10_data: PathBuf,
    /// Seeds of the simulated sets (IRB 4400, a payload drawn per pose; 300 poses to train on, the
    /// next 1000 to test).
    #[arg(long, value_delimiter = ',', default_value = "1,2,3")]
    pub seeds: Vec<u64>,
    /// Seeds of the simulated 7-axis payload-run sets (iiwa 7, joints 1 and 2 moving, four payload
    /// runs with a tool each; 300 poses to train on, 1000 to test, interleaved).
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub payload_run_seeds: Vec<u64>,
    /// Only the sets whose name contains one of these (case-sensitive); all when empty.
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// With `--kernels`: only the candidate kernels whose name is one of these exactly; all when
    /// empty.
    #[arg(long, value_delimiter = ';')]
    pub kernel_names: Vec<String>,
}

impl KernelArgs {
    fn wanted(&self, name: &str) -> bool {
        self.only.is_empty() || self.only.iter().any(|o| name.contains(o.as_str()))
    }
}

/// The candidates, by name.
pub fn candidates() -> Vec<(&'static str, KernelChoice, OutputMode)> {
    use StationaryShape::{Matern52, SquaredExponential};
    let composite = |shape, constant, linear| KernelChoice::Composite { shape, constant, linear, additive: false };
    let additive = |shape, constant, linear| KernelChoice::Composite { shape, constant, linear, additive: true };
    vec![
        ("Eq. 5 (paper, isotropic)", KernelChoice::Quadratic, OutputMode::Shared),
        ("SE-ARD", KernelChoice::SquaredExponentialArd, OutputMode::Shared),
        ("SE-ARD, independent outputs", KernelChoice::SquaredExponentialArd, OutputMode::Independent),
        ("SE-ARD + const", composite(SquaredExponential, true, false), OutputMode::Shared),
        ("SE-ARD + const + linear-ARD", composite(SquaredExponential, true, true), OutputMode::Shared),
        (
            "SE-ARD + const + linear-ARD, independent outputs",
            composite(SquaredExponential, true, true),
            OutputMode::Independent,
        ),
        ("Matérn52-ARD", KernelChoice::Matern52Ard, OutputMode::Shared),
        ("Matérn52-ARD + const", composite(Matern52, true, false), OutputMode::Shared),
        ("Matérn52-ARD + const + linear-ARD", composite(Matern52, true, true), OutputMode::Shared),
        (
            "Matérn52-ARD + const + linear-ARD, independent outputs",
            composite(Matern52, true, true),
            OutputMode::Independent,
        ),
        ("SE-ARD + additive SE", additive(SquaredExponential, false, false), OutputMode::Shared),
        (
            "SE-ARD + additive SE, independent outputs",
            additive(SquaredExponential, false, false),
            OutputMode::Independent,
        ),
        (
            "SE-ARD + const + linear-ARD + additive SE, independent outputs",
            additive(SquaredExponential, true, true),
            OutputMode::Independent,
        ),
        (
            "Matérn52-ARD + additive Matérn52, independent outputs",
            additive(Matern52, false, false),
            OutputMode::Independent,
        ),
    ]
}

/// Every data set this machine has.
pub fn data_sets(args: &KernelArgs) -> Result<Vec<Residuals>, String> {
    let mut sets = Vec::new();
    let robot =
        |file: &str| RobotDescription::read(&PathBuf::from("fixtures/robots").join(file)).map_err(|e| e.to_string());
    if args.ur10_data.join("ur10_C_even.csv").exists() {
        let ur10 = robot("ur10.ron")?;
        let d = &args.ur10_data;
        let name = "UR10 C even → odd";
        if args.wanted(name) {
            sets.push(real(name, &ur10, &d.join("ur10_C_even.csv"), Some(&d.join("ur10_C_odd.csv")))?);
        }
        for series in ["B", "D"] {
            let file = d.join(format!("ur10_{series}.csv"));
            let name = format!("UR10 {series} even → odd");
            if file.exists() && args.wanted(&name) {
                sets.push(real(&name, &ur10, &file, None)?);
            }
        }
    } else {
        eprintln!("{}: no UR10 data, real sets skipped", args.ur10_data.display());
    }
    let irb = robot("irb4400.ron")?;
    for &seed in &args.seeds {
        let set = simulated(&irb, seed, 300, 1000)?;
        if args.wanted(&set.name) {
            sets.push(set);
        }
    }
    let iiwa = robot("iiwa7.ron")?;
    for &seed in &args.payload_run_seeds {
        let set = simulated_payload_runs(&iiwa, seed, 300, 1000)?;
        if args.wanted(&set.name) {
            sets.push(set);
        }
    }
    Ok(sets)
}

/// Runs every candidate on every set and returns the markdown table.
pub fn run(args: &KernelArgs) -> Result<String, String> {
    let sets = data_sets(args)?;
    let kernels: Vec<_> = candidates()
        .into_iter()
        .filter(|(name, ..)| args.kernel_names.is_empty() || args.kernel_names.iter().any(|k| k == name))
        .collect();
    if kernels.is_empty() {
        return Err(format!("no candidate kernel is named {:?}", args.kernel_names));
    }
    let bar = ProgressBar::new((sets.len() * kernels.len()) as u64);
    bar.set_style(
        ProgressStyle::with_template("kernels {msg} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut table = vec![vec![(f64::NAN, f64::NAN); sets.len()]; kernels.len()];
    for (s, set) in sets.iter().enumerate() {
        for (k, (name, choice, outputs)) in kernels.iter().enumerate() {
            bar.set_message(format!("{} / {name}", set.name));
            let mut config = CompensationOptions::default().gp;
            config.kernel = *choice;
            config.outputs = *outputs;
            let t = Instant::now();
            let model = ExactGp::fit(set.train.inputs.as_ref(), set.train.outputs.as_ref(), &config)
                .map_err(|e| format!("{} / {name}: {e}", set.name))?;
            let seconds = t.elapsed().as_secs_f64();
            let mean = model.predict_mean(set.test.inputs.as_ref()).map_err(|e| e.to_string())?;
            table[k][s] = (heldout_mm(&mean, &set.test), seconds);
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let mut md = String::new();
    let _ = write!(md, "| kernel |");
    for set in &sets {
        let _ = write!(md, " {} (mm) |", set.name);
    }
    let _ = writeln!(md, " mean ratio to best | fit time, sum (s) |");
    let _ = writeln!(md, "|---|{}---:|---:|", "---:|".repeat(sets.len()));
    let best: Vec<f64> = (0..sets.len()).map(|s| table.iter().map(|r| r[s].0).fold(f64::INFINITY, f64::min)).collect();
    for (k, (name, _, _)) in kernels.iter().enumerate() {
        let _ = write!(md, "| {name} |");
        for (s, b) in best.iter().enumerate() {
            let (e, _) = table[k][s];
            let mark = if e == *b { "**" } else { "" };
            let _ = write!(md, " {mark}{e:.4}{mark} |");
        }
        let ratio = (0..sets.len()).map(|s| table[k][s].0 / best[s]).sum::<f64>() / sets.len() as f64;
        let time: f64 = table[k].iter().map(|c| c.1).sum();
        let _ = writeln!(md, " {ratio:.4} | {time:.1} |");
    }
    Ok(md)
}
