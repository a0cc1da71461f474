//! Input standardisation and output normalisation, stored in the fitted model and applied again at
//! prediction time.
//!
//! Both use the population standard deviation (divide by `n`), as numpy's `std` and
//! scikit-learn's `normalize_y` do, so that hyperparameters can be compared one to one.

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::points::Points;

/// Per-input affine map `z = (x − mean) / scale`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputStandardiser {
    /// Mean of each input column over the training set (0 when disabled).
    pub mean: Vec<f64>,
    /// Standard deviation of each input column (1 when disabled or when the column is constant).
    pub scale: Vec<f64>,
}

/// Per-output affine map `z = (y − mean) / scale`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OutputNormaliser {
    /// Mean of each output column over the training set (0 when disabled).
    pub mean: Vec<f64>,
    /// Standard deviation of each output column (1 when disabled or when the column is constant).
    pub scale: Vec<f64>,
}

/// Column means and population standard deviations; a constant column gets scale 1 so that it
/// passes through unchanged instead of dividing by zero (e.g. a payload that never changes).
fn column_moments(n: usize, cols: usize, at: impl Fn(usize, usize) -> f64) -> (Vec<f64>, Vec<f64>) {
    let mut mean = vec![0.0; cols];
    let mut scale = vec![1.0; cols];
    if n == 0 {
        return (mean, scale);
    }
    for j in 0..cols {
        let m = (0..n).map(|i| at(i, j)).sum::<f64>() / n as f64;
        let var = (0..n).map(|i| (at(i, j) - m).powi(2)).sum::<f64>() / n as f64;
        mean[j] = m;
        let sd = var.sqrt();
        // Relative test: a column whose spread is at round-off level of its mean is constant.
        if sd > 1e-12 * m.abs().max(f64::MIN_POSITIVE) {
            scale[j] = sd;
        }
    }
    (mean, scale)
}

/// `mean` and `scale` have `len` entries, means finite, scales finite and positive (a stored model
/// read back from a file is checked with this).
fn check_map(mean: &[f64], scale: &[f64], len: usize, field: &'static str) -> Result<(), Error> {
    if mean.len() != len || scale.len() != len {
        return Err(Error::InvalidConfig { field, value: mean.len().max(scale.len()) as f64 });
    }
    if let Some(&bad) = mean.iter().find(|v| !v.is_finite()) {
        return Err(Error::InvalidConfig { field, value: bad });
    }
    if let Some(&bad) = scale.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(Error::InvalidConfig { field, value: bad });
    }
    Ok(())
}

impl InputStandardiser {
    /// Refuses a map that does not have `dim` finite entries with positive scales.
    pub fn check(&self, dim: usize) -> Result<(), Error> {
        check_map(&self.mean, &self.scale, dim, "inputs")
    }

    /// The identity map for `dim` inputs.
    pub fn identity(dim: usize) -> Self {
        Self { mean: vec![0.0; dim], scale: vec![1.0; dim] }
    }

    /// Mean and standard deviation of each column of the training inputs.
    pub fn fit(points: &Points) -> Self {
        let (mean, scale) = column_moments(points.len(), points.dim(), |i, j| points.row(i)[j]);
        Self { mean, scale }
    }

    /// Applies the map to raw inputs, refusing a wrong column count or non-finite entries.
    pub fn apply(&self, x: MatRef<'_, f64>) -> Result<Points, Error> {
        if x.ncols() != self.mean.len() {
            return Err(Error::InputDimensionMismatch { expected: self.mean.len(), found: x.ncols() });
        }
        let raw = Points::from_rows(x)?;
        Ok(self.apply_points(&raw))
    }

    /// Applies the map to already validated points.
    pub fn apply_points(&self, raw: &Points) -> Points {
        let data = raw
            .as_slice()
            .chunks_exact(raw.dim().max(1))
            .flat_map(|row| row.iter().zip(&self.mean).zip(&self.scale).map(|((x, m), s)| (x - m) / s))
            .collect();
        Points::from_row_major(raw.dim(), data)
    }
}

impl OutputNormaliser {
    /// Refuses a map that does not have `outputs` finite entries with positive scales.
    pub fn check(&self, outputs: usize) -> Result<(), Error> {
        check_map(&self.mean, &self.scale, outputs, "outputs")
    }

    /// The identity map for `outputs` columns.
    pub fn identity(outputs: usize) -> Self {
        Self { mean: vec![0.0; outputs], scale: vec![1.0; outputs] }
    }

    /// Mean and standard deviation of each output column.
    pub fn fit(y: MatRef<'_, f64>) -> Self {
        let (mean, scale) = column_moments(y.nrows(), y.ncols(), |i, j| y[(i, j)]);
        Self { mean, scale }
    }

    /// `(y − mean) / scale`, column by column.
    pub fn normalise(&self, y: MatRef<'_, f64>) -> Mat<f64> {
        Mat::from_fn(y.nrows(), y.ncols(), |i, j| (y[(i, j)] - self.mean[j]) / self.scale[j])
    }
}
