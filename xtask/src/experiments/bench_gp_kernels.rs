//! `cargo xtask bench-gp --kernels`: which kernel the GP stage should use by default. Every
//! candidate kernel on the residuals of the real UR10 series (C even → odd, B and D split the same
//! way) and of simulated soft joints with payloads (several seeds), held-out error in mm.

use anyhow::Context;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

use gp::{ExactGp, Kernel, KernelChoice, OutputMode, StationaryShape};
use indicatif::{ProgressBar, ProgressStyle};
use model::ResidualGpOptions;
use robot::RobotDescription;

use super::bench_gp_residuals::{Residuals, heldout_mm, real, simulated, simulated_payload_runs};

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
    /// Only the sets whose name contains one of these (case-sensitive), separated by `;` (set names
    /// contain commas); all when none is given. A selection that matches no set is refused.
    #[arg(long, value_delimiter = ';')]
    pub only: Vec<String>,
    /// With `--kernels`: only the candidate kernels whose name is one of these exactly; all when
    /// empty.
    #[arg(long, value_delimiter = ';')]
    pub kernel_names: Vec<String>,
    /// With `--kernels`: seeds of the hyperparameter search, one fit per seed: each draws its own
    /// warm-start subset and, above 0, moves the start by up to ±1e-3 in every log-parameter. The
    /// table gives the mean held-out error over the seeds ± half the spread (largest − smallest),
    /// which shows how much of a difference between two searches is the luck of the local optimum
    /// reached.
    #[arg(long, value_delimiter = ',', default_value = "0")]
    pub search_seeds: Vec<u64>,
    /// With `--kernels`: the search's L-BFGS memory instead of the GP stage's.
    #[arg(long)]
    pub search_memory: Option<usize>,
    /// With `--kernels`: the search's relative function tolerance instead of the GP stage's.
    #[arg(long)]
    pub search_tolerance: Option<f64>,
    /// With `--kernels`: the search's warm-start subset rows instead of the GP stage's.
    #[arg(long)]
    pub search_warm_rows: Option<usize>,
    /// With `--kernels`: whether a kernel with an additive term also fits its form without and
    /// keeps the additive term only where BIC says so (the GP stage's default: true).
    #[arg(long)]
    pub additive_by_bic: Option<bool>,
}

impl KernelArgs {
    /// The non-empty `--only` patterns (an empty one would match every set).
    fn patterns(&self) -> Vec<&str> {
        self.only.iter().map(|o| o.trim()).filter(|o| !o.is_empty()).collect()
    }

