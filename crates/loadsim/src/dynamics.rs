//! The mass and stiffness data of a robot that the load model needs, as stored in the robot RON.

use serde::{Deserialize, Serialize};

/// The mass of one moving body and where its centre of mass is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinkInertia {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Centre of mass at the zero configuration, base frame, metres.
    pub com_m: [f64; 3],
}

/// What the load model knows of a robot beyond its geometry. Link `i` (0-based) is the body moved
/// by joint `i + 1` (and every joint before it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotDynamics {
    /// One entry per joint: the body that joint moves.
    pub links: Vec<LinkInertia>,
    /// Joint stiffness, N·m/rad (N/m for a prismatic joint), one per joint.
    pub stiffness_nm_per_rad: Vec<f64>,
}
