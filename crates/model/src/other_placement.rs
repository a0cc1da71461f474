//! Data measured from another tracker placement than the model's. A model
//! predicts in the tracker frame it was fitted in; rows measured after the tracker moved miss by
//! the move, a rigid motion of every point, however good the model. `eval` fits one rigid motion
//! of the predicted tool points onto the measured ones (Kabsch): where it explains most of the
//! error, the error is the placement's, not the model's, and the warning gives what remains after
//! it and names `calib register`, which fits the new placement from a few rows.

use crate::{ErrorSummary, PoseError, pose_error};
use errors::OptionOutOfRange;
use lie::{SE3, Vector3};
use measurements::Measurement;
use serde::{Deserialize, Serialize};
use std::fmt;

/// When the error of an evaluation is said to be a tracker placement's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OtherPlacementOptions {
    /// The share of the squared position error one rigid motion must explain ("most of the
    /// error"): 0.5 leaves at most 0.71 of the RMS. On noise alone a rigid motion (6 parameters)
    /// explains about 6 / 3n of it; on the real UR10 (`docs/results/cell-check.md`, *eval on
    /// another placement*) it explains 0.4 % and 3 % of a model's error on rows of its own series,
    /// 69 % and 71 % between series B and C (a millimetre and 1–2 mrad apart, which `calib
    /// register` on 30 rows removes: 1.63 → 0.96 mm mean) and 100 % on series D (metres).
    pub explained_share: f64,
    /// The fewest rows judged: 10 rows put 6 parameters against 30 coordinates, noise alone
    /// explains a fifth of the squared error, well below `explained_share`.
    pub min_rows: usize,
}

impl Default for OtherPlacementOptions {
    fn default() -> Self {
        Self { explained_share: 0.5, min_rows: 10 }
    }
}

impl OtherPlacementOptions {
    /// Refuses a share outside (0, 1) or fewer rows than a rigid motion has parameters.
    pub fn validate(&self) -> Result<(), OptionOutOfRange> {
        let share = self.explained_share;
        OptionOutOfRange::check("explained_share", share, share > 0.0 && share < 1.0, "a number in (0, 1)")?;
        let expected = "at least 7 (a rigid motion has 6 parameters)";
        OptionOutOfRange::check("min_rows", self.min_rows as f64, self.min_rows >= 7, expected)
    }
}

/// An evaluation whose error one rigid motion of the predictions explains.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OtherPlacement {
    /// The RMS position error as evaluated, mm.
    pub rms_position_error_mm: f64,
    /// The errors after the rigid motion (fitted to the positions; rotations for full-pose data).
    pub after: ErrorSummary,
    /// How far the motion moves the predicted points, mean, mm.
    pub moved_mm: f64,
    /// The motion's angle, mrad.
    pub turned_mrad: f64,
}

impl OtherPlacement {
    /// The check on `rows` with each row's predicted tool pose `predicted` (tracker frame);
    /// `with_rotations` where the evaluation gives rotation errors. `None` where the rows are too
    /// few or the motion explains less than the options' share.
    pub fn of(
        rows: &[Measurement],
        predicted: &[SE3],
        with_rotations: bool,
        options: &OtherPlacementOptions,
    ) -> Option<Self> {
        if rows.len() < options.min_rows || rows.len() != predicted.len() {
            return None;
        }
        let from: Vec<Vector3> = predicted.iter().map(SE3::translation).collect();
        let to: Vec<Vector3> = rows.iter().map(|r| r.position).collect();
        let squared = |a: &[Vector3]| a.iter().zip(&to).map(|(p, m)| (m - p).norm_squared()).sum::<f64>();
        let before = squared(&from);
        let motion = poe::identify::kabsch(&from, &to);
        let moved: Vec<Vector3> = from.iter().map(|p| motion.transform_point(p)).collect();
        let after = squared(&moved);
        if !(before > 0.0 && after.is_finite() && after <= (1.0 - options.explained_share) * before) {
            return None;
        }
        let errors: Vec<PoseError> = predicted
            .iter()
            .zip(rows)
            .map(|(pose, row)| {
                let error = pose_error(&(motion * *pose), row);
                if with_rotations { error } else { PoseError { rotation_mrad: None, ..error } }
            })
            .collect();
        let count = rows.len() as f64;
        Some(Self {
            rms_position_error_mm: (before / count).sqrt() * 1e3,
            after: ErrorSummary::from_errors(&errors),
            moved_mm: from.iter().zip(&moved).map(|(a, b)| (b - a).norm()).sum::<f64>() / count * 1e3,
            turned_mrad: motion.rotation().log().norm() * 1e3,
        })
    }
}

