//! Where one effect parameter moves the pose: the left twist that a unit of its scaled feature
//! adds, in the model's reference frame (the tracker for a calibrated model).

use crate::ErrorKind;
use errors::Error;
use lie::{Twist, Vector6};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// The twist one parameter moves the pose along, per unit of its feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Joint `j` (0-based) turns: its spatial twist `S_j(q)`, so that `T(q + δq) = exp(S_j δq_j)
    /// T(q)` to first order (Lynch & Park, *Modern Robotics*, §5.1.1).
    Joint(usize),
    /// A fixed left twist along one component `(v, ω)` of the reference frame (0..6).
    Component(usize),
    /// Every link but the base placement grows by a unit strain: `Σ_{i ≥ 1} (R_{i-1}(q) t_i, 0)`
    /// (`loadsim::thermal_regressor`, one expansion coefficient for the whole arm).
    LinkGrowth,
    /// Joint `joint`'s link (0-based) turns about the `axis` (0: x, 1: y) of the joint's frame
    /// through the link's midpoint: `(m × e, e)` (`loadsim::link_bend`, link deflection).
    LinkBend {
        /// 0-based joint whose link bends.
        joint: usize,
        /// 0: the x axis of the joint's frame, 1: its y axis.
        axis: usize,
    },
}

/// The twists of one row under one model, computed once for all the parameters that use them.
#[derive(Debug)]
pub struct RowTwists<'a> {
    model: &'a LocalPoe,
    q: &'a [f64],
    tool: usize,
    spatial: Option<Vec<Twist>>,
    growth: Option<Vector6>,
}

impl<'a> RowTwists<'a> {
    /// The twists of joint configuration `q` with tool `tool` under `model`, computed on demand.
    pub fn new(model: &'a LocalPoe, q: &'a [f64], tool: usize) -> Self {
        Self { model, q, tool, spatial: None, growth: None }
    }

