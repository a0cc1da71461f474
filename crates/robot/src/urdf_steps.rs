//! The steps of a URDF chain from its base link to its tip link, as read: what the chain reader
//! makes and the mimic fold takes.

use lie::{SE3, Vector3};

/// How a step of the chain moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepMotion {
    /// A fixed joint, folded into the neighbouring transforms.
    Fixed,
    /// A revolute joint with its limits (radians), or a continuous one (`None`).
    Revolute {
        /// Lower and upper limit, radians.
        limits_rad: Option<(f64, f64)>,
    },
    /// A prismatic joint with its limits, metres.
    Prismatic {
        /// Lower and upper limit, metres.
        limits_m: (f64, f64),
    },
}

/// One joint on the chain, in the direction from the base link to the tip link.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainStep {
    /// The URDF joint's name.
    pub joint: String,
    /// The link the step leaves.
    pub from_link: String,
    /// The link the step reaches.
    pub to_link: String,
    /// Whether the step runs the joint from its child to its parent (fixed joints only).
    pub reversed: bool,
    /// Fixed, revolute or prismatic.
    pub motion: StepMotion,
    /// `from_link_from_to_link` at zero joint value.
    pub from_to: SE3,
    /// Unit axis of a movable joint in `to_link`'s frame.
    pub axis: Vector3,
    /// The joint this one follows (`<mimic>`), for a movable joint.
    pub mimic: Option<StepMimic>,
}

/// A `<mimic>` element as the URDF writes it (multiplier 1 and offset 0 where left out, as the
/// URDF specification says).
#[derive(Debug, Clone, PartialEq)]
pub struct StepMimic {
    /// The joint it follows.
    pub joint: String,
    /// Its value is `multiplier · q + offset`, `q` the followed joint's value.
    pub multiplier: f64,
    /// Radians or metres.
    pub offset: f64,
}
