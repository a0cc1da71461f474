//! Non-geometric error models of a serial robot: payload and gravity deflection through joint
//! compliance (the paper's ref. [15]), backlash, gear periodic error, thermal growth, drift and
//! tracker noise.
#![deny(missing_docs)]

mod dynamics;

pub use dynamics::{LinkInertia, RobotDynamics};
