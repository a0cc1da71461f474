//! The errors of the `loadsim` crate.

use std::fmt;

/// What can go wrong when configuring or running a simulation.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// The kinematic model refused the request (wrong joint count, unknown tool).
    Kinematics {
        /// The error of the `poe` crate.
        source: poe::Error,
    },
    /// A setting does not fit the robot (a list's length, a joint index, a number out of its
    /// physical range, a stiffness the robot does not give): the kinds `dynamics` refuses a
    /// robot's dynamics with, and the same text whichever crate checked.
    Dynamics {
        /// The refusal, in the kinds of the `dynamics` crate.
        source: dynamics::Error,
    },
    /// An effect needs the robot's masses and stiffness, but the robot description has none.
    MissingDynamics {
        /// The effect that needs them.
        effect: &'static str,
    },
    /// A joint range is empty once the margin is taken off both ends.
    EmptyJointRange {
        /// 0-based joint index.
        joint_index: usize,
        /// Lower limit, rad.
        lower_rad: f64,
        /// Upper limit, rad.
        upper_rad: f64,
        /// Margin taken off each end, rad.
        margin_rad: f64,
    },
    /// A coupled joint error whose factor is the joint's own angle (that is a gear error).
    SelfCoupling {
        /// The 0-based joint index.
        joint_index: usize,
    },
    /// A screw's or rack's periodic error on a revolute joint (its period is a length).
    NotPrismatic {
        /// Which setting carried it, e.g. `"screw"`.
        field: &'static str,
        /// The 0-based joint index.
        joint_index: usize,
    },
    /// A campaign setting that does not fit the cell or the other settings.
    Campaign {
        /// Which setting, e.g. `"tool_per_run"`.
        field: &'static str,
        /// What it needs, e.g. `"one tool per payload run"`.
        needs: &'static str,
        /// The count given.
        given: usize,
        /// The count needed.
        expected: usize,
    },
    /// The generator rejected too many candidate poses as near-singular.
    SamplingExhausted {
        /// Poses accepted before giving up.
        accepted: usize,
        /// Candidates drawn.
        attempts: usize,
    },
}

impl From<poe::Error> for Error {
    fn from(source: poe::Error) -> Self {
        Error::Kinematics { source }
    }
}

impl From<dynamics::Error> for Error {
    fn from(source: dynamics::Error) -> Self {
        Error::Dynamics { source }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Kinematics { source } => write!(f, "kinematic model: {source}"),
            // Transparent: the message is the robot's dynamics' own.
            Error::Dynamics { source } => fmt::Display::fmt(source, f),
            Error::MissingDynamics { effect } => {
                write!(f, "{effect} needs link masses and joint stiffness, but the robot has no `dynamics`")
            }
            Error::EmptyJointRange { joint_index, lower_rad, upper_rad, margin_rad } => write!(
                f,
                "joint {} range [{lower_rad}, {upper_rad}] rad is empty after a margin of {margin_rad} rad",
                joint_index.saturating_add(1)
            ),
            Error::SelfCoupling { joint_index } => write!(
                f,
                "coupling: joint {} is coupled to its own angle (a periodic error of its own angle is `periodic`)",
                joint_index.saturating_add(1)
            ),
            Error::NotPrismatic { field, joint_index } => write!(
                f,
                "{field}: joint {} is revolute, and a screw's or rack's error is periodic in a linear axis's position \
                 (a periodic error of a revolute joint's angle is `periodic`)",
                joint_index.saturating_add(1)
            ),
            Error::Campaign { field, needs, given, expected } => {
                write!(f, "{field} needs {needs}: {given} given, {expected} needed")
            }
            Error::SamplingExhausted { accepted, attempts } => write!(
                f,
                "only {accepted} poses accepted after {attempts} candidates: the singularity threshold is too strict"
            ),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Kinematics { source } => Some(source),
            // Transparent, as its message: what the `dynamics` error wraps, not the error itself.
            Error::Dynamics { source } => std::error::Error::source(source),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Error;

    #[test]
    fn the_largest_joint_index_a_file_can_hold_is_shown_without_overflow() {
        let error =
            Error::from(dynamics::Error::UnknownJoint { field: "backlash", joint_index: usize::MAX, joint_count: 6 });
        assert_eq!(error.to_string(), format!("backlash names joint {} but the robot has 6 joints", usize::MAX));
        assert!(Error::SelfCoupling { joint_index: usize::MAX }.to_string().contains(&usize::MAX.to_string()));
    }

    #[test]
    fn a_refusal_of_the_robots_dynamics_reads_the_same_through_loadsim() {
        let refusals = [
            dynamics::Error::LengthMismatch { field: "links", given: 5, expected: 6 },
            dynamics::Error::UnknownJoint { field: "counterbalance", joint_index: 6, joint_count: 6 },
            dynamics::Error::InvalidParameter { field: "links.mass_kg", value: -1.0 },
            dynamics::Error::MissingStiffness { effect: "joint compliance" },
        ];
        for refusal in refusals {
            assert_eq!(Error::from(refusal.clone()).to_string(), refusal.to_string());
        }
    }
}
