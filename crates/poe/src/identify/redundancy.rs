//! The unidentifiable directions of an identification, named.

use super::{Observation, ParameterMask, Target};
use crate::{Block, JointKind, LocalPoe};
use lie::{Twist, Vector3, Vector6};
use std::fmt;

/// A direction of the parameter space that the measurements cannot see, in words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Redundancy {
    /// Turning joint `joint`'s frame about its own axis and the next frame back by the same angle
    /// changes nothing: only their sum (the joint's zero offset) is identifiable.
    AboutJointAxis {
        /// 0-based joint index.
        joint: usize,
    },
    /// Shifting joint `joint`'s frame along its axis and the next frame back changes nothing.
    AlongJointAxis {
        /// 0-based joint index.
        joint: usize,
    },
    /// A prismatic joint's frame can also shift across its axis (translations commute).
    AcrossPrismaticAxis {
        /// 0-based joint index.
        joint: usize,
        /// 0 for the local x axis, 1 for y.
        axis: usize,
    },
    /// With position-only data the orientation of a tool about its measured point is unseen.
    ToolOrientation {
        /// Tool index.
        tool: usize,
        /// 0, 1, 2 for rotation about the tool's x, y, z axis.
        axis: usize,
    },
    /// Directions of the null space that none of the above explains (a poorly exciting data set).
    Unexplained {
        /// How many.
        count: usize,
    },
}

impl fmt::Display for Redundancy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const AXES: [char; 3] = ['x', 'y', 'z'];
        match *self {
            Redundancy::AboutJointAxis { joint } => write!(
                f,
                "joint {}: rotation of its frame about its axis trades against the next frame (only the zero offset is seen)",
                joint + 1
            ),
            Redundancy::AlongJointAxis { joint } => {
                write!(f, "joint {}: translation of its frame along its axis trades against the next frame", joint + 1)
            }
            Redundancy::AcrossPrismaticAxis { joint, axis } => write!(
                f,
                "joint {} (prismatic): translation of its frame along local {} trades against the next frame",
                joint + 1,
                AXES[axis]
            ),
            Redundancy::ToolOrientation { tool, axis } => {
                write!(f, "tool {}: rotation about its {} axis is unseen by position-only data", tool + 1, AXES[axis])
            }
            Redundancy::Unexplained { count } => {
                write!(f, "{count} further direction(s) not excited by these poses: add more varied poses")
            }
        }
    }
}

fn put(direction: &mut [f64], offset: usize, value: &Vector6) {
    direction[offset..offset + 6].copy_from_slice(value.as_slice());
}

/// The analytic redundancies of the local POE model (Chen et al.: 6 + 4R + 2P identifiable
/// parameters for full-pose data), restricted to the free parameters and made independent, then
/// compared with the numerical nullity.
pub(crate) fn find_redundancies(
    model: &LocalPoe,
    observations: &[Observation],
    mask: &ParameterMask,
    nullity: usize,
) -> Vec<Redundancy> {
    let layout = model.layout();
    let mut candidates: Vec<(Redundancy, Vec<f64>)> = Vec::new();
    let n = model.joint_count();
    for (i, joint) in model.joints().iter().enumerate() {
        let mut motions: Vec<(Redundancy, Twist)> = vec![
            (Redundancy::AboutJointAxis { joint: i }, Twist::new(Vector3::zeros(), Vector3::z())),
            (Redundancy::AlongJointAxis { joint: i }, Twist::new(Vector3::z(), Vector3::zeros())),
        ];
        if joint.kind == JointKind::Prismatic {
            for axis in 0..2 {
                let mut v = Vector3::zeros();
                v[axis] = 1.0;
                motions.push((Redundancy::AcrossPrismaticAxis { joint: i, axis }, Twist::new(v, Vector3::zeros())));
            }
        }
        for (name, motion) in motions {
            let mut direction = vec![0.0; layout.len()];
            let local = joint.previous_from_joint_zero.adjoint() * motion.to_vector();
            put(&mut direction, layout.offset(Block::Joint(i)), &local);
            let back = -motion.to_vector();
            if i + 1 < n {
                put(&mut direction, layout.offset(Block::Joint(i + 1)), &back);
            } else {
                for tool in 0..layout.tool_count {
                    put(&mut direction, layout.offset(Block::Tool(tool)), &back);
                }
            }
            candidates.push((name, direction));
        }
    }
    for (tool, pose) in model.tools().iter().enumerate() {
        let seen = observations.iter().filter(|o| o.tool == tool);
        let position_only = seen.clone().count() > 0 && seen.clone().all(|o| matches!(o.target, Target::Point(_)));
        if !position_only {
            continue;
        }
        for axis in 0..3 {
            let mut w = Vector3::zeros();
            w[axis] = 1.0;
            let mut direction = vec![0.0; layout.len()];
            let local = pose.adjoint() * Twist::new(Vector3::zeros(), w).to_vector();
            put(&mut direction, layout.offset(Block::Tool(tool)), &local);
            candidates.push((Redundancy::ToolOrientation { tool, axis }, direction));
        }
    }
    // Keep those that live entirely in free parameters and are independent of the ones kept.
    let free = mask.flags();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut found = Vec::new();
    for (name, direction) in candidates {
        if direction.iter().zip(free).any(|(d, f)| !f && d.abs() > 1e-12) {
            continue;
        }
        let mut residual = direction.clone();
        for b in &basis {
            let dot: f64 = residual.iter().zip(b).map(|(r, b)| r * b).sum();
            residual.iter_mut().zip(b).for_each(|(r, b)| *r -= dot * b);
        }
        let norm = residual.iter().map(|r| r * r).sum::<f64>().sqrt();
        let original = direction.iter().map(|r| r * r).sum::<f64>().sqrt();
        if norm > 1e-8 * original {
            basis.push(residual.iter().map(|r| r / norm).collect());
            found.push(name);
        }
    }
    if nullity > found.len() {
        found.push(Redundancy::Unexplained { count: nullity - found.len() });
    }
    found
}
