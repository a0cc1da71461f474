//! The robot: its description (joint axes, types, limits, flange, tools, load data), read from the
//! robot RON, a standard or modified DH table, or a URDF chain between two links (mimic joints folded),
//! checked once where it is read, and the base-frame geometry of a fitted model.
//!
//! ```
//! # let fixture = |name: &str| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name);
//! let robot = robot::RobotDescription::read(&fixture("ur10.ron"))?;
//! assert_eq!(robot.joint_count(), 6);
//! let nominal = robot.nominal_model()?; // the local POE model of the nominal kinematics
//! assert_eq!(nominal.joint_count(), 6);
//! // The same arm as a URDF, the chain from its root link to its deepest leaf.
//! let urdf = robot::RobotDescription::read(&fixture("ur10.urdf"))?;
//! assert_eq!(urdf.joint_count(), 6);
//! // What is not a robot is refused at its file, line and column.
//! let error = robot::RobotDescription::parse("(name: \"arm\", joints: [])", "arm.ron").unwrap_err();
//! assert!(error.to_string().starts_with("arm.ron:1:"), "{error}");
//! # Ok::<(), errors::Error>(())
//! ```
#![deny(missing_docs)]

mod base_frame;
mod bounds;
mod description;
mod error_kind;
mod read;
mod robot_check;
mod robot_dh;
mod urdf_chain;
mod urdf_inertial;
mod urdf_mimic;
mod urdf_model;
mod urdf_steps;
pub mod xml_outline;
pub use bounds::{MAX_TRANSLATION_M, PITCH_BOUNDS_MM, bad_translation};
pub use error_kind::ErrorKind;

pub use base_frame::{NominalTolerance, axis_changes, check_nominal, in_base_frame, tracker_from_base};
pub use description::{
    FlangeDescription, FoldedJoint, JointDescription, MimicStage, RobotDescription, SCALE_BOUNDS, scale_in_bounds,
};
pub use robot_dh::{DhTable, DhTableRow};
pub use urdf_chain::{ChainEnds, UrdfChain, UrdfDocument};
pub use urdf_inertial::MAX_LINK_MASS_KG;
pub use urdf_mimic::ChainJoint;
pub use urdf_model::{UrdfJoint, UrdfJointType, UrdfLimit, UrdfLink, UrdfMimic, UrdfOrigin, UrdfRobot};
pub use urdf_steps::{ChainStep, StepMimic, StepMotion};
