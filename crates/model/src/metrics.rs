//! Accuracy metrics of a calibrated model on measurements.

use lie::SE3;
use measurements::Measurement;
use serde::{Deserialize, Serialize};

/// The error of one measured pose: distance and rotation angle between measured and predicted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseError {
    /// Distance between measured and predicted tool points, millimetres.
    pub position_mm: f64,
    /// Angle of the rotation between measured and predicted orientation, milliradians
    /// (`None` for position-only rows).
    pub rotation_mrad: Option<f64>,
}

/// Summary statistics of a set of pose errors (the SPEC's `calib eval --json` fields).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorSummary {
    /// Number of rows.
    pub n: usize,
    /// Mean position error, mm.
    pub mean_position_error_mm: f64,
    /// Root-mean-square position error, mm.
    pub rms_position_error_mm: f64,
    /// Largest position error, mm.
    pub max_position_error_mm: f64,
    /// Median position error, mm.
    pub median_position_error_mm: f64,
    /// Mean rotation error, mrad, for full-pose data.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_rotation_error_mrad: Option<f64>,
    /// Largest rotation error, mrad, for full-pose data.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_rotation_error_mrad: Option<f64>,
}

impl ErrorSummary {
    /// Summarises per-row errors. An empty slice gives zeros and `n = 0`.
    pub fn from_errors(errors: &[PoseError]) -> Self {
        let n = errors.len();
        let count = n.max(1) as f64;
        let mut positions: Vec<f64> = errors.iter().map(|e| e.position_mm).collect();
        positions.sort_by(f64::total_cmp);
        let median = match n {
            0 => 0.0,
            _ if n % 2 == 1 => positions[n / 2],
            _ => 0.5 * (positions[n / 2 - 1] + positions[n / 2]),
        };
        let rotations: Vec<f64> = errors.iter().filter_map(|e| e.rotation_mrad).collect();
        let full_pose = !rotations.is_empty() && rotations.len() == n;
        Self {
            n,
            mean_position_error_mm: positions.iter().sum::<f64>() / count,
            rms_position_error_mm: (positions.iter().map(|p| p * p).sum::<f64>() / count).sqrt(),
            max_position_error_mm: positions.last().copied().unwrap_or(0.0),
            median_position_error_mm: median,
            mean_rotation_error_mrad: full_pose.then(|| rotations.iter().sum::<f64>() / count),
            max_rotation_error_mrad: full_pose.then(|| rotations.iter().copied().fold(0.0, f64::max)),
        }
    }
}

/// The error of a prediction against a measured row.
pub fn pose_error(predicted: &SE3, row: &Measurement) -> PoseError {
    PoseError {
        position_mm: (row.position - predicted.translation()).norm() * 1e3,
        rotation_mrad: row.orientation.map(|measured| (measured * predicted.rotation().inverse()).log().norm() * 1e3),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_of_known_errors_has_the_textbook_statistics() {
        let errors: Vec<PoseError> =
            [3.0, 4.0, 1.0, 2.0].iter().map(|&p| PoseError { position_mm: p, rotation_mrad: Some(p / 2.0) }).collect();
        let s = ErrorSummary::from_errors(&errors);
        assert_eq!(s.n, 4);
        assert_eq!(s.mean_position_error_mm, 2.5);
        assert_eq!(s.max_position_error_mm, 4.0);
        assert_eq!(s.median_position_error_mm, 2.5);
        assert!((s.rms_position_error_mm - (30.0f64 / 4.0).sqrt()).abs() < 1e-15);
        assert_eq!(s.mean_rotation_error_mrad, Some(1.25));
    }

    #[test]
    fn position_only_rows_have_no_rotation_statistics() {
        let s = ErrorSummary::from_errors(&[PoseError { position_mm: 1.0, rotation_mrad: None }]);
        assert_eq!(s.mean_rotation_error_mrad, None);
    }
}
