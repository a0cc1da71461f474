//! A joint's kind as the refusals of several crates name it.

/// A joint's kind, as a refusal names it (the errors know no kinematics crate: `poe::JointKind`
/// maps onto this one by name).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// It turns about its axis; its value is an angle.
    Revolute,
    /// It slides along its axis; its value is a length.
    Prismatic,
}

impl JointKind {
    /// The kind as a URDF names it.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        }
    }
}
