//! `cargo xtask bench-gp`: the `gp` crate's benchmarks (markdown on stdout).
//!
//! By default the sweep of `bench_gp_sweep`: `calib fit --method poe-gp-load` with `--gp exact` and
//! `--gp sparse` on n = 300 … 100,000 simulated poses, run as child processes (wall clock and peak
//! resident memory), held-out error on the same 3,000 poses, scikit-learn on the same residuals in
//! the same run, the log–log slopes, and an SVG plot beside `--out`. The flags pick the other
//! benches instead: `--synthetic` the older table of the exact GP on synthetic robot-like data
//! (d = 7, six outputs, beside scikit-learn via `xtask/scripts/bench_gp_sklearn.py`, the machine's
//! peak GFLOP/s from a faer matrix product, the sparse GP against the exact one), `--compare` and
//! `--kernels` the real and simulated residual sets of `bench_gp_kernels`, `--paper` the paper's
//! setting and the UR10 against scikit-learn (`bench_gp_paper`), `--lml-floor N` one
//! evaluation against the n³ flop floor.

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use gp::{ExactGp, GpConfig, Kernel, KernelChoice, OptimiserConfig, OutputMode, Parallelism, PredictOptions};
use gp_sparse::{SparseConfig, SparseGp};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Arguments of `cargo xtask bench-gp`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sizes 100 and 300 only, and the sparse comparison at n = 1000.
    #[arg(long)]
    quick: bool,
    /// Random restarts of the hyperparameter search, for both gp and scikit-learn.
    #[arg(long, default_value_t = 2)]
    restarts: usize,
    /// Largest n at which scikit-learn is run (its fit at n = 3000 would take most of an hour on 2
    /// cores).
    #[arg(long, default_value_t = 1000)]
    sklearn_max_n: usize,
    /// Also write the table to this file.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Compare the GP stage with scikit-learn on real and simulated residuals instead.
    #[arg(long)]
    compare: bool,
    /// Compare the candidate kernels on real and simulated residuals instead.
    #[arg(long)]
    kernels: bool,
    /// The paper's setting and the UR10 against scikit-learn instead (`bench_gp_paper`): simulated
    /// campaigns of the paper's shape against its isotropic Eq. 5 kernel, the UR10 series C
    /// (position only and full pose, from `--ur10-data`) against the ARD GP.
    #[arg(long)]
    paper: bool,
    #[command(flatten)]
    paper_args: super::bench_gp_paper::PaperArgs,
    /// Write the residual sets of `--kernels`/`--compare` to this folder as CSV (`NAME.train.csv`,
    /// `NAME.test.csv`: inputs, then outputs) instead, for other tools to read.
    #[arg(long)]
    dump_residuals: Option<PathBuf>,
    /// Time one log marginal likelihood with its gradient at this n (SE-ARD, one output) against
    /// the n³-flop floor measured with faer's matrix product at the same n, instead.
    #[arg(long)]
    lml_floor: Option<usize>,
    #[command(flatten)]
    kernel_args: super::bench_gp_kernels::KernelArgs,
    /// The older table instead of the sweep: exact GP fit and predict on synthetic robot-like data
    /// (Eq. 5 kernel, shared outputs), n = 100 … 3000, beside scikit-learn.
    #[arg(long)]
    synthetic: bool,
    #[command(flatten)]
    sweep: super::bench_gp_sweep::SweepArgs,
}

