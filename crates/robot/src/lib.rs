//! The robot: its description (joint axes, types, limits, flange, tools, load data), read from the
//! robot RON, a standard or modified DH table, or a URDF chain between two links (mimic joints folded),
//! checked once where it is read, and the base-frame geometry of a fitted model.
#![deny(missing_docs)]

mod base_frame;
mod bounds;
mod description;
mod read;
mod robot_check;
mod robot_dh;
mod urdf_chain;
mod urdf_mimic;
mod urdf_steps;
pub mod xml_outline;
pub use bounds::{MAX_TRANSLATION_M, bad_translation};

pub use base_frame::{NominalTolerance, axis_changes, check_nominal, in_base_frame, tracker_from_base};
pub use description::{
    FlangeDescription, FoldedJoint, JointDescription, JointType, MimicStage, RobotDescription, SCALE_BOUNDS,
    scale_in_bounds,
};
pub use robot_dh::{DhTable, DhTableRow};
pub use urdf_chain::{ChainEnds, UrdfChain, UrdfDocument};
pub use urdf_mimic::ChainJoint;
pub use urdf_steps::{ChainStep, StepMimic, StepMotion};
