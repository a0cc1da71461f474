//! The scikit-learn side of `cargo xtask bench-gp`: one fit and prediction in a python3 process
//! (`xtask/scripts/bench_gp_sklearn.py`), killed when it passes its time limit.
//!
//! The interpreter is [`python`]: `$CALIB_PYTHON`, else the project's own environment
//! `target/pyenv` (made by `python3 -m venv target/pyenv && target/pyenv/bin/pip install -r
//! xtask/scripts/requirements.txt`), else `python3` on the path.

use anyhow::Context;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use faer::Mat;

/// How scikit-learn is asked to fit.
#[derive(Debug, Clone, Copy)]
pub struct SklearnOptions {
    /// With the `C · DotProduct` term.
    pub linear: bool,
    /// The paper's isotropic Eq. 5 instead: `C · RBF(one length scale) + C + DotProduct + White`.
    pub isotropic: bool,
    /// `n_restarts_optimizer`.
    pub restarts: usize,
    /// One GP per output column (in a pool of `processes` workers) rather than one for all.
    pub independent: bool,
    /// Worker processes for independent outputs.
    pub processes: usize,
    /// Kill the fit after this long.
    pub timeout: Duration,
}

/// What scikit-learn did.
#[derive(Debug, Clone)]
pub struct SklearnResult {
    /// Wall-clock seconds of the fit (the whole process when it finished).
    pub fit_s: f64,
    /// Peak resident memory of the python process and its workers, bytes.
    pub peak_bytes: f64,
    /// Predicted means at the test inputs.
    pub mean: Mat<f64>,
    /// Per GP (one per output, or one for all): the fitted kernel as scikit-learn prints it and its
    /// log marginal likelihood of the normalised outputs.
    pub fitted: Vec<(String, f64)>,
}

/// The Python interpreter the comparisons run: `$CALIB_PYTHON`, else `target/pyenv/bin/python3`
/// under the workspace when it exists, else `python3`.
pub fn python() -> PathBuf {
    if let Some(p) = std::env::var_os("CALIB_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/pyenv/bin/python3");
    if venv.exists() { venv } else { PathBuf::from("python3") }
}

/// `true` when `python -c "import sklearn"` works.
pub fn available() -> bool {
    Command::new(python()).args(["-c", "import sklearn"]).output().map(|o| o.status.success()).unwrap_or(false)
}

fn rows(m: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows()).map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect()).collect()
}

/// Fits and predicts; `Ok(None)` when the process passed `options.timeout` and was killed.
pub fn fit_predict(
    x: &Mat<f64>,
    y: &Mat<f64>,
    x_test: &Mat<f64>,
    options: &SklearnOptions,
) -> anyhow::Result<Option<SklearnResult>> {
    fit_predict_with(&python(), false, x, y, x_test, options)
}

/// [`fit_predict`] with the interpreter `python`; `quiet`: without Python's warnings (scikit-learn's
/// convergence warnings, one per length scale at its bound).
pub fn fit_predict_with(
    python: &Path,
    quiet: bool,
    x: &Mat<f64>,
    y: &Mat<f64>,
    x_test: &Mat<f64>,
    options: &SklearnOptions,
) -> anyhow::Result<Option<SklearnResult>> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/bench_gp_sklearn.py");
    let dir = std::env::temp_dir().join(format!("calib-bench-gp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).with_context(|| dir.display().to_string())?;
    let (request, response) = (dir.join("request.json"), dir.join("response.json"));
    let body = serde_json::json!({
        "x": rows(x),
        "y": rows(y),
        "x_test": rows(x_test),
        "linear": options.linear,
        "isotropic": options.isotropic,
        "restarts": options.restarts,
        "independent": options.independent,
        "processes": options.processes,
    });
    std::fs::write(&request, body.to_string()).with_context(|| request.display().to_string())?;
    let _ = std::fs::remove_file(&response);
    let start = Instant::now();
    // Its own process group, so that a timeout ends the pool's workers with it.
    let mut command = Command::new(python);
    if quiet {
        command.env("PYTHONWARNINGS", "ignore");
    }
    let mut child = command
        .process_group(0)
        .arg(&script)
        .arg(&request)
        .arg(&response)
        .spawn()
        .with_context(|| script.display().to_string())?;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > options.timeout {
            let group = format!("-{}", child.id());
            let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
            let _ = child.kill();
            let _ = child.wait();
            let _ = std::fs::remove_dir_all(&dir);
            return Ok(None);
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    if !status.success() {
        anyhow::bail!("{} failed: {status}", script.display());
    }
    let text = std::fs::read_to_string(&response).with_context(|| response.display().to_string())?;
    let _ = std::fs::remove_dir_all(&dir);
    response_of(&text, y.ncols()).map(Some)
}

/// The script's answer: the fit's seconds and peak memory, the predicted mean (`cols` outputs) and
/// each fitted kernel with its log marginal likelihood.
fn response_of(text: &str, cols: usize) -> anyhow::Result<SklearnResult> {
    let v: serde_json::Value = serde_json::from_str(text)?;
    let num = |k: &str| v[k].as_f64().with_context(|| format!("scikit-learn response lacks {k}"));
    let mean_rows = v["mean"].as_array().context("scikit-learn response lacks mean")?;
    let mut mean = Mat::zeros(mean_rows.len(), cols);
    for (i, r) in mean_rows.iter().enumerate() {
        for j in 0..cols {
            mean[(i, j)] = r[j].as_f64().context("scikit-learn mean is not a number")?;
        }
    }
    let fitted = v["fitted"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|f| (f["kernel"].as_str().unwrap_or("?").to_owned(), f["lml"].as_f64().unwrap_or(f64::NAN)))
                .collect()
        })
        .unwrap_or_default();
    Ok(SklearnResult { fit_s: num("fit_s")?, peak_bytes: num("peak_bytes")?, mean, fitted })
}