impl fmt::Display for OtherPlacement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the data looks measured from another tracker placement than the model's (or with the robot or its \
             tool moved): one rigid motion of the predictions (moving them {:.1} mm on average, turning {:.1} mrad) leaves an RMS position error of {:.4} mm \
             of {:.4} mm (mean {:.4} mm, max {:.4} mm",
            self.moved_mm,
            self.turned_mrad,
            self.after.rms_position_error_mm,
            self.rms_position_error_mm,
            self.after.mean_position_error_mm,
            self.after.max_position_error_mm
        )?;
        if let Some(mean) = self.after.mean_rotation_error_mrad {
            write!(f, ", rotation mean {mean:.4} mrad")?;
        }
        write!(
            f,
            "); `calib register --model MODEL --data ROWS.csv --out REGISTERED.ron` fits the new placement from a \
             few of its rows (30 are plenty), everything else held"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lie::SO3;

    /// Rows on a spiral, predicted with a few tenths of a millimetre of the model's own error
    /// and measured through `placement`.
    fn rows(n: usize, placement: SE3) -> (Vec<Measurement>, Vec<SE3>) {
        (0..n)
            .map(|i| {
                let t = i as f64 * 0.37;
                let point = Vector3::new(0.8 * t.cos(), 0.8 * t.sin(), 0.5 + 0.003 * i as f64);
                let own = Vector3::new((i as f64 * 1.7).sin(), (i as f64 * 2.3).cos(), (i as f64 * 0.9).sin()) * 3e-4;
                let predicted = SE3::new(SO3::exp(&Vector3::new(0.1 * t, 0.2, -0.3)), point);
                let measured = placement * SE3::new(predicted.rotation(), point + own);
                let row = Measurement {
                    orientation: Some(measured.rotation()),
                    ..Measurement::at(vec![0.0; 6], measured.translation())
                };
                (row, predicted)
            })
            .unzip()
    }

    #[test]
    fn a_moved_tracker_is_named_with_what_remains_after_its_move() {
        let options = OtherPlacementOptions::default();
        options.validate().unwrap();
        let (same, predicted) = rows(60, SE3::identity());
        assert_eq!(OtherPlacement::of(&same, &predicted, true, &options), None);
        // The tracker moved 1.2 m and turned 0.3 rad.
        let moved = SE3::new(SO3::exp(&Vector3::new(0.0, 0.0, 0.3)), Vector3::new(1.2, 0.0, 0.0));
        let (rows, predicted) = rows(60, moved);
        let found = OtherPlacement::of(&rows, &predicted, true, &options).expect("another placement");
        assert!(found.rms_position_error_mm > 500.0, "{found:?}");
        assert!(found.after.rms_position_error_mm < 0.6 && found.after.rms_position_error_mm > 0.2, "{found:?}");
        assert!((found.turned_mrad - 300.0).abs() < 1.0, "{found:?}");
        assert!(found.after.mean_rotation_error_mrad.unwrap() < 0.05, "{found:?}");
        let text = found.to_string();
        assert!(text.contains("another tracker placement") && text.contains("calib register"), "{text}");
        // Too few rows to tell.
        assert_eq!(OtherPlacement::of(&rows[..9], &predicted[..9], true, &options), None);
    }

    #[test]
    fn options_out_of_range_are_refused_with_their_field_value_and_range() {
        for (options, message) in [
            (
                OtherPlacementOptions { explained_share: 1.0, ..Default::default() },
                "explained_share = 1: expected a number in (0, 1)",
            ),
            (
                OtherPlacementOptions { explained_share: f64::NAN, ..Default::default() },
                "explained_share = NaN: expected a number in (0, 1)",
            ),
            (
                OtherPlacementOptions { explained_share: 0.0, ..Default::default() },
                "explained_share = 0: expected a number in (0, 1)",
            ),
            (
                OtherPlacementOptions { min_rows: 6, ..Default::default() },
                "min_rows = 6: expected at least 7 (a rigid motion has 6 parameters)",
            ),
        ] {
            assert_eq!(options.validate().unwrap_err().to_string(), format!("option {message}"), "{options:?}");
        }
        assert!(OtherPlacementOptions { min_rows: 7, explained_share: 0.99 }.validate().is_ok());
    }
}
