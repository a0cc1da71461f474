//! The local POE model of a serial chain (paper Eq. 1–3).

use crate::{Error, Joint, JointKind};
use lie::{Matrix3, SE3, SO3, Twist, Vector3};
use serde::{Deserialize, Serialize};

/// A joint axis at the zero configuration, in the reference (base) frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointAxis {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Unit direction of the axis, reference frame.
    pub direction: Vector3,
    /// A point on the axis, reference frame, metres.
    pub point: Vector3,
}

/// The local product-of-exponentials model (Chen, Yang et al., paper Eq. 3):
/// `T(q) = Π_i (exp(p̂_i) exp(ŝ_i q_i)) · exp(p̂_{n+1})`.
///
/// Frame 0 is the reference frame in which the tool is expressed: the robot base for a nominal
/// model, the tracker frame after calibration (the first local transform then also holds the
/// base placement). Each tool `t` has its own last transform `T_{n,n+1}(0)`; everything else is
/// shared between tools.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LocalPoe {
    joints: Vec<Joint>,
    tools: Vec<SE3>,
}

impl LocalPoe {
    /// A model from its joints and its tools' `joint_n_from_tool` transforms. With no tool given,
    /// the tool is the last joint frame itself.
    pub fn new(joints: Vec<Joint>, mut tools: Vec<SE3>) -> Self {
        if tools.is_empty() {
            tools.push(SE3::identity());
        }
        Self { joints, tools }
    }

    /// Builds the model from zero-configuration joint axes and the zero-configuration
    /// `reference_from_flange` pose. The flange becomes tool 0.
    ///
    /// Each joint frame has its origin at the given point on the axis and its z axis along the
    /// axis; its x axis is the previous frame's x axis made perpendicular (or, where that is
    /// parallel to the axis, the previous y axis), so that the frames of a nominal arm are as
    /// aligned as the axes allow.
    pub fn from_zero_configuration(axes: &[JointAxis], reference_from_flange: SE3) -> Result<Self, Error> {
        let mut previous = SE3::identity();
        let mut joints = Vec::with_capacity(axes.len());
        for (index, axis) in axes.iter().enumerate() {
            let norm = axis.direction.norm();
            if (norm - 1.0).abs() > 1e-6 {
                return Err(Error::AxisNotUnit { joint: index, norm });
            }
            let z = axis.direction / norm;
            let previous_rotation = previous.rotation().matrix();
            let mut x = previous_rotation.column(0).into_owned();
            x -= z * z.dot(&x);
            if x.norm() < 1e-6 {
                x = previous_rotation.column(1).into_owned();
                x -= z * z.dot(&x);
            }
            let x = x.normalize();
            let y = z.cross(&x);
            let rotation = SO3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
            let reference_from_joint = SE3::new(rotation, axis.point);
            joints.push(Joint::new(axis.kind, previous.inverse() * reference_from_joint));
            previous = reference_from_joint;
        }
        Ok(Self::new(joints, vec![previous.inverse() * reference_from_flange]))
    }

    /// Number of joints `n`.
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// Number of tools.
    pub fn tool_count(&self) -> usize {
        self.tools.len()
    }

    /// The joints, base first.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Mutable access to the joints, base first.
    pub fn joints_mut(&mut self) -> &mut [Joint] {
        &mut self.joints
    }

    /// The tools' `joint_n_from_tool` transforms `T_{n,n+1}(0)`.
    pub fn tools(&self) -> &[SE3] {
        &self.tools
    }

    /// Replaces the tools' `joint_n_from_tool` transforms (at least one).
    pub fn set_tools(&mut self, tools: Vec<SE3>) {
        *self = Self::new(std::mem::take(&mut self.joints), tools);
    }

    /// Changes the reference frame: afterwards poses are expressed in `new`, where
    /// `new_from_old` maps the old reference frame into it.
    pub fn change_reference(&mut self, new_from_old: SE3) {
        match self.joints.first_mut() {
            Some(first) => first.previous_from_joint_zero = new_from_old * first.previous_from_joint_zero,
            None => {
                for tool in &mut self.tools {
                    *tool = new_from_old * *tool;
                }
            }
        }
    }

    fn check(&self, q: &[f64], tool: usize) -> Result<(), Error> {
        if q.len() != self.joints.len() {
            return Err(Error::JointCountMismatch { given: q.len(), expected: self.joints.len() });
        }
        if tool >= self.tools.len() {
            return Err(Error::UnknownTool { tool, tool_count: self.tools.len() });
        }
        Ok(())
    }

    /// Forward kinematics: `reference_from_tool` at joint values `q` (paper Eq. 3).
    pub fn forward(&self, q: &[f64], tool: usize) -> Result<SE3, Error> {
        self.check(q, tool)?;
        let mut pose = SE3::identity();
        for (joint, &value) in self.joints.iter().zip(q) {
            pose = pose * joint.previous_from_joint(value);
        }
        Ok(pose * self.tools[tool])
    }

    /// Every frame at joint values `q`: element `i` is `reference_from_joint_{i+1}` after that
    /// joint's motion (so the last one is the frame the tools hang from).
    pub fn frames(&self, q: &[f64]) -> Result<Vec<SE3>, Error> {
        self.check(q, 0)?;
        let mut pose = SE3::identity();
        Ok(self
            .joints
            .iter()
            .zip(q)
            .map(|(joint, &value)| {
                pose = pose * joint.previous_from_joint(value);
                pose
            })
            .collect())
    }

    /// The joint twists in the reference frame at joint values `q` (the columns of the spatial
    /// manipulator Jacobian): `Ad(reference_from_joint_i) s_i · scale_i`, with joint `i`'s frame
    /// taken before its own motion (which leaves its axis unchanged).
    pub fn spatial_twists(&self, q: &[f64]) -> Result<Vec<Twist>, Error> {
        Ok(self
            .frames(q)?
            .iter()
            .zip(&self.joints)
            .map(|(frame, joint)| Twist::from_vector(&(frame.adjoint() * joint.local_twist().to_vector())))
            .collect())
    }
}
