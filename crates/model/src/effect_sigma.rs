//! What a fit knows of its effects' parameters, carried to every row a model is applied at: the
//! posterior covariance of each effect's parameters (`poe::identify::Identification::
//! correction_covariance`), stored as its Cholesky factor, gives the standard deviation of the
//! effect's correction at any row it is applied at. Where that σ is far above what the training
//! rows had, the effects were fitted on nothing like the row (a joint combination never excited,
//! a gap, beyond a range), and the model falls back to the geometry fitted alone there
//! (`model_parts`, [`EffectUncertainty::weight`]).

use effects::{IdentifiedEffect, RowTwists};
use errors::Error;
use faer::{Mat, Side};
use lie::Vector3;
use measurements::Measurement;
use poe::LocalPoe;
use poe::RowKind;
use serde::{Deserialize, Serialize};

/// The posterior uncertainty of a model's geometry and effects, as a model file keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectUncertainty {
    /// The free kinematic parameters, as indices into the kinematics' parameter layout (their
    /// left perturbations, `poe::LocalPoe::identification_jacobian`), in the factor's order;
    /// the effects' parameters follow them, effect by effect, in the model's order.
    pub free: Vec<usize>,
    /// The lower Cholesky factor `L` of the posterior covariance `Σ = L Lᵀ` of those parameters
    /// (the effects' scaled), packed by rows (`L₀₀, L₁₀, L₁₁, L₂₀, …`: `p(p+1)/2` numbers for `p`
    /// parameters). Written as one string of numbers to seven significant digits (the factor of
    /// a fit with effects has tens of thousands; σ needs three digits), read back exactly.
    #[serde(with = "packed_numbers")]
    pub factor: Vec<f64>,
    /// The σ of the tool point's position (m) over the training rows: the median and the largest.
    pub training_sigma_m: [f64; 2],
    /// Rows whose σ exceeds this (m) fall back to the geometry fitted alone, fully from twice it
    /// (the fit's `EffectOptions::fallback_sigma_ratio` times the largest training σ).
    pub fallback_sigma_m: f64,
}

impl EffectUncertainty {
    /// The factor of `covariance` (row-major, `p × p`); `None` when it is not `p × p` or not
    /// positive (semi)definite.
    pub fn factor_of(covariance: &[f64], p: usize) -> Option<Vec<f64>> {
        if covariance.len() != p * p || p == 0 {
            return None;
        }
        let largest = (0..p).map(|i| covariance[i * p + i]).fold(0.0_f64, f64::max);
        if !(largest.is_finite() && largest >= 0.0) {
            return None;
        }
        // A definite inverse; rounding can leave a direction the prior alone holds a hair below
        // zero, so the factor gets a jitter of 1e-12 of the largest variance (far below any σ a
        // report shows).
        let matrix = Mat::<f64>::from_fn(p, p, |i, j| {
            covariance[i * p + j] + if i == j { largest * 1e-12 + f64::MIN_POSITIVE } else { 0.0 }
        });
        let llt = matrix.llt(Side::Lower).ok()?;
        let l = llt.L();
        // Rounded as the file keeps it, so that the fit uses what eval will read.
        Some(
            (0..p)
                .flat_map(|i| (0..=i).map(move |j| (i, j)))
                .map(|(i, j)| packed_numbers::rounded(l[(i, j)]))
                .collect(),
        )
    }

    /// The number of parameters the factor is of.
    pub fn parameter_count(&self) -> usize {
        // p(p+1)/2 = len.
        (((8 * self.factor.len() + 1) as f64).sqrt() as usize).saturating_sub(1) / 2
    }

    /// The σ of the tool point's position (m) of a row's per-component σ ([`EffectUncertainty::sigma`]):
    /// the three position components in quadrature.
    pub fn position(sigma: &[f64; 6]) -> f64 {
        (sigma[0] * sigma[0] + sigma[1] * sigma[1] + sigma[2] * sigma[2]).sqrt()
    }

    /// How fully the effects apply at a row whose position σ is `sigma_m`: 1 up to
    /// [`EffectUncertainty::fallback_sigma_m`], 0 from twice it, linear between.
    pub fn weight(&self, sigma_m: f64) -> f64 {
        let limit = self.fallback_sigma_m;
        if limit.is_nan() || limit <= 0.0 || sigma_m <= limit { 1.0 } else { (2.0 - sigma_m / limit).clamp(0.0, 1.0) }
    }

