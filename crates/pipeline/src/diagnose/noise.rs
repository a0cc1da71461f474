//! The noise floor: the error a perfect model would still show, from the measurement noise and
//! the robot's repeatability.

use crate::MeasurementSet;
use serde::{Deserialize, Serialize};

/// `E|e|` of an isotropic 3-D Gaussian error of unit standard deviation per axis: `√(8/π)`.
pub(crate) const MEAN_DISTANCE_PER_SIGMA: f64 = 1.595_769_121_605_730_7;

/// Where the noise level comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// Given by the user (`--noise-mm`).
    Given,
    /// The scatter of repeated measurements of the same joint configuration.
    Repeats,
    /// The held-out residual of the final model, per axis: an upper bound, since structure that no
    /// candidate explains counts as noise.
    HeldOutResidual,
    /// What a cross-validated GP leaves of the final model's held-out residual, per axis: the
    /// noise if the GP caught all structure, an upper bound otherwise.
    ResidualGp,
}

/// The noise level and the floor it sets.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseFloor {
    /// Standard deviation per axis, mm.
    pub sigma_mm: f64,
    /// The mean position error of a perfect model, `σ √(8/π)`, mm.
    pub floor_mm: f64,
    /// Where `sigma_mm` comes from.
    pub source: NoiseSource,
}

impl NoiseFloor {
    /// A floor from a per-axis standard deviation.
    pub(crate) fn from_sigma(sigma_mm: f64, source: NoiseSource) -> Self {
        Self { sigma_mm, floor_mm: sigma_mm * MEAN_DISTANCE_PER_SIGMA, source }
    }
}

/// The pooled per-axis scatter of rows that repeat a joint configuration (to 1e-6 rad) with the
/// same tool and payload, when at least five configurations are repeated; mm.
pub(crate) fn from_repeats(data: &MeasurementSet) -> Option<f64> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, row) in data.rows.iter().enumerate() {
        let same = |j: &usize| {
            let other = &data.rows[*j];
            other.tool == row.tool
                && other.payload_kg == row.payload_kg
                && other.q.iter().zip(&row.q).all(|(a, b)| (a - b).abs() < 1e-6)
        };
        match groups.iter_mut().find(|g| same(&g[0])) {
            Some(group) => group.push(i),
            None => groups.push(vec![i]),
        }
    }
    let repeated: Vec<&Vec<usize>> = groups.iter().filter(|g| g.len() > 1).collect();
    if repeated.len() < 5 {
        return None;
    }
    let (mut sum, mut dof) = (0.0, 0usize);
    for group in repeated {
        let mean = group.iter().map(|&i| data.rows[i].position).sum::<lie::Vector3>() / group.len() as f64;
        sum += group.iter().map(|&i| (data.rows[i].position - mean).norm_squared()).sum::<f64>();
        dof += 3 * (group.len() - 1);
    }
    Some((sum / dof as f64).sqrt() * 1e3)
}
