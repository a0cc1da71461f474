//! One joint of a local POE chain.

use lie::{SE3, Twist, Vector3};
use serde::{Deserialize, Serialize};

/// Whether a joint turns or slides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum JointKind {
    /// Rotation about the local z axis; the joint value is in radians.
    Revolute,
    /// Translation along the local z axis; the joint value is in metres.
    Prismatic,
}

impl JointKind {
    /// The joint twist `s_i` in its local frame (paper Eq. 1): the local frame's z axis.
    ///
    /// Chen et al.'s local POE fixes the twist in the local frame so that every kinematic error is
    /// absorbed by the constant transform `T_{i-1,i}(0)`.
    pub fn local_twist(self) -> Twist {
        match self {
            JointKind::Revolute => Twist::new(Vector3::zeros(), Vector3::z()),
            JointKind::Prismatic => Twist::new(Vector3::z(), Vector3::zeros()),
        }
    }
}

/// A joint: the constant transform from the previous frame to this joint's frame at zero joint value,
/// `T_{i-1,i}(0) = exp(p̂_i)`, and the kind of motion about or along that frame's z axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Joint {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// `T_{i-1,i}(0)`: the previous frame from this joint's frame at zero joint value.
    pub previous_from_joint_zero: SE3,
}

impl Joint {
    /// `T_{i-1,i}(q) = exp(p̂_i) · exp(ŝ_i q)` (paper Eq. 2).
    pub fn previous_from_joint(&self, q: f64) -> SE3 {
        self.previous_from_joint_zero * (self.kind.local_twist() * q).exp()
    }
}