/// One LML + gradient evaluation at `n` against the time faer's own n × n matrix product takes for
/// n³ flops (half of its 2n³), both on the rayon pool and serially.
///
/// The evaluation is timed twice: in a workspace kept from the previous evaluation (as the
/// hyperparameter search runs it) and with fresh buffers (`gp::log_marginal_likelihood`, which pays
/// the page faults of 144 MB at n = 3,000). Other jobs share the machine, so each of the seven
/// rounds times the product and both evaluations back to back and the best of each is kept: a
/// floor measured minutes apart from the evaluation would compare two different machines.
fn lml_floor(n: usize) -> anyhow::Result<String> {
    const ROUNDS: usize = 7;
    let d = data(n, 2024);
    let kernel = Kernel::start(KernelChoice::SquaredExponentialArd, DIM);
    let y = Mat::from_fn(n, 1, |i, _| d.y[(i, 0)]);
    let a = Mat::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
    let b = Mat::from_fn(n, n, |i, j| ((i * 5 + j) % 13) as f64 - 6.0);
    let mut c = Mat::<f64>::zeros(n, n);
    let mut md = format!(
        "| n = {n} | LML + gradient, reused workspace (s) | fresh buffers (s) | n³ flops at faer's matmul rate (s) | \
         ratio, reused | ratio, fresh |\n|---|---:|---:|---:|---:|---:|\n"
    );
    for (name, parallelism, par) in
        [("rayon", Parallelism::Rayon, Par::rayon(0)), ("serial", Parallelism::Sequential, Par::Seq)]
    {
        let mut workspace = gp::LmlWorkspace::default();
        let evaluate = |w: &mut gp::LmlWorkspace| {
            w.log_marginal_likelihood(&kernel, d.x.as_ref(), y.as_ref(), true, parallelism)
                .with_context(|| format!("LML at n = {n}"))
        };
        evaluate(&mut workspace)?;
        let (mut reused, mut fresh, mut product) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for _ in 0..ROUNDS {
            let t = Instant::now();
            matmul(c.as_mut(), Accum::Replace, a.as_ref(), b.as_ref(), 1.0, par);
            product = product.min(t.elapsed().as_secs_f64());
            let t = Instant::now();
            evaluate(&mut workspace)?;
            reused = reused.min(t.elapsed().as_secs_f64());
            let t = Instant::now();
            evaluate(&mut gp::LmlWorkspace::default())?;
            fresh = fresh.min(t.elapsed().as_secs_f64());
        }
        let floor = product / 2.0;
        md.push_str(&format!(
            "| {name} | {reused:.3} | {fresh:.3} | {floor:.3} | {:.2}× | {:.2}× |\n",
            reused / floor,
            fresh / floor
        ));
    }
    Ok(md)
}

const DIM: usize = 7;
const OUTPUTS: usize = 6;
const TEST_POINTS: usize = 1000;
const NOISE: f64 = 0.02;

/// Smooth, load-dependent error of a six-joint arm (six outputs), the shape of what the paper's GP
/// models: sums of sines of the joint angles scaled by the payload.
fn truth(x: &[f64], k: usize) -> f64 {
    let q = &x[..6];
    let payload = x[6];
    let phase = k as f64 * 0.7;
    let gravity = (q[1] + phase).sin() + 0.5 * (q[1] + q[2]).sin() * (1.0 + 0.1 * payload);
    let periodic = 0.3 * (2.0 * q[0] + phase).cos() + 0.2 * (q[3] - q[4] + 0.5 * q[5]).sin();
    gravity + periodic
}

struct Data {
    x: Mat<f64>,
    y: Mat<f64>,
    x_test: Mat<f64>,
    y_test_clean: Mat<f64>,
}

fn data(n: usize, seed: u64) -> Data {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let payloads = [1.0, 2.5, 3.5, 5.0, 7.5];
    let draw = |rows: usize, rng: &mut ChaCha8Rng| {
        Mat::from_fn(rows, DIM, |_, j| {
            if j < 6 { rng.random_range(-2.5..2.5) } else { payloads[rng.random_range(0..payloads.len())] }
        })
    };
    let x = draw(n, &mut rng);
    let x_test = draw(TEST_POINTS, &mut rng);
    let row = |m: &Mat<f64>, i: usize| (0..DIM).map(|j| m[(i, j)]).collect::<Vec<_>>();
    let y = Mat::from_fn(n, OUTPUTS, |i, k| truth(&row(&x, i), k) + NOISE * (rng.random::<f64>() * 2.0 - 1.0) * 1.7);
    let y_test_clean = Mat::from_fn(TEST_POINTS, OUTPUTS, |i, k| truth(&row(&x_test, i), k));
    Data { x, y, x_test, y_test_clean }
}

fn rows(m: &Mat<f64>, n: usize) -> Vec<Vec<f64>> {
    (0..n).map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect()).collect()
}

fn rmse(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    let mut s = 0.0;
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            s += (a[(i, j)] - b[(i, j)]).powi(2);
        }
    }
    (s / (a.nrows() * a.ncols()) as f64).sqrt()
}

