//! The mass and stiffness data of a robot that the load model needs, as stored in the robot RON.

use crate::{Counterbalance, Error};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};

/// Gravity in the base frame of a floor-mounted robot (base z up), m/s².
pub const FLOOR_GRAVITY_M_PER_S2: [f64; 3] = [0.0, 0.0, -9.81];

/// Gravity in the base frame of a robot whose base is tilted by `tilt_rad` from upright about the
/// horizontal base axis at `azimuth_rad` from base x (towards base y), m/s²: 0 is a floor mount,
/// π/2 a wall mount, π a ceiling mount. On a tilted base joint 1's axis is no longer vertical, so
/// gravity loads it: this is how a joint-1 compliance or backlash becomes visible at all.
pub fn tilted_base_gravity(tilt_rad: f64, azimuth_rad: f64) -> [f64; 3] {
    let axis = lie::Vector3::new(azimuth_rad.cos(), azimuth_rad.sin(), 0.0);
    // world_from_base turns the base by `tilt` about `axis`; gravity in the base frame is
    // base_from_world · (0, 0, −g).
    let base_from_world = lie::SO3::exp(&(axis * -tilt_rad));
    let g = base_from_world.act(&lie::Vector3::from(FLOOR_GRAVITY_M_PER_S2));
    [g.x, g.y, g.z]
}

fn floor_gravity() -> [f64; 3] {
    FLOOR_GRAVITY_M_PER_S2
}

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
    /// Joint stiffness, N·m/rad (N/m for a prismatic joint), one per joint; empty where it is not
    /// known (a URDF gives masses but no stiffness): then joint compliance cannot be simulated
    /// ([`RobotDynamics::stiffness`] refuses), while what needs the masses alone (gravity torque,
    /// backlash's sign, link deflection) still can.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stiffness_nm_per_rad: Vec<f64>,
    /// A spring or gas-spring balancer acting on one joint (joint 2 of most large arms), if fitted.
    #[serde(default)]
    pub counterbalance: Option<Counterbalance>,
    /// Gravity in the base frame, m/s²; `(0, 0, -9.81)` for a floor-mounted robot, the default.
    /// A wall- or ceiling-mounted robot states its own.
    #[serde(default = "floor_gravity")]
    pub gravity_m_per_s2: [f64; 3],
}

impl RobotDynamics {
    /// Checks the data against a robot with `joint_count` joints: one link per joint, one
    /// stiffness per joint or none at all, masses finite and non-negative, stiffness finite and
    /// positive, a valid balancer.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        if self.links.len() != joint_count {
            return Err(Error::LengthMismatch { field: "links", given: self.links.len(), expected: joint_count });
        }
        if !self.stiffness_nm_per_rad.is_empty() && self.stiffness_nm_per_rad.len() != joint_count {
            return Err(Error::LengthMismatch {
                field: "stiffness_nm_per_rad",
                given: self.stiffness_nm_per_rad.len(),
                expected: joint_count,
            });
        }
        for link in &self.links {
            if !(link.mass_kg.is_finite() && link.mass_kg >= 0.0) {
                return Err(Error::InvalidParameter { field: "links.mass_kg", value: link.mass_kg });
            }
            if let Some(&c) = link.com_m.iter().find(|c| !c.is_finite()) {
                return Err(Error::InvalidParameter { field: "links.com_m", value: c });
            }
        }
        if let Some(&k) = self.stiffness_nm_per_rad.iter().find(|k| !(k.is_finite() && **k > 0.0)) {
            return Err(Error::InvalidParameter { field: "stiffness_nm_per_rad", value: k });
        }
        if let Some(&g) = self.gravity_m_per_s2.iter().find(|g| !g.is_finite()) {
            return Err(Error::InvalidParameter { field: "gravity_m_per_s2", value: g });
        }
        if let Some(balancer) = &self.counterbalance {
            balancer.validate(joint_count)?;
        }
        Ok(())
    }

    /// The joint stiffness, or the error that `effect` needs it where the robot gives none.
    pub fn stiffness(&self, effect: &'static str) -> Result<&[f64], Error> {
        if self.stiffness_nm_per_rad.is_empty() {
            return Err(Error::MissingStiffness { effect });
        }
        Ok(&self.stiffness_nm_per_rad)
    }

    /// The stacked inertial parameters `π = (m_1, m_1 c_1, …, m_n, m_n c_n)` (4 per link, `c_k` at
    /// the zero configuration in the base frame), so that the links' gravity torque is
    /// `Y(q) · π` with `Y` from `loadsim::gravity_regressor`.
    pub fn inertial_parameters(&self) -> DVector<f64> {
        DVector::from_iterator(
            4 * self.links.len(),
            self.links
                .iter()
                .flat_map(|l| [l.mass_kg, l.mass_kg * l.com_m[0], l.mass_kg * l.com_m[1], l.mass_kg * l.com_m[2]]),
        )
    }

    /// Sum of the link masses, kg (the moving part of the arm; the fixed base is not a link).
    pub fn moving_mass_kg(&self) -> f64 {
        self.links.iter().map(|l| l.mass_kg).sum()
    }
}
