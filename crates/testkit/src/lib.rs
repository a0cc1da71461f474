//! Test helpers shared by the calibration crates' tests: the robot files under `fixtures/robots`,
//! read by name. Only dev-dependencies name this crate, so no library or binary depends on it and
//! it may sit anywhere above `robot` without turning the crate graph back on itself. (`loadsim` and
//! `poe` lie below `robot` and keep their own fixtures.)
//!
//! ```
//! let irb = testkit::robot("irb4400.ron");
//! assert_eq!(irb.joint_count(), 6);
//! assert!(testkit::robot_path("iiwa7.ron").is_file());
//! ```

use robot::RobotDescription;
use std::path::PathBuf;

/// The path of `fixtures/robots/<name>` in the workspace (`name` with its extension).
pub fn robot_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name)
}

/// The fixture robot `fixtures/robots/<name>` (RON, DH or URDF, as `RobotDescription::read` takes
/// them).
///
/// # Panics
/// Where the file is missing or refused: a test has no use for a robot it cannot read.
pub fn robot(name: &str) -> RobotDescription {
    let path = robot_path(name);
    RobotDescription::read(&path).unwrap_or_else(|e| panic!("fixture robot {}: {e}", path.display()))
}