    /// The twist of `direction` at this row.
    pub fn twist(&mut self, direction: Direction) -> Result<Vector6, Error> {
        match direction {
            Direction::Joint(j) => {
                if self.spatial.is_none() {
                    self.spatial = Some(self.model.spatial_twists(self.q).map_err(Error::kinematics)?);
                }
                let spatial = self.spatial.as_deref().unwrap_or(&[]);
                let joint_count = spatial.len();
                spatial
                    .get(j)
                    .map(Twist::to_vector)
                    .ok_or_else(|| Error::new(ErrorKind::EffectJoint { joint: j + 1, joint_count }))
            }
            Direction::Component(k) => {
                let mut twist = Vector6::zeros();
                if k < 6 {
                    twist[k] = 1.0;
                }
                Ok(twist)
            }
            Direction::LinkGrowth => {
                if self.growth.is_none() {
                    let columns =
                        loadsim::thermal_regressor(self.model, self.q, self.tool, 1.0).map_err(Error::load)?;
                    // Column 0 grows the tracker-to-base distance, which is not a robot link.
                    self.growth = Some(columns.iter().skip(1).copied().sum());
                }
                Ok(self.growth.unwrap_or_else(Vector6::zeros))
            }
            Direction::LinkBend { joint, axis } => {
                let joint_count = self.model.joint_count();
                if joint >= joint_count || axis > 1 {
                    return Err(Error::new(ErrorKind::EffectJoint { joint: joint + 1, joint_count }));
                }
                Ok(loadsim::link_bend(self.model, self.q, self.tool, joint).map_err(Error::load)?.unit_twist(axis))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lie::{SE3, Vector3};
    use poe::{JointAxis, JointKind};

    fn arm() -> LocalPoe {
        let axis =
            |d: [f64; 3], p: [f64; 3]| JointAxis { kind: JointKind::Revolute, direction: d.into(), point: p.into() };
        let model = LocalPoe::from_zero_configuration(
            &[
                axis([0.0, 0.0, 1.0], [0.0, 0.0, 0.0]),
                axis([0.0, 1.0, 0.0], [0.3, 0.0, 0.5]),
                axis([1.0, 0.0, 0.0], [0.9, 0.1, 0.6]),
            ],
            SE3::from_translation(Vector3::new(1.1, 0.1, 0.7)),
        )
        .unwrap();
        // Placed away from the identity, as a calibrated model in the tracker frame is.
        let mut placed = model.clone();
        placed.joints_mut()[0].previous_from_joint_zero =
            Twist::new(Vector3::new(2.0, -1.0, 0.3), Vector3::new(0.1, -0.2, 0.4)).exp();
        placed
    }

    /// `log(T' T⁻¹)^∨ / h`: the left twist of a pose change per unit of the parameter.
    fn slope(after: &SE3, before: &SE3, h: f64) -> Vector6 {
        (*after * before.inverse()).log().to_vector() / h
    }

    #[test]
    fn a_joint_direction_is_the_derivative_of_the_pose_in_that_joint() {
        let model = arm();
        let q = [0.4, -0.9, 1.3];
        let h = 1e-7;
        for j in 0..3 {
            let mut moved = q;
            moved[j] += h;
            let numeric = slope(&model.forward(&moved, 0).unwrap(), &model.forward(&q, 0).unwrap(), h);
            let analytic = RowTwists::new(&model, &q, 0).twist(Direction::Joint(j)).unwrap();
            assert!((numeric - analytic).norm() < 1e-6 * (1.0 + analytic.norm()), "joint {j}: {numeric} {analytic}");
        }
        assert!(RowTwists::new(&model, &q, 0).twist(Direction::Joint(3)).is_err());
    }

    #[test]
    fn a_link_bend_is_the_derivative_of_the_pose_in_a_turn_of_the_far_end_about_the_midpoint() {
        let model = arm();
        let q = [0.3, -0.8, 1.1];
        let h = 1e-7;
        let frames = model.frames(&q).unwrap();
        // Link 2 runs from joint 2's axis point to joint 3's; turning everything beyond it (joint 3
        // on) by h about the joint frame's axis through its midpoint.
        let start = frames[0] * model.joints()[1].previous_from_joint_zero;
        let end = frames[1] * model.joints()[2].previous_from_joint_zero;
        let midpoint = (start.translation() + end.translation()) * 0.5;
        for axis in 0..2 {
            let e = frames[1].rotation().matrix().column(axis).into_owned();
            let turn = SE3::from_translation(midpoint)
                * SE3::new(lie::SO3::exp(&(e * h)), Vector3::zeros())
                * SE3::from_translation(-midpoint);
            let before = model.forward(&q, 0).unwrap();
            let numeric = slope(&(turn * before), &before, h);
            let analytic = RowTwists::new(&model, &q, 0).twist(Direction::LinkBend { joint: 1, axis }).unwrap();
            assert!((numeric - analytic).norm() < 1e-6 * (1.0 + analytic.norm()), "axis {axis}: {numeric} {analytic}");
        }
        assert!(RowTwists::new(&model, &q, 0).twist(Direction::LinkBend { joint: 3, axis: 0 }).is_err());
        assert!(RowTwists::new(&model, &q, 0).twist(Direction::LinkBend { joint: 0, axis: 2 }).is_err());
    }

    #[test]
    fn link_growth_is_the_derivative_of_the_pose_in_the_links_strain() {
        let model = arm();
        let q = [-0.7, 0.5, 2.0];
        let h = 1e-7;
        // Every link but the tracker-to-base placement (link 0) grows by the strain h.
        let growth = loadsim::ThermalModel {
            reference_temp_c: 0.0,
            expansion_per_k: 1.0,
            link_expansion_per_k: vec![0.0, 1.0, 1.0, 1.0],
        };
        let grown = growth.grown_model(&model, h).unwrap();
        let numeric = slope(&grown.forward(&q, 0).unwrap(), &model.forward(&q, 0).unwrap(), h);
        let analytic = RowTwists::new(&model, &q, 0).twist(Direction::LinkGrowth).unwrap();
        assert!((numeric - analytic).norm() < 1e-6 * (1.0 + analytic.norm()), "{numeric} {analytic}");
    }
}
