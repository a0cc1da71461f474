//! Is anything left? A Gaussian process on the held-out residual of the final model, itself
//! cross-validated: if it predicts the held-out residual of rows it has not seen, the residual has
//! structure that no candidate explains.

use super::selection::CrossValidated;
use super::statistics::{mean, paired_t};
use crate::{Error, MeasurementSet};
use faer::Mat;
use lie::Vector3;

/// What the GP found in the residual.
#[derive(Debug, Clone)]
pub(crate) struct Structure {
    /// The residual's mean position error after the GP's held-out prediction is removed, m.
    pub after_gp_m: f64,
    /// Per-axis standard deviation of what the GP leaves, m: a noise estimate.
    pub sigma_m: f64,
    /// Paired t statistic of the GP's gain.
    pub t: f64,
}

/// Most training rows one fold's GP sees.
const MAX_TRAINING_ROWS: usize = 400;

/// A per-row quantity that may be absent.
type Column = fn(&crate::Measurement) -> Option<f64>;

/// GP inputs: the joint values and whichever of payload, temperature and time vary.
fn inputs(data: &MeasurementSet) -> Mat<f64> {
    let mut columns: Vec<Vec<f64>> =
        (0..data.joint_count).map(|j| data.rows.iter().map(|r| r.q[j]).collect()).collect();
    let extra: [Column; 3] = [|r| Some(r.payload_kg), |r| r.temp_c, |r| r.t_s];
    for key in extra {
        if let Some(values) = data.rows.iter().map(key).collect::<Option<Vec<f64>>>()
            && values.iter().any(|v| (v - values[0]).abs() > 1e-9)
        {
            columns.push(values);
        }
    }
    Mat::from_fn(data.rows.len(), columns.len(), |i, c| columns[c][i])
}

/// Cross-validates a GP on the position residual of `result` with the same folds.
pub(crate) fn residual_structure(
    result: &CrossValidated,
    data: &MeasurementSet,
    folds: &[usize],
    fold_count: usize,
) -> Result<Structure, Error> {
    let x = inputs(data);
    let n = data.rows.len();
    let config = gp::GpConfig {
        kernel: gp::KernelChoice::SquaredExponentialArd,
        outputs: gp::OutputMode::Shared,
        optimiser: gp::OptimiserConfig { restarts: 1, max_iterations: 100, ..gp::OptimiserConfig::default() },
        ..gp::GpConfig::default()
    };
    let mut left = vec![Vector3::zeros(); n];
    for fold in 0..fold_count {
        let train: Vec<usize> = (0..n).filter(|&i| folds[i] != fold).collect();
        // An exact GP costs O(n³): beyond a few hundred rows an even subsample finds the same
        // structure, and keeps a diagnosis of thousands of poses to seconds.
        let stride = train.len().div_ceil(MAX_TRAINING_ROWS).max(1);
        let train: Vec<usize> = train.into_iter().step_by(stride).collect();
        let test: Vec<usize> = (0..n).filter(|&i| folds[i] == fold).collect();
        if train.is_empty() || test.is_empty() {
            continue;
        }
        let xt = Mat::from_fn(train.len(), x.ncols(), |i, c| x[(train[i], c)]);
        let yt = Mat::from_fn(train.len(), 3, |i, c| result.residuals[train[i]][c]);
        let model = gp::ExactGp::fit(xt.as_ref(), yt.as_ref(), &config)?;
        let xs = Mat::from_fn(test.len(), x.ncols(), |i, c| x[(test[i], c)]);
        let predicted = model.predict_mean(xs.as_ref())?;
        for (k, &i) in test.iter().enumerate() {
            let r = &result.residuals[i];
            left[i] = Vector3::new(r[0] - predicted[(k, 0)], r[1] - predicted[(k, 1)], r[2] - predicted[(k, 2)]);
        }
    }
    let before: Vec<f64> = result.errors.iter().map(|e| e * e).collect();
    let after: Vec<f64> = left.iter().map(|l| l.norm_squared()).collect();
    Ok(Structure {
        after_gp_m: mean(&left.iter().map(|l| l.norm()).collect::<Vec<_>>()),
        sigma_m: (mean(&after) / 3.0).sqrt(),
        t: paired_t(&before, &after),
    })
}
