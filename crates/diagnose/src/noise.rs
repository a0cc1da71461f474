//! The noise floor: the error a perfect model would still show, from the measurement noise. It
//! comes from what the data or the user say about the instrument, never from what a model leaves
//! (a GP's leftover holds every structure the GP missed, and called 0.27 mm "the floor" on a UR10
//! whose tracker is ten times better).

use loadsim::TrackerNoise;
use measurements::MeasurementSet;
use serde::{Deserialize, Serialize};

/// `E|e|` of an isotropic 3-D Gaussian error of unit standard deviation per axis: `√(8/π)`.
pub(crate) const MEAN_DISTANCE_PER_SIGMA: f64 = 1.595_769_121_605_730_7;

/// Where the noise level comes from (SPEC v2 `noise.source`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// The scatter of repeated measurements of the same joint configuration.
    Repeats,
    /// Given by the user (`--noise-mm`).
    Given,
    /// The tracker's own stated standard deviation of every row (`std_x_mm` …).
    Stated,
    /// The default of the instrument class the data come from (a laser tracker), at the measured
    /// distances: see [`NoiseFloor::instrument`].
    TrackerDefault,
}

/// The noise level and the floor it sets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseFloor {
    /// Standard deviation per axis, mm.
    pub sigma_mm: f64,
    /// The mean position error of a perfect model, `σ √(8/π)`, mm.
    pub floor_mm: f64,
    /// Where `sigma_mm` comes from.
    pub source: NoiseSource,
    /// For `tracker_default`: the instrument model assumed, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instrument: Option<String>,
}

impl NoiseFloor {
    /// A floor from a per-axis standard deviation.
    pub(crate) fn from_sigma(sigma_mm: f64, source: NoiseSource) -> Self {
        Self { sigma_mm, floor_mm: sigma_mm * MEAN_DISTANCE_PER_SIGMA, source, instrument: None }
    }
}

/// The floor of a laser tracker of the class `noise` describes (default: Leica AT901 with a
/// T-Mac, σ = MPE/2, module `loadsim::TrackerNoise`), the tracker at the origin of the measurement
/// frame: per pose the radial and the two transverse variances at the measured distance, pooled
/// into one per-axis σ.
pub(crate) fn tracker_default(data: &MeasurementSet, noise: &TrackerNoise) -> NoiseFloor {
    let variance: f64 = data
        .rows
        .iter()
        .map(|row| {
            let transverse = noise.transverse_sigma_m + noise.transverse_sigma_per_m * row.position.norm();
            (noise.radial_sigma_m.powi(2) + 2.0 * transverse * transverse) / 3.0
        })
        .sum::<f64>()
        / data.rows.len().max(1) as f64;
    let mut floor = NoiseFloor::from_sigma(variance.sqrt() * 1e3, NoiseSource::TrackerDefault);
    floor.instrument = Some(format!(
        "laser tracker at the origin of the measurement frame, Leica AT901-class (σ = MPE/2): {:.1} µm radial, \
         {:.1} µm + {:.1} µm/m transverse",
        noise.radial_sigma_m * 1e6,
        noise.transverse_sigma_m * 1e6,
        noise.transverse_sigma_per_m * 1e6
    ));
    floor
}

/// The per-axis σ every row states (`std_x_mm` …), pooled as the tracker default's variances
/// are, mm; `None` unless every row states its position's.
pub(crate) fn stated(data: &MeasurementSet) -> Option<f64> {
    let variances: Vec<f64> = data
        .rows
        .iter()
        .map(|row| row.std.and_then(|s| s.position_m).map(|p| p.iter().map(|v| v * v).sum::<f64>() / 3.0))
        .collect::<Option<_>>()?;
    (!variances.is_empty()).then(|| (variances.iter().sum::<f64>() / variances.len() as f64).sqrt() * 1e3)
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

#[cfg(test)]
mod tests {
    use super::*;
    use lie::Vector3;
    use measurements::Measurement;

    fn row(q: f64, x: f64) -> Measurement {
        Measurement::at(vec![q], Vector3::new(x, 0.0, 0.0))
    }

    #[test]
    fn the_tracker_default_grows_with_distance_and_names_its_instrument() {
        let noise = TrackerNoise::default();
        let near = MeasurementSet::from_rows("t", vec![row(0.0, 1.0)], vec![String::new()]);
        let far = MeasurementSet::from_rows("t", vec![row(0.0, 10.0)], vec![String::new()]);
        let (a, b) = (tracker_default(&near, &noise), tracker_default(&far, &noise));
        assert_eq!(a.source, NoiseSource::TrackerDefault);
        assert!(a.instrument.as_deref().is_some_and(|s| s.contains("AT901")));
        // At 1 m: radial 5 µm, transverse 10.5 µm: σ² = (25 + 2·110.25)/3 µm².
        assert!((a.sigma_mm - ((25.0 + 220.5) / 3.0f64).sqrt() * 1e-3).abs() < 1e-12, "{}", a.sigma_mm);
        assert!(b.sigma_mm > 2.0 * a.sigma_mm);
        assert!((a.floor_mm / a.sigma_mm - MEAN_DISTANCE_PER_SIGMA).abs() < 1e-12);
    }

    #[test]
    fn repeats_give_the_pooled_scatter_and_too_few_give_none() {
        let mut rows = Vec::new();
        for k in 0..5 {
            rows.push(row(k as f64, 1.0));
            rows.push(row(k as f64, 1.0 + 2e-5));
        }
        let set = MeasurementSet::from_rows("t", rows.clone(), vec![String::new()]);
        // Each pair: deviations ±1e-5 m on x, 3 dof per pair: σ² = 5·2e-10 / 15.
        let sigma = from_repeats(&set).unwrap();
        assert!((sigma - (1e-9 / 15.0f64).sqrt() * 1e3).abs() < 1e-12, "{sigma}");
        let set = MeasurementSet::from_rows("t", rows[..8].to_vec(), vec![String::new()]);
        assert_eq!(from_repeats(&set), None);
    }
}
