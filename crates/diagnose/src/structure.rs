//! How much of a residual any smooth function of the joint angles explains: a Gaussian process
//! with one length scale per input (ARD squared exponential, Rasmussen & Williams 2006, Eq. 5.2),
//! itself cross-validated with the diagnosis's folds. Fitted to the geometric model's held-out
//! residual it measures what *could* be explained; fitted to what the selected effects leave, what
//! is still unexplained. Its short length scales say which inputs carry the structure.

use super::statistics::mean;
use errors::Error;
use faer::Mat;
use lie::{Vector3, Vector6};
use measurements::MeasurementSet;
use serde::{Deserialize, Serialize};

/// How the GP check runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StructureOptions {
    /// Run it at all (it costs a few GP fits; without it no `unknown` verdict is possible).
    pub enabled: bool,
    /// Most training rows one fold's GP sees: an exact GP costs O(n³). 300 keeps a diagnosis of
    /// thousands of poses to seconds; it understates what a GP on more rows would explain (on the
    /// UR10's series C, 150, 200 and 300 rows give 0.33, 0.32 and 0.27 mm held out), which makes
    /// `unknown` rarer, never more frequent.
    pub max_training_rows: usize,
    /// Iterations of the hyperparameter search per fold (30 and 60 gave the same held-out error
    /// within 0.5 % on the UR10 and the blind check's cases).
    pub max_iterations: usize,
    /// An input whose length scale is at most this many of its standard deviations carries
    /// structure (a function that turns over within the data's spread); a longer one is nearly
    /// linear there, which the kinematic model absorbs.
    pub short_length_scale: f64,
}

impl Default for StructureOptions {
    fn default() -> Self {
        Self { enabled: true, max_training_rows: 300, max_iterations: 30, short_length_scale: 1.0 }
    }
}

/// One input of the GP.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GpInput {
    /// A joint angle (1-based joint).
    Joint(usize),
    /// The payload.
    Payload,
    /// The temperature.
    Temperature,
    /// The time.
    Time,
}

/// What the GP found in one residual.
#[derive(Debug, Clone)]
pub(crate) struct Structure {
    /// Held-out position error per pose once the GP's prediction is removed, m.
    pub errors: Vec<f64>,
    /// The inputs, in the order of `length_scales`.
    pub inputs: Vec<GpInput>,
    /// Each input's length scale in its standard deviations, geometric mean over the folds.
    pub length_scales: Vec<f64>,
}

impl Structure {
    /// Mean held-out position error after the GP, m.
    pub(crate) fn mean_error(&self) -> f64 {
        mean(&self.errors)
    }

    /// The inputs with a short length scale, shortest first.
    pub(crate) fn relevant(&self, short: f64) -> Vec<(GpInput, f64)> {
        let mut out: Vec<(GpInput, f64)> =
            self.inputs.iter().cloned().zip(self.length_scales.iter().copied()).filter(|(_, l)| *l <= short).collect();
        out.sort_by(|a, b| a.1.total_cmp(&b.1));
        out
    }
}

/// One fold's GP: what it leaves of each held-out pose's residual, and its length scales.
type FoldFit = (Vec<(usize, Vector3)>, Vec<f64>);

/// A per-row quantity that may be absent.
type Column = fn(&measurements::Measurement) -> Option<f64>;

/// GP inputs: the moving joints' angles and whichever of payload, temperature and time vary.
fn inputs(data: &MeasurementSet, moving: &[usize]) -> (Vec<GpInput>, Mat<f64>) {
    let mut names: Vec<GpInput> = moving.iter().map(|&j| GpInput::Joint(j + 1)).collect();
    let mut columns: Vec<Vec<f64>> = moving.iter().map(|&j| data.rows.iter().map(|r| r.q[j]).collect()).collect();
    let extra: [(GpInput, Column); 3] =
        [(GpInput::Payload, |r| Some(r.payload_kg)), (GpInput::Temperature, |r| r.temp_c), (GpInput::Time, |r| r.t_s)];
    for (name, key) in extra {
        if let Some(values) = data.rows.iter().map(key).collect::<Option<Vec<f64>>>()
            && values.iter().any(|v| (v - values[0]).abs() > 1e-9)
        {
            names.push(name);
            columns.push(values);
        }
    }
    (names, Mat::from_fn(data.rows.len(), columns.len(), |i, c| columns[c][i]))
}

