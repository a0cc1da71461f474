//! What a robot description states beyond its geometry: the mass and centre of mass of the body
//! each joint moves, the joint stiffness, a spring balancer on one joint, and gravity in the base
//! frame ([`RobotDynamics`]), as the robot RON (and a URDF's `<inertial>`s) give them.
//!
//! The data alone, with the checks that tie it to a robot's joint count: `robot` reads and writes
//! it, `loadsim` simulates with it (and re-exports it), so that reading a robot file does not
//! build the simulator.
#![deny(missing_docs)]

mod counterbalance;
mod error;
mod robot_dynamics;

pub use counterbalance::Counterbalance;
pub use error::Error;
pub use robot_dynamics::{FLOOR_GRAVITY_M_PER_S2, LinkInertia, RobotDynamics, tilted_base_gravity};