/// Best of `repeats` wall-clock times of `f`, in seconds.
fn best_of(repeats: usize, mut f: impl FnMut()) -> f64 {
    (0..repeats)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Least-squares slope of ln t against ln n.
fn log_log_slope(points: &[(usize, f64)]) -> f64 {
    let xs: Vec<f64> = points.iter().map(|(n, _)| (*n as f64).ln()).collect();
    let ys: Vec<f64> = points.iter().map(|(_, t)| t.ln()).collect();
    let k = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / k, ys.iter().sum::<f64>() / k);
    let cov: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let var: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    cov / var
}

/// GFLOP/s of a square faer matrix product (2n³ flops), best of three.
fn peak_gflops(n: usize, par: Par) -> f64 {
    let a = Mat::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
    let b = Mat::from_fn(n, n, |i, j| ((i * 5 + j) % 13) as f64 - 6.0);
    let mut c = Mat::<f64>::zeros(n, n);
    let t = best_of(3, || matmul(c.as_mut(), Accum::Replace, a.as_ref(), b.as_ref(), 1.0, par));
    2.0 * (n as f64).powi(3) / t / 1e9
}

/// GFLOP/s of the Cholesky factorisation of an n × n kernel matrix (n³/3 flops), best of three,
/// through the same faer routine the crate uses.
fn cholesky_gflops(x: &Mat<f64>, n: usize, par: Par) -> anyhow::Result<f64> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::cholesky::llt;
    let kernel = Kernel::start(KernelChoice::SquaredExponentialArd, DIM);
    let rows: Vec<Vec<f64>> = rows(x, n);
    let k = Mat::from_fn(n, n, |i, j| kernel.value(&rows[i], &rows[j]) + if i == j { 0.01 } else { 0.0 });
    let mut failed = None;
    let t = best_of(3, || {
        let mut a = k.clone();
        let mut mem = MemBuffer::new(llt::factor::cholesky_in_place_scratch::<f64>(n, par, Default::default()));
        let stack = MemStack::new(&mut mem);
        if let Err(e) = llt::factor::cholesky_in_place(a.as_mut(), Default::default(), par, stack, Default::default()) {
            failed = Some(format!("{e:?}"));
        }
    });
    match failed {
        Some(e) => Err(anyhow::anyhow!("benchmark Cholesky failed: {e}")),
        None => Ok((n as f64).powi(3) / 3.0 / t / 1e9),
    }
}

fn config(restarts: usize, outputs: OutputMode, parallelism: Parallelism) -> GpConfig {
    GpConfig {
        kernel: KernelChoice::Quadratic,
        outputs,
        parallelism,
        optimiser: OptimiserConfig { restarts, ..OptimiserConfig::default() },
        ..GpConfig::default()
    }
}

struct OurRow {
    n: usize,
    fit: f64,
    predict: f64,
    lml: f64,
    fit_serial: Option<f64>,
    fit_independent: Option<f64>,
    rmse: f64,
}

struct SklearnRow {
    fit: f64,
    predict: f64,
    lml: f64,
}

fn sub(m: &Mat<f64>, n: usize) -> Mat<f64> {
    Mat::from_fn(n, m.ncols(), |i, j| m[(i, j)])
}

fn ours(d: &Data, n: usize, restarts: usize) -> anyhow::Result<OurRow> {
    let (x, y) = (sub(&d.x, n), sub(&d.y, n));
    let shared = config(restarts, OutputMode::Shared, Parallelism::Rayon);
    let t = Instant::now();
    let model = ExactGp::fit(x.as_ref(), y.as_ref(), &shared)?;
    let fit = t.elapsed().as_secs_f64();
    let mut prediction = None;
    let predict = best_of(3, || prediction = Some(model.predict_with(d.x_test.as_ref(), &PredictOptions::default())));
    let prediction = prediction.context("no prediction")??;
    let small = n <= 1000;
    let timed = |c: GpConfig| -> anyhow::Result<f64> {
        let t = Instant::now();
        ExactGp::fit(x.as_ref(), y.as_ref(), &c)?;
        Ok(t.elapsed().as_secs_f64())
    };
    let fit_serial = small.then(|| timed(config(restarts, OutputMode::Shared, Parallelism::Sequential))).transpose()?;
    let fit_independent =
        small.then(|| timed(config(restarts, OutputMode::Independent, Parallelism::Rayon))).transpose()?;
    Ok(OurRow {
        n,
        fit,
        predict,
        lml: model.log_marginal_likelihood(),
        fit_serial,
        fit_independent,
        rmse: rmse(&prediction.mean, &d.y_test_clean),
    })
}