/// Cross-validates a GP on the position part of `residuals` with the folds `fold`, each residual
/// expressed in the frame `link1[i]` (reference from the frame that turns with joint 1): there a
/// joint error downstream of joint 1 no longer changes direction with `q1`, so the GP's length
/// scales point at the joints the error depends on, not at the one that carries it around.
pub(crate) fn residual_structure(
    residuals: &[Vector6],
    link1: &[lie::SO3],
    data: &MeasurementSet,
    moving: &[usize],
    fold: &[usize],
    folds: usize,
    options: &StructureOptions,
) -> Result<Structure, Error> {
    let (names, x) = inputs(data, moving);
    let n = data.rows.len();
    let local: Vec<Vector3> = residuals
        .iter()
        .zip(link1)
        .map(|(r, rotation)| rotation.inverse().act(&Vector3::new(r[0], r[1], r[2])))
        .collect();
    let config = gp_config(options);
    let fit_fold = |f: usize| -> Result<FoldFit, Error> {
        let train: Vec<usize> = (0..n).filter(|&i| fold[i] != f).collect();
        let stride = train.len().div_ceil(options.max_training_rows.max(1)).max(1);
        let train: Vec<usize> = train.into_iter().step_by(stride).collect();
        let test: Vec<usize> = (0..n).filter(|&i| fold[i] == f).collect();
        if train.is_empty() || test.is_empty() || x.ncols() == 0 {
            return Ok((test.iter().map(|&i| (i, local[i])).collect(), vec![]));
        }
        let xt = Mat::from_fn(train.len(), x.ncols(), |i, c| x[(train[i], c)]);
        let yt = Mat::from_fn(train.len(), 3, |i, c| local[train[i]][c]);
        let model = gp::ExactGp::fit(xt.as_ref(), yt.as_ref(), &config).map_err(Error::gp)?;
        let xs = Mat::from_fn(test.len(), x.ncols(), |i, c| x[(test[i], c)]);
        let predicted = model.predict_mean(xs.as_ref()).map_err(Error::gp)?;
        let left = test
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let r = &local[i];
                (i, Vector3::new(r[0] - predicted[(k, 0)], r[1] - predicted[(k, 1)], r[2] - predicted[(k, 2)]))
            })
            .collect();
        let scales = match model.kernel_for_output(0) {
            Some(gp::Kernel::SquaredExponentialArd(k)) => k.length_scales.clone(),
            _ => vec![],
        };
        Ok((left, scales))
    };
    use rayon::prelude::*;
    let per_fold: Vec<FoldFit> = (0..folds).into_par_iter().map(fit_fold).collect::<Result<_, _>>()?;
    Ok(gathered(&per_fold, n, names))
}

/// One fold's GP: ARD squared exponential shared by the three position axes, one search without
/// restarts, sequential (the folds run side by side).
fn gp_config(options: &StructureOptions) -> gp::GpConfig {
    gp::GpConfig {
        kernel: gp::KernelChoice::SquaredExponentialArd,
        outputs: gp::OutputMode::Shared,
        optimiser: gp::OptimiserConfig {
            restarts: 0,
            max_iterations: options.max_iterations,
            ..gp::OptimiserConfig::default()
        },
        parallelism: gp::Parallelism::Sequential,
        ..gp::GpConfig::default()
    }
}

/// The folds' fits gathered: each held-out pose's error, and each input's length scale as the
/// geometric mean over the folds that fitted one.
fn gathered(per_fold: &[FoldFit], n: usize, names: Vec<GpInput>) -> Structure {
    let mut errors = vec![0.0; n];
    let mut log_scales = vec![0.0; names.len()];
    let mut counted = 0usize;
    for (left, scales) in per_fold {
        for (i, v) in left {
            errors[*i] = v.norm();
        }
        if scales.len() == names.len() {
            for (sum, l) in log_scales.iter_mut().zip(scales) {
                *sum += l.ln();
            }
            counted += 1;
        }
    }
    let length_scales =
        log_scales.iter().map(|s| if counted > 0 { (s / counted as f64).exp() } else { f64::INFINITY }).collect();
    Structure { errors, inputs: names, length_scales }
}