    fn wanted(&self, name: &str) -> bool {
        let patterns = self.patterns();
        patterns.is_empty() || patterns.iter().any(|o| name.contains(o))
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
pub fn data_sets(args: &KernelArgs) -> anyhow::Result<Vec<Residuals>> {
    let mut sets = Vec::new();
    let robot =
        |file: &str| RobotDescription::read(&PathBuf::from("fixtures/robots").join(file)).map_err(anyhow::Error::from);
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
    if sets.is_empty() && !args.patterns().is_empty() {
        anyhow::bail!("--only {:?} matches no data set", args.only);
    }
    Ok(sets)
}

/// The search's default start, and for `seed > 0` each log-parameter moved by up to ±1e-3 (a
/// thousandth of its value, immaterial to the model) drawn from a SplitMix64 stream: together with
/// the seed's own warm-start subset, it shows how far the held-out error depends on which of
/// several nearly equal local optima the search happens to reach. Sets no larger than the
/// warm-start subset have no subset to draw, so without it every seed would give the same fit.
fn perturbed_start(choice: KernelChoice, dim: usize, seed: u64) -> anyhow::Result<Kernel> {
    let start = Kernel::start(choice, dim);
    if seed == 0 {
        return Ok(start);
    }
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let p: Vec<f64> = start.log_parameters().iter().map(|v| v + 1e-3 * (2.0 * next() - 1.0)).collect();
    start.with_log_parameters(&p).map_err(anyhow::Error::from)
}

/// Runs every candidate on every set and returns the markdown table.
pub fn run(args: &KernelArgs) -> anyhow::Result<String> {
    let sets = data_sets(args)?;
    let kernels: Vec<_> = candidates()
        .into_iter()
        .filter(|(name, ..)| args.kernel_names.is_empty() || args.kernel_names.iter().any(|k| k == name))
        .collect();
    if kernels.is_empty() {
        anyhow::bail!("no candidate kernel is named {:?}", args.kernel_names);
    }
    let seeds = &args.search_seeds;
    if seeds.is_empty() {
        anyhow::bail!("--search-seeds is empty");
    }
    let bar = ProgressBar::new((sets.len() * kernels.len() * seeds.len()) as u64);
    bar.set_style(
        ProgressStyle::with_template("kernels {msg} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut table = vec![vec![(f64::NAN, f64::NAN, f64::NAN, f64::NAN); sets.len()]; kernels.len()];
    for (s, set) in sets.iter().enumerate() {
        for (k, candidate) in kernels.iter().enumerate() {
            table[k][s] = measure(args, set, candidate, &bar)?;
        }
    }
    bar.finish_and_clear();
    Ok(markdown(&sets, &kernels, seeds, &table))
}

/// One candidate on one set, once per search seed: (mean held-out error, spread over the seeds,
/// fit time summed over the seeds, log marginal likelihood summed over the seeds).
fn measure(
    args: &KernelArgs,
    set: &Residuals,
    (name, choice, outputs): &(&str, KernelChoice, OutputMode),
    bar: &ProgressBar,
) -> anyhow::Result<(f64, f64, f64, f64)> {
    let (mut errors, mut seconds, mut lml) = (Vec::new(), 0.0, 0.0);
    for &seed in &args.search_seeds {
        bar.set_message(format!("{} / {name} / seed {seed}", set.name));
        let mut config = ResidualGpOptions::default().gp;
        config.kernel = *choice;
        config.outputs = *outputs;
        config.optimiser.seed = seed;
        if let Some(m) = args.search_memory {
            config.optimiser.memory = m;
        }
        if let Some(t) = args.search_tolerance {
            config.optimiser.function_tolerance = t;
        }
        if let Some(r) = args.search_warm_rows {
            config.optimiser.warm_start_rows = r;
        }
        if let Some(b) = args.additive_by_bic {
            config.additive_by_bic = b;
        }
        let start = perturbed_start(*choice, set.train.inputs.ncols(), seed)?;
        let t = Instant::now();
        let model = ExactGp::fit_from(set.train.inputs.as_ref(), set.train.outputs.as_ref(), &start, &config)
            .with_context(|| format!("{} / {name}", set.name))?;
        seconds += t.elapsed().as_secs_f64();
        lml += model.log_marginal_likelihood();
        let mean = model.predict_mean(set.test.inputs.as_ref())?;
        errors.push(heldout_mm(&mean, &set.test));
        bar.inc(1);
    }
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let spread =
        errors.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b)) - errors.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    Ok((mean, spread, seconds, lml))
}

/// The table: one row per kernel, the best error of each set in bold.
fn markdown(
    sets: &[Residuals],
    kernels: &[(&str, KernelChoice, OutputMode)],
    seeds: &[u64],
    table: &[Vec<(f64, f64, f64, f64)>],
) -> String {
    let mut md = String::new();
    let _ = write!(md, "| kernel |");
    for set in sets {
        let _ = write!(md, " {} (mm) |", set.name);
    }
    let _ = writeln!(
        md,
        " mean ratio to best | fit time, sum over the sets (s, mean over the seeds) | log marginal likelihood, sum over \
         the sets (mean over the seeds) |"
    );
    let spreads = seeds.len() > 1;
    let _ = writeln!(md, "|---|{}---:|---:|---:|", "---:|".repeat(sets.len()));
    let best: Vec<f64> = (0..sets.len()).map(|s| table.iter().map(|r| r[s].0).fold(f64::INFINITY, f64::min)).collect();
    for (k, (name, _, _)) in kernels.iter().enumerate() {
        let _ = write!(md, "| {name} |");
        for (s, b) in best.iter().enumerate() {
            let (e, spread, seconds, _) = table[k][s];
            let mark = if e == *b { "**" } else { "" };
            let _ = write!(md, " {mark}{e:.4}{mark}");
            if spreads {
                let _ = write!(md, " ± {:.4}", spread / 2.0);
            }
            let _ = write!(md, " ({:.2} s) |", seconds / seeds.len() as f64);
        }
        let ratio = (0..sets.len()).map(|s| table[k][s].0 / best[s]).sum::<f64>() / sets.len() as f64;
        let time: f64 = table[k].iter().map(|c| c.2).sum::<f64>() / seeds.len() as f64;
        let lml: f64 = table[k].iter().map(|c| c.3).sum::<f64>() / seeds.len() as f64;
        let _ = writeln!(md, " {ratio:.4} | {time:.1} | {lml:.3} |");
    }
    md
}
