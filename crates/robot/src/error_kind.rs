//! The refusals of the robot readers and checks: the kinds of [`errors::Error`] this crate raises, with
//! their messages (the error adds the place a message starts with).

use std::fmt;

/// What the robot readers (RON, URDF, DH) and the robot checks refuse.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A URDF file that does not parse, or whose kinematic chain cannot be calibrated.
    UrdfFormat {
        /// What is wrong.
        message: String,
    },
    /// A nominal robot description whose joints are not where a calibrated model has them, once
    /// its base is placed by joint 1: not the description the model was fitted with.
    NominalMismatch {
        /// 1-based joint that is furthest off.
        joint: usize,
        /// Distance of the model's joint frame origin from the description's axis, mm.
        offset_mm: f64,
        /// Angle between the two axes, mrad.
        angle_mrad: f64,
        /// The largest offset accepted, mm.
        limit_mm: f64,
        /// The largest angle accepted, mrad.
        limit_mrad: f64,
    },
    /// A robot description with another number of joints than a calibrated model.
    RobotJointCount {
        /// Its joints.
        robot: usize,
        /// The model's joints.
        model: usize,
    },
    /// Two consecutive joints of a robot description whose motions are one (revolute about the
    /// same line, or prismatic along the same direction): their Jacobian columns are equal.
    ///
    /// At the second joint's axis in a RON file; the file alone otherwise.
    RepeatedJointAxis {
        /// The first joint, 1-based.
        first: usize,
        /// The second joint, 1-based.
        second: usize,
        /// Whether they are revolute (otherwise prismatic).
        revolute: bool,
        /// The second joint's axis direction.
        axis: [f64; 3],
        /// A point on it.
        point: [f64; 3],
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::UrdfFormat { message } => write!(f, "{message}"),
            ErrorKind::NominalMismatch { joint, offset_mm, angle_mrad, limit_mm, limit_mrad } => write!(
                f,
                "joint {joint} of this robot is {offset_mm:.1} mm and {angle_mrad:.1} mrad from the model's (at most {limit_mm} mm and {limit_mrad} mrad expected): give the robot description the model was fitted with"
            ),
            ErrorKind::RobotJointCount { robot, model } => {
                write!(f, "the robot has {robot} joints, the model {model}: not the robot the model was fitted for")
            }
            ErrorKind::RepeatedJointAxis { first, second, revolute, axis, point } => {
                let [a, b, c] = axis;
                let [x, y, z] = point;
                if *revolute {
                    write!(
                        f,
                        "joints {first} and {second} turn about the same line (direction ({a}, {b}, {c}) through \
                         ({x}, {y}, {z}) m): no joint between them moves one off the other, so their columns in the \
                         identification Jacobian are equal at every pose and their angles cannot be told apart; \
                         correct the axis or merge the two joints"
                    )
                } else {
                    write!(
                        f,
                        "joints {first} and {second} slide along the same direction ({a}, {b}, {c}): their columns \
                         in the identification Jacobian are equal at every pose and their values cannot be told apart; \
                         correct the axis or merge the two joints"
                    )
                }
            }
        }
    }
}

impl std::error::Error for ErrorKind {}

impl errors::Kind for ErrorKind {}
