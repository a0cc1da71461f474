//! The refusals of the fit pipeline (a fitted model a file could not hold, implausible data): the
//! kinds of [`errors::Error`] this crate raises, with their messages.

use poe::JointKind;
use std::fmt;

/// What the fit pipeline refuses.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A fit produced a model that the model file's check refuses: `fit` says so rather than
    /// write a file that `eval` would refuse.
    FittedModelRefused {
        /// The method fitted.
        method: String,
        /// The check's refusal (an [`Error`](errors::Error), boxed so that the kinds stay apart
        /// from the error that carries them).
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// Measured positions that leave a plane, for a planar chain (whose tool moves in one): the
    /// data of another robot, or a joint axis wrong in the robot file.
    PlanarChainData {
        /// The robot's name.
        robot: String,
        /// The direction every revolute axis is parallel to.
        direction: [f64; 3],
        /// The joint count.
        joints: usize,
        /// RMS distance of the measured positions from their best plane, mm.
        out_of_plane_mm: f64,
        /// RMS distance of the measured positions from their centroid, mm.
        spread_mm: f64,
        /// Refused above this ratio of the two (`PlausibilityOptions::planar_ratio`).
        ratio: f64,
    },
    /// A joint value beyond the robot's limits by more than the margin
    /// (`PlausibilityOptions::limit_margin_rad`): the first in file order.
    ///
    /// At the value: line 0 and the joint's number as column for rows made in memory.
    JointBeyondLimits {
        /// 1-based joint.
        joint: usize,
        /// Revolute (value and limits in radians) or prismatic (metres).
        kind: JointKind,
        /// The value, SI.
        value: f64,
        /// The robot's limits, SI.
        limits: (f64, f64),
        /// The margin allowed beyond them, SI.
        margin: f64,
        /// Whether every value of the column, read as degrees, is within the limits (and the
        /// column says `_rad`).
        degrees_under_rad: bool,
    },
    /// Measured positions whose spread is not the robot's at the same joints: a unit mistake, a
    /// scale, or another robot (`PlausibilityOptions::scale_band`).
    PositionScale {
        /// RMS distance of the measured positions from their centroid, mm (read as the columns say).
        measured_spread_mm: f64,
        /// The same of the nominal model's tool points at the same joints, the tool fitted, mm.
        robot_spread_mm: f64,
        /// Measured over robot.
        ratio: f64,
        /// The unit the position columns name (`mm` or `m`).
        column_unit: &'static str,
        /// The unit the ratio says the positions are in, where it is near a unit mistake's factor.
        likely_unit: Option<&'static str>,
        /// The accepted ratios.
        band: (f64, f64),
    },
    /// Measured positions that a mirror image of the robot fits much better than the robot: a
    /// left-handed frame (`PlausibilityOptions::reflection_ratio`).
    LeftHandedFrame {
        /// RMS residual of the best rotation of the nominal tool points onto the measured, mm.
        rotation_rms_mm: f64,
        /// RMS residual of the best reflection, mm.
        reflection_rms_mm: f64,
        /// Refused where the reflection's residual is below this fraction of the rotation's.
        reflection_ratio: f64,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::FittedModelRefused { method, source } => write!(
                f,
                "the fitted {method} model fails the check every model file passes on reading, so it is not written: {source}"
            ),
            ErrorKind::PlanarChainData { robot, direction: [a, b, c], joints, out_of_plane_mm, spread_mm, ratio } => {
                write!(
                    f,
                    "the positions leave a plane, but {robot}'s chain is planar: all {joints} joints turn about \
                     axes parallel to ({a}, {b}, {c}), so its tool moves in a plane; the positions lie {out_of_plane_mm:.1} mm \
                     RMS off their best plane, {:.1} % of their {spread_mm:.1} mm spread (accepted: {:.1} %): the data of \
                     another robot, or a joint axis wrong in the robot file?",
                    100.0 * out_of_plane_mm / spread_mm,
                    100.0 * ratio
                )
            }
            ErrorKind::JointBeyondLimits { joint, kind, value, limits: (lo, hi), margin, degrees_under_rad } => {
                match kind {
                    JointKind::Revolute => write!(
                        f,
                        "joint {joint} is at {value} rad ({:.1}°), beyond its limits {:.1}° to {:.1}° by more than {:.1}°",
                        value.to_degrees(),
                        lo.to_degrees(),
                        hi.to_degrees(),
                        margin.to_degrees()
                    )?,
                    JointKind::Prismatic => write!(
                        f,
                        "joint {joint} is at {value} m, beyond its limits {lo} m to {hi} m by more than {margin} m"
                    )?,
                }
                if *degrees_under_rad {
                    write!(f, ": degrees under `_rad`? (every value of the column fits the limits read as degrees)")?;
                }
                write!(f, " (--force fits anyway)")
            }
            ErrorKind::PositionScale { measured_spread_mm, robot_spread_mm, ratio, column_unit, likely_unit, band } => {
                let spreads = format!(
                    "measured spread {measured_spread_mm:.4} mm, the robot's {robot_spread_mm:.1} mm at these joints: ratio {ratio:.4}"
                );
                match likely_unit {
                    Some(unit) => write!(
                        f,
                        "positions look like {unit} under _{column_unit} columns ({spreads}); give the columns the positions' unit (--force fits anyway)"
                    ),
                    None => write!(
                        f,
                        "the positions do not have the robot's size ({spreads}, outside {} to {}): a unit, a scale or another robot's description? (--force fits anyway)",
                        band.0, band.1
                    ),
                }
            }
            ErrorKind::LeftHandedFrame { rotation_rms_mm, reflection_rms_mm, .. } => write!(
                f,
                "the measured frame looks left-handed: two position columns swapped? (the robot turned onto the measurements leaves {rotation_rms_mm:.1} mm RMS, its mirror image {reflection_rms_mm:.1} mm) (--force fits anyway)"
            ),
        }
    }
}

impl std::error::Error for ErrorKind {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ErrorKind::FittedModelRefused { source, .. } => Some(source.as_ref()),
            _ => None,
        }
    }
}

impl errors::Kind for ErrorKind {}
