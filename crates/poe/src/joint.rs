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

    /// The kind as a URDF names it (`revolute`, `prismatic`), and as a refusal names it.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
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
    /// Radians (or metres) the frame moves per unit of the joint value: 1 for a joint moved
    /// directly, the summed motion of the stages for one motor that drives several coaxial stages
    /// (a telescopic column's mimic joints). The twist `scale · s_i` keeps the model a product of
    /// exponentials, exactly. Written only where it is not 1, so model files without such a joint
    /// are unchanged.
    #[serde(default = "unit_scale", skip_serializing_if = "is_unit_scale")]
    pub scale: f64,
}

fn unit_scale() -> f64 {
    1.0
}

#[allow(clippy::trivially_copy_pass_by_ref)] // serde's `skip_serializing_if` passes a reference
fn is_unit_scale(scale: &f64) -> bool {
    *scale == 1.0
}

impl Joint {
    /// A joint moved directly by its value (scale 1).
    pub fn new(kind: JointKind, previous_from_joint_zero: SE3) -> Self {
        Self { kind, previous_from_joint_zero, scale: 1.0 }
    }

    /// The joint's twist in its local frame per unit of the joint value: `scale · s_i`.
    pub fn local_twist(&self) -> Twist {
        self.kind.local_twist() * self.scale
    }

    /// `T_{i-1,i}(q) = exp(p̂_i) · exp(ŝ_i · scale · q)` (paper Eq. 2).
    pub fn previous_from_joint(&self, q: f64) -> SE3 {
        self.previous_from_joint_zero * (self.local_twist() * q).exp()
    }
}
