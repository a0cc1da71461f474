//! The errors of the `dynamics` crate: data that does not fit the robot it describes.

use std::fmt;

/// What is wrong with a robot's dynamics. `loadsim` refuses its own settings in these kinds too
/// (`loadsim::Error::Dynamics`, whose message is this one's), so that a simulation's refusal reads
/// the same whichever crate checked.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A list that needs one entry per joint (or per link) has the wrong length.
    LengthMismatch {
        /// Which list, e.g. `"stiffness_nm_per_rad"`.
        field: &'static str,
        /// Entries given.
        given: usize,
        /// Entries needed.
        expected: usize,
    },
    /// A joint index refers to no joint of the robot.
    UnknownJoint {
        /// Which setting carried it, e.g. `"counterbalance"`.
        field: &'static str,
        /// The 0-based index given.
        joint_index: usize,
        /// The robot's joint count.
        joint_count: usize,
    },
    /// A number is out of its physical range (negative stiffness, NaN, …).
    InvalidParameter {
        /// Which parameter.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// An effect needs the joint stiffness, but the robot's dynamics give masses only (a URDF's).
    MissingStiffness {
        /// The effect that needs it.
        effect: &'static str,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::LengthMismatch { field, given, expected } => {
                write!(f, "{field} has {given} entries, {expected} expected")
            }
            Error::UnknownJoint { field, joint_index, joint_count } => {
                // A user's file can hold usize::MAX: no overflow when numbering it from 1.
                write!(
                    f,
                    "{field} names joint {} but the robot has {joint_count} joints",
                    joint_index.saturating_add(1)
                )
            }
            Error::InvalidParameter { field, value } => write!(f, "{field} = {value} is out of range"),
            Error::MissingStiffness { effect } => write!(
                f,
                "{effect} needs the joint stiffness, but the robot's `dynamics` give masses only (a URDF has no \
                 stiffness): give `stiffness_nm_per_rad` in a RON robot file"
            ),
        }
    }
}

impl std::error::Error for Error {}