fn sklearn_available() -> bool {
    Command::new(super::bench_gp_sklearn::python())
        .args(["-c", "import sklearn"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

fn sklearn(d: &Data, sizes: &[usize], restarts: usize) -> anyhow::Result<Vec<SklearnRow>> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/bench_gp_sklearn.py");
    let dir = std::env::temp_dir().join(format!("calib-bench-gp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).with_context(|| dir.display().to_string())?;
    let (request, response) = (dir.join("request.json"), dir.join("response.json"));
    let max_n = sizes.iter().copied().max().unwrap_or(0);
    // Same start and box as gp's defaults, so both searches solve the same problem.
    let start = Kernel::start(KernelChoice::Quadratic, DIM);
    let bounds = start.default_bounds();
    let body = serde_json::json!({
        "sizes": sizes,
        "x": rows(&d.x, max_n),
        "y": rows(&d.y, max_n),
        "x_test": rows(&d.x_test, TEST_POINTS),
        "restarts": restarts,
        "start": start.parameters(),
        "lower": bounds.lower,
        "upper": bounds.upper,
    });
    std::fs::write(&request, body.to_string()).with_context(|| request.display().to_string())?;
    let status = Command::new(super::bench_gp_sklearn::python())
        .arg(&script)
        .arg(&request)
        .arg(&response)
        .status()
        .with_context(|| script.display().to_string())?;
    if !status.success() {
        anyhow::bail!("{} failed: {status}", script.display());
    }
    let text = std::fs::read_to_string(&response).with_context(|| response.display().to_string())?;
    let _ = std::fs::remove_dir_all(&dir);
    let v: serde_json::Value = serde_json::from_str(&text)?;
    let results = v["results"].as_array().context("sklearn response has no results")?;
    results
        .iter()
        .map(|r| {
            let num = |k: &str| r[k].as_f64().with_context(|| format!("sklearn response lacks {k}"));
            Ok(SklearnRow { fit: num("fit_s")?, predict: num("predict_s")?, lml: num("lml")? })
        })
        .collect()
}

pub(crate) fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

fn fmt_opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map(f).unwrap_or_else(|| "–".into())
}

/// Runs the benchmark and prints the markdown table.
pub fn run(args: &Args) -> anyhow::Result<()> {
    if args.paper {
        let md = super::bench_gp_paper::run(&args.paper_args, &args.kernel_args.ur10_data)?;
        println!("{md}");
        if let Some(path) = &args.out {
            std::fs::write(path, &md).with_context(|| path.display().to_string())?;
        }
        return Ok(());
    }
    if args.compare {
        let md = super::bench_gp_compare::run(&args.kernel_args, std::time::Duration::from_secs(300))?;
        println!("{md}");
        return Ok(());
    }
    if let Some(dir) = &args.dump_residuals {
        return super::bench_gp_residuals::dump(&super::bench_gp_kernels::data_sets(&args.kernel_args)?, dir);
    }
    if let Some(n) = args.lml_floor {
        println!("{}", lml_floor(n)?);
        return Ok(());
    }
    if args.kernels {
        let md = super::bench_gp_kernels::run(&args.kernel_args)?;
        println!("{md}");
        return Ok(());
    }
    if !args.synthetic {
        let mut sweep = args.sweep.clone();
        if args.quick {
            sweep.sizes = vec![300, 1000];
        }
        let svg = args.out.as_ref().map(|p| p.with_extension("svg"));
        let md = super::bench_gp_sweep::run(&sweep, svg.as_deref())?;
        println!("{md}");
        if let Some(path) = &args.out {
            std::fs::write(path, &md).with_context(|| path.display().to_string())?;
        }
        return Ok(());
    }
    synthetic(args)
}

/// The markdown of `--synthetic`, each line printed as it is written.
#[derive(Default)]
struct Lines(String);

impl Lines {
    fn line(&mut self, s: String) {
        println!("{s}");
        self.0.push_str(&s);
        self.0.push('\n');
    }
}

/// `--synthetic`: the exact GP beside scikit-learn, Cholesky against the machine's peak, the sparse GP
/// against the exact one.
fn synthetic(args: &Args) -> anyhow::Result<()> {
    let sizes: Vec<usize> = if args.quick { vec![100, 300] } else { vec![100, 300, 1000, 3000] };
    let max_n = *sizes.iter().max().unwrap_or(&100);
    let sparse_sizes: Vec<usize> = if args.quick { vec![1000] } else { vec![3000, 10000] };
    let d = data(max_n.max(*sparse_sizes.iter().max().unwrap_or(&0)), 2024);
    let threads = rayon::current_num_threads();
    let mut out = Lines::default();

    out.line("# gp benchmark (`cargo xtask bench-gp`)".into());
    out.line(String::new());
    out.line(format!(
        "Machine: {} ({} cores visible, rayon pool of {threads} threads). Data: d = {DIM} (6 joint angles + payload), \
         {OUTPUTS} outputs sharing one kernel (`OutputMode::Shared`), the paper's Eq. 5 kernel, inputs standardised, \
         outputs normalised, {} random restarts besides the default start; predictions at {TEST_POINTS} points \
         (mean and variance). Times are wall-clock seconds of one run (predict: best of 3).",
        cpu_model(),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        args.restarts
    ));
    out.line(String::new());

    exact_section(&mut out, &d, &sizes, args)?;
    cholesky_section(&mut out, &d, max_n)?;
    sparse_section(&mut out, &d, &sparse_sizes, args.restarts)?;

    if let Some(path) = &args.out {
        std::fs::write(path, &out.0).with_context(|| path.display().to_string())?;
    }
    Ok(())
}

/// Our exact GP at each size, scikit-learn at those up to `--sklearn-max-n`, and the log–log slopes.
fn exact_section(out: &mut Lines, d: &Data, sizes: &[usize], args: &Args) -> anyhow::Result<()> {
    let skl_sizes: Vec<usize> = sizes.iter().copied().filter(|&n| n <= args.sklearn_max_n).collect();
    let mut our_rows = Vec::new();
    for &n in sizes {
        eprintln!("gp n={n} …");
        our_rows.push(ours(d, n, args.restarts)?);
    }
    let skl = if sklearn_available() && !skl_sizes.is_empty() {
        match sklearn(d, &skl_sizes, args.restarts) {
            Ok(r) => Some(r),
            Err(e) => {
                eprintln!("scikit-learn comparison skipped: {e:#}");
                None
            }
        }
    } else {
        eprintln!("scikit-learn not importable by python3: comparison skipped");
        None
    };

    out.line("## Exact GP: fit (with hyperparameter search) and predict".into());
    out.line(String::new());
    out.line("| n | fit (s) | fit serial (s) | fit, 6 independent kernels (s) | predict (s) | LML | test RMSE | sklearn fit (s) | sklearn predict (s) | sklearn LML | fit speed-up | LML − sklearn |".into());
    out.line("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|".into());
    for r in &our_rows {
        let s = skl.as_ref().and_then(|rows| skl_sizes.iter().position(|&n| n == r.n).and_then(|i| rows.get(i)));
        out.line(format!(
            "| {} | {:.3} | {} | {} | {:.4} | {:.2} | {:.4} | {} | {} | {} | {} | {} |",
            r.n,
            r.fit,
            fmt_opt(r.fit_serial, |v| format!("{v:.3}")),
            fmt_opt(r.fit_independent, |v| format!("{v:.3}")),
            r.predict,
            r.lml,
            r.rmse,
            fmt_opt(s.map(|s| s.fit), |v| format!("{v:.3}")),
            fmt_opt(s.map(|s| s.predict), |v| format!("{v:.4}")),
            fmt_opt(s.map(|s| s.lml), |v| format!("{v:.2}")),
            fmt_opt(s.map(|s| s.fit / r.fit), |v| format!("{v:.1}×")),
            fmt_opt(s.map(|s| r.lml - s.lml), |v| format!("{v:+.4}")),
        ));
    }
    out.line(String::new());
    let slope = log_log_slope(&our_rows.iter().map(|r| (r.n, r.fit)).collect::<Vec<_>>());
    out.line(format!("Log–log slope of gp fit time against n over n = {sizes:?}: **{slope:.2}**."));
    if let Some(rows) = &skl
        && rows.len() >= 2
    {
        let pts: Vec<(usize, f64)> = skl_sizes.iter().copied().zip(rows.iter().map(|r| r.fit)).collect();
        out.line(format!("scikit-learn: **{:.2}** over n = {skl_sizes:?}.", log_log_slope(&pts)));
    }
    out.line(String::new());
    Ok(())
}

/// The Cholesky factorisation's GFLOP/s at the largest n against faer's matrix product.
fn cholesky_section(out: &mut Lines, d: &Data, max_n: usize) -> anyhow::Result<()> {
    out.line("## Cholesky against the machine's peak".into());
    out.line(String::new());
    let peak = peak_gflops(2000, Par::rayon(0));
    let peak_seq = peak_gflops(2000, Par::Seq);
    let chol = cholesky_gflops(&d.x, max_n, Par::rayon(0))?;
    let chol_seq = cholesky_gflops(&d.x, max_n, Par::Seq)?;
    out.line("| | rayon (GFLOP/s) | serial (GFLOP/s) |".into());
    out.line("|---|---:|---:|".into());
    out.line(format!("| faer matmul 2000×2000 (peak) | {peak:.1} | {peak_seq:.1} |"));
    out.line(format!("| Cholesky n = {max_n} | {chol:.1} | {chol_seq:.1} |"));
    out.line(format!("| peak / Cholesky | {:.2}× | {:.2}× |", peak / chol, peak_seq / chol_seq));
    out.line(String::new());
    Ok(())
}

/// The sparse GP against the exact GP on the sparse fit's hyperparameters.
fn sparse_section(out: &mut Lines, d: &Data, sparse_sizes: &[usize], restarts: usize) -> anyhow::Result<()> {
    out.line("## Sparse GP (VFE/DTC, m k-means inducing points, hyperparameters from a 600-point subset) against the exact GP".into());
    out.line(String::new());
    out.line("The exact GP uses the sparse fit's hyperparameters (no search), so the columns compare the approximation itself; test RMSE is against the noiseless truth at the test points (noise std ≈ 0.02).".into());
    out.line(String::new());
    out.line("| n | m | sparse fit with subset search (s) | sparse fit, fixed hyperparameters (s) | sparse predict (s) | sparse RMSE | exact fit, fixed hyperparameters (s) | exact predict (s) | exact RMSE |".into());
    out.line("|---:|---:|---:|---:|---:|---:|---:|---:|---:|".into());
    for (n, m) in sparse_sizes.iter().flat_map(|&n| [(n, 300), (n, 1000)]).filter(|&(n, m)| m < n) {
        eprintln!("sparse n={n} m={m} …");
        let (x, y) = (sub(&d.x, n), sub(&d.y, n));
        let sc = SparseConfig {
            gp: config(restarts, OutputMode::Shared, Parallelism::Rayon),
            inducing_points: m,
            hyperparameter_subset: 600,
            ..SparseConfig::default()
        };
        let t = Instant::now();
        let sparse = SparseGp::fit(x.as_ref(), y.as_ref(), &sc)?;
        let sparse_fit = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let ps = sparse.predict(d.x_test.as_ref())?;
        let sparse_predict = t.elapsed().as_secs_f64();
        let kernels: Vec<Kernel> = sparse.report().components.iter().map(|c| c.kernel.clone()).collect();
        let t = Instant::now();
        SparseGp::fit_fixed(x.as_ref(), y.as_ref(), &kernels, &sc)?;
        let sparse_fixed = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let exact = ExactGp::fit_fixed(x.as_ref(), y.as_ref(), &kernels, &sc.gp)?;
        let exact_fit = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let pe = exact.predict(d.x_test.as_ref())?;
        let exact_predict = t.elapsed().as_secs_f64();
        out.line(format!(
            "| {n} | {m} | {sparse_fit:.3} | {sparse_fixed:.3} | {sparse_predict:.4} | {:.4} | {exact_fit:.3} | {exact_predict:.4} | {:.4} |",
            rmse(&ps.mean, &d.y_test_clean),
            rmse(&pe.mean, &d.y_test_clean)
        ));
    }
    out.line(String::new());
    Ok(())
}
