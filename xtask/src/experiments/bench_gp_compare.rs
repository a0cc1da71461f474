//! `cargo xtask bench-gp --compare`: the GP stage against scikit-learn on the same residuals, in the
//! same run: the real UR10 (series C, even rows → odd rows) and simulated soft joints with
//! payloads (300 poses, several seeds); held-out error and fit time.

use std::fmt::Write;
use std::time::Duration;

use super::bench_gp_kernels::{KernelArgs, data_sets};
use super::bench_gp_residuals::{Residuals, fit_timed, heldout_mm};
use super::bench_gp_sklearn::{SklearnOptions, available, fit_predict};

/// Runs the comparison and returns the markdown table.
pub fn run(args: &KernelArgs, timeout: Duration) -> anyhow::Result<String> {
    let sets = data_sets(args)?;
    let with_sklearn = available();
    if !with_sklearn {
        eprintln!("scikit-learn is not importable by python3: its columns stay empty");
    }
    let mut md = String::new();
    let _ = writeln!(
        md,
        "| data | n train / test | gp (mm) | gp fit (s) | sklearn C·RBF(ARD)+C+White (mm) | its fit (s, peak memory) | \
         sklearn … + C·DotProduct (mm) | its fit (s, peak memory) | speed-up over the faster sklearn |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for set in &sets {
        eprintln!("{} …", set.name);
        let (model, ours_s) = fit_timed(set)?;
        let mean = model.predict_mean(set.test.inputs.as_ref())?;
        let ours = heldout_mm(&mean, &set.test);
        for c in &model.report().components {
            eprintln!("  gp outputs {:?}: LML {:.3}, {:?}", c.outputs, c.log_marginal_likelihood, c.kernel);
        }
        let (cells, fastest) = sklearn_cells(set, with_sklearn, timeout)?;
        let speedup = if fastest.is_finite() { format!("{:.0}×", fastest / ours_s) } else { "–".into() };
        let row = format!(
            "| {} | {} / {} | {ours:.4} | {ours_s:.2} | {} | {speedup} |",
            set.name,
            set.train.inputs.nrows(),
            set.test.inputs.nrows(),
            cells.join(" | ")
        );
        // Each row as soon as it is measured: a long run stopped half-way keeps what it did.
        eprintln!("{row}");
        let _ = writeln!(md, "{row}");
    }
    Ok(md)
}

/// scikit-learn's held-out error, fit time and peak memory without and with the linear term, and
/// the faster fit's seconds (infinite when neither finished).
fn sklearn_cells(set: &Residuals, with_sklearn: bool, timeout: Duration) -> anyhow::Result<(Vec<String>, f64)> {
    let mut cells = Vec::new();
    let mut fastest = f64::INFINITY;
    for linear in [false, true] {
        let options =
            SklearnOptions { linear, isotropic: false, restarts: 1, independent: true, processes: 2, timeout };
        let result = if with_sklearn {
            fit_predict(&set.train.inputs, &set.train.outputs, &set.test.inputs, &options)?
        } else {
            None
        };
        match result {
            Some(r) => {
                for (k, (kernel, lml)) in r.fitted.iter().enumerate() {
                    eprintln!("  sklearn (linear: {linear}) GP {k}: LML {lml:.3}, {kernel}");
                }
                fastest = fastest.min(r.fit_s);
                cells.push(format!(
                    "{:.4} | {:.1} ({:.0} MB)",
                    heldout_mm(&r.mean, &set.test),
                    r.fit_s,
                    r.peak_bytes / 1e6
                ));
            }
            None => cells.push(format!("> {} s | –", timeout.as_secs())),
        }
    }
    Ok((cells, fastest))
}
