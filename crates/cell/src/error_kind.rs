//! The refusals of the cell's work (registration, joint targets, URDF export): the kinds of
//! [`errors::Error`] this crate raises, with their messages.

use poe::JointKind;
use std::fmt;

/// What registration, joint targets and URDF export refuse.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A joint of the URDF written into (`export --like`) that turns where the model's slides, or
    /// the other way round: the URDF keeps its joint types, so it would be calibrated wrongly.
    ///
    /// At the URDF's `<joint>` element.
    UrdfJointKind {
        /// The joint's name in the URDF.
        joint: String,
        /// The joint's 1-based place among the chain's movable joints.
        index: usize,
        /// Its kind in the URDF.
        urdf: JointKind,
        /// The model's kind of that joint.
        model: JointKind,
    },
    /// A targets file with an orientation that cannot be used: without a position, or for a model
    /// fitted on positions only.
    ///
    /// At line 1, the orientation's column.
    TargetOrientation {
        /// Whether the position columns are missing (otherwise the model has no orientation).
        without_position: bool,
    },
    /// Targets whose meaning needs the robot description: joint targets (the nominal model) or
    /// poses in the base frame.
    ///
    /// At 1:1.
    TargetsNeedRobot {
        /// Whether the targets are poses (in the base frame) rather than joint targets.
        poses: bool,
    },
    /// A robot description that a base-and-tool fit cannot lay onto the calibrated model.
    RegistrationMismatch {
        /// RMS distance left, mm.
        rms_mm: f64,
        /// The largest accepted, mm.
        limit_mm: f64,
    },
    /// A model with parts a URDF cannot hold, exported without the training data that measure
    /// the error left without them.
    ExportNeedsData {
        /// The parts.
        parts: Vec<String>,
    },
    /// A prismatic joint exported without the limits a URDF requires (no nominal description).
    PrismaticWithoutLimits {
        /// 1-based joint.
        joint: usize,
    },
    /// Too few poses for what a registration re-fits: `rows` residual rows for `parameters`
    /// parameters, `needed_poses` poses wanted (or too few poses of one tool).
    TooFewPoses {
        /// What is short: `the registration` or `tool 'x'`.
        what: String,
        /// Poses given.
        poses: usize,
        /// Poses needed.
        needed_poses: usize,
        /// Residual rows given.
        rows: usize,
        /// Parameters re-fitted.
        parameters: usize,
    },
    /// Registration data that name a tool the model does not know, and tools are not re-fitted.
    ///
    /// At the first row with it, its `tool` column.
    NewToolWithoutRefit {
        /// The tool's identifier.
        tool: String,
    },
    /// Poses that do not determine what a registration re-fits (e.g. all points on a line, or
    /// one flange orientation for a tool offset and a base rotation).
    PosesUndetermined {
        /// Directions the poses determine.
        rank: usize,
        /// Parameters re-fitted.
        parameters: usize,
        /// Largest over smallest singular value of the scaled Jacobian.
        condition: f64,
    },
    /// The registration's least squares did not converge.
    RegistrationNotConverged {
        /// Iterations run.
        iterations: usize,
        /// RMS residual at the end, m.
        rms_m: f64,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::UrdfJointKind { joint, index, urdf, model } => write!(
                f,
                "joint '{joint}' (movable joint {index}) is {} in the URDF but {} in the \
                 model: refusing to write the calibration into a joint of another kind",
                urdf.name(),
                model.name()
            ),
            ErrorKind::TargetOrientation { without_position: true } => {
                write!(f, "an orientation without x_mm, y_mm, z_mm: give the whole pose, or joint targets alone")
            }
            ErrorKind::TargetOrientation { without_position: false } => write!(
                f,
                "the model was fitted on positions only, its orientation is not calibrated: give position targets"
            ),
            ErrorKind::TargetsNeedRobot { poses: false } => write!(
                f,
                "joint targets are a program taught on the nominal model: give its robot description (--robot)"
            ),
            ErrorKind::TargetsNeedRobot { poses: true } => {
                write!(f, "poses in the base frame need the robot description (--robot) to place the base")
            }
            ErrorKind::RegistrationMismatch { rms_mm, limit_mm } => write!(
                f,
                "this robot, placed on the model by base and tool, stays {rms_mm:.1} mm from it (at most {limit_mm} mm expected): give the robot description the model was fitted with"
            ),
            ErrorKind::ExportNeedsData { parts } => write!(
                f,
                "the model has {} that a URDF cannot hold: give its training data (--data) to measure the error left without them",
                parts.join(" and ")
            ),
            ErrorKind::PrismaticWithoutLimits { joint } => write!(
                f,
                "joint {joint} is prismatic and a URDF needs its limits: give the robot description (--robot or --like)"
            ),
            ErrorKind::TooFewPoses { what, poses, needed_poses, rows, parameters } => write!(
                f,
                "too few poses for {what}: {poses} poses ({rows} residual rows) for {parameters} re-fitted \
                 parameters; at least {needed_poses} poses are needed"
            ),
            ErrorKind::NewToolWithoutRefit { tool } => write!(
                f,
                "tool '{tool}' is not in the model; re-fit tools to add it (--refit tools or --refit base,tools)"
            ),
            ErrorKind::PosesUndetermined { rank, parameters, condition } => write!(
                f,
                "the poses determine only {rank} of the {parameters} re-fitted parameters (condition number \
                 {condition:.3e}): measure poses with more varied joint angles and flange orientations"
            ),
            ErrorKind::RegistrationNotConverged { iterations, rms_m } => write!(
                f,
                "the registration did not converge in {iterations} iterations (RMS residual {:.4} mm)",
                rms_m * 1e3
            ),
        }
    }
}

impl std::error::Error for ErrorKind {}

impl errors::Kind for ErrorKind {}

#[cfg(test)]
mod tests {
    use super::ErrorKind;
    use errors::Error;

    #[test]
    fn the_registration_kinds_keep_the_messages_of_their_former_enum() {
        // The texts `cell::Error` wrote before it was folded into `errors`, and then out again.
        let error = Error::at_line("d.csv", 7, 3, ErrorKind::NewToolWithoutRefit { tool: "probe".into() });
        assert_eq!(
            error.to_string(),
            "d.csv:7:3: tool 'probe' is not in the model; re-fit tools to add it (--refit tools or --refit base,tools)"
        );
        let kind = ErrorKind::TooFewPoses {
            what: "the registration".into(),
            poses: 8,
            needed_poses: 9,
            rows: 24,
            parameters: 9,
        };
        assert_eq!(
            kind.to_string(),
            "too few poses for the registration: 8 poses (24 residual rows) for 9 re-fitted parameters; at least 9 poses are needed"
        );
        let kind = ErrorKind::PosesUndetermined { rank: 5, parameters: 6, condition: 1234.5 };
        assert_eq!(
            kind.to_string(),
            "the poses determine only 5 of the 6 re-fitted parameters (condition number 1.234e3): measure poses with more varied joint angles and flange orientations"
        );
        let kind = ErrorKind::RegistrationNotConverged { iterations: 50, rms_m: 0.000_123_4 };
        assert_eq!(kind.to_string(), "the registration did not converge in 50 iterations (RMS residual 0.1234 mm)");
        assert!(matches!(error.kind::<ErrorKind>(), Some(ErrorKind::NewToolWithoutRefit { .. })));
    }
}