    /// How the pose at `row` (model tool `tool`) moves per unit of each parameter of the factor,
    /// at the tool point, as `(v, ω)`: the tool point's displacement and the rotation (the
    /// identification Jacobian's columns of the free kinematic parameters, then each effect
    /// parameter's twist times its feature, moved to the point). First order in the effects:
    /// how their own twist turns the kinematic columns (`poe::identify::PoseCorrection`, of the
    /// effects' size, 1e-4 on an industrial arm) is left out of a σ.
    pub fn parameter_changes(
        &self,
        kinematics: &LocalPoe,
        effects: &[IdentifiedEffect],
        row: &Measurement,
        tool: usize,
    ) -> Result<Vec<[f64; 6]>, Error> {
        let (mut changes, point) = kinematic_changes(kinematics, &self.free, row, tool)?;
        let mut twists = RowTwists::new(kinematics, &row.q, tool);
        for effect in effects {
            let features = effect.features(row, tool)?;
            for (direction, f) in effect.directions().into_iter().zip(features) {
                if f == 0.0 {
                    changes.push([0.0; 6]);
                    continue;
                }
                let twist = twists.twist(direction)? * f;
                let w = Vector3::new(twist[3], twist[4], twist[5]);
                let v = Vector3::new(twist[0], twist[1], twist[2]) + w.cross(&point);
                changes.push([v.x, v.y, v.z, w.x, w.y, w.z]);
            }
        }
        Ok(changes)
    }

    /// The standard deviation of the pose the geometry and `effects` predict at `row` (model
    /// tool `tool`), per component of the pose error `(v, ω)` at the tool point: `σ_k = ‖Lᵀ g_k‖`,
    /// `g_k` the k-th component of [`EffectUncertainty::parameter_changes`]. Zero when the factor
    /// is not of those parameters (a model edited by hand; the file check refuses it).
    pub fn sigma(
        &self,
        kinematics: &LocalPoe,
        effects: &[IdentifiedEffect],
        row: &Measurement,
        tool: usize,
    ) -> Result<[f64; 6], Error> {
        let changes = self.parameter_changes(kinematics, effects, row, tool)?;
        Ok(factor_sigma(&self.factor, &changes))
    }
}

/// The columns of the identification Jacobian of `kinematics` at `row` (model tool `tool`) for
/// the parameters `free`, as `(v, ω)` at the tool point, and that point.
pub(crate) fn kinematic_changes(
    kinematics: &LocalPoe,
    free: &[usize],
    row: &Measurement,
    tool: usize,
) -> Result<(Vec<[f64; 6]>, Vector3), Error> {
    let columns = kinematics.layout().len();
    let mut jacobian = vec![0.0; 6 * columns];
    let pose = kinematics
        .identification_jacobian(&row.q, tool, RowKind::PointAndRotation, &mut jacobian)
        .map_err(Error::kinematics)?;
    let changes =
        free.iter().map(|&c| std::array::from_fn(|k| jacobian.get(k * columns + c).copied().unwrap_or(0.0))).collect();
    Ok((changes, pose.translation()))
}

/// Per component of the pose error, `σ_k = ‖Lᵀ g_k‖` for the packed lower factor `factor` of a
/// covariance and the pose's changes `changes` per parameter; zero when the factor is not of
/// that many parameters (a model edited by hand; the file check refuses it).
pub(crate) fn factor_sigma(factor: &[f64], changes: &[[f64; 6]]) -> [f64; 6] {
    let p = changes.len();
    if factor.len() != p * (p + 1) / 2 {
        return [0.0; 6];
    }
    // (Lᵀ g)_j = Σ_{i ≥ j} L_ij g_i, row i of L starting at i(i+1)/2.
    let mut u = vec![[0.0; 6]; p];
    for (i, change) in changes.iter().enumerate() {
        let start = i * (i + 1) / 2;
        for (j, uj) in u.iter_mut().enumerate().take(i + 1) {
            let l = factor[start + j];
            for k in 0..6 {
                uj[k] += l * change[k];
            }
        }
    }
    std::array::from_fn(|k| u.iter().map(|v| v[k] * v[k]).sum::<f64>().sqrt())
}

/// A list of numbers as one string, each to seven significant digits.
pub(crate) mod packed_numbers {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    /// `value` to seven significant digits: what the string keeps.
    pub(crate) fn rounded(value: f64) -> f64 {
        format!("{value:.6e}").parse().unwrap_or(value)
    }

    pub(crate) fn serialize<S: Serializer>(values: &[f64], serializer: S) -> Result<S::Ok, S::Error> {
        let text: Vec<String> = values.iter().map(|v| format!("{v:.6e}")).collect();
        serializer.serialize_str(&text.join(" "))
    }

    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<f64>, D::Error> {
        let text = String::deserialize(deserializer)?;
        text.split_ascii_whitespace()
            .enumerate()
            .map(|(k, token)| {
                token
                    .parse::<f64>()
                    .map_err(|_| D::Error::custom(format!("number {} of the list, '{token}', is not a number", k + 1)))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_weight_is_one_inside_the_limit_and_zero_from_twice_it() {
        let u = EffectUncertainty {
            free: Vec::new(),
            factor: Vec::new(),
            training_sigma_m: [1e-5, 2e-5],
            fallback_sigma_m: 1e-4,
        };
        assert_eq!(u.weight(5e-5), 1.0);
        assert_eq!(u.weight(1e-4), 1.0);
        assert!((u.weight(1.5e-4) - 0.5).abs() < 1e-12);
        assert_eq!(u.weight(2e-4), 0.0);
        assert_eq!(u.weight(1.0), 0.0);
    }
}
