//! What the torque-driven effects need to know of gravity: the arm in the robot's base frame
//! (where gravity is known; a calibrated model's frame is the tracker's), and gravity in that
//! frame.
//!
//! The arm is the nominal one: the data may not determine a calibrated arm's frames where its
//! joints barely move (a campaign with joints 3–7 fixed), and the masses' torques hardly depend on
//! millimetres of geometry. The tools, though, are placed from the calibrated model: a
//! calibrated model's last frame may sit anywhere along the directions the data cannot see (a
//! shift along the last axis traded against the tool), so its tool transforms mean something only
//! on its own joints. Each tool is the calibrated tool pose seen from the nominal flange, averaged
//! over the rows that carry it. On the 7-axis payload campaign (seed 0) the calibrated tools put on
//! the nominal flange left 1.5 N·m of the measured joint-2 torque unexplained (0.5 N·m of sensor
//! noise) and 0.18 mm held out.

use errors::Error;
use lie::{SE3, Vector3};
use loadsim::Payload;
use measurements::{BoundSet, Measurement};
use poe::LocalPoe;
use robot::RobotDescription;
use serde::{Deserialize, Serialize};

/// The nominal arm in the base frame and gravity there: the gravity-torque regressors of a row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoadFrame {
    /// The nominal arm in the robot's base frame, with the calibrated tools (the payload hangs
    /// from them).
    pub base_model: LocalPoe,
    /// Gravity in the base frame, m/s².
    pub gravity_m_per_s2: [f64; 3],
}

impl LoadFrame {
    /// The frame of `robot` for the calibrated `kinematics` (reference frame: the tracker), its
    /// tools placed from the rows of `data` that carry each.
    pub fn new(robot: &RobotDescription, kinematics: &LocalPoe, data: &BoundSet<'_>) -> Result<Self, Error> {
        let mut base_model = robot.nominal_model()?;
        let in_base = robot::in_base_frame(kinematics, Some(&base_model));
        let mut placed = Vec::with_capacity(in_base.tool_count());
        let zero = vec![0.0; base_model.joint_count()];
        for tool in 0..in_base.tool_count() {
            let mut carried: Vec<&[f64]> =
                data.iter().filter(|(_, t)| *t == tool).map(|(r, _)| r.q.as_slice()).collect();
            if carried.is_empty() {
                carried.push(&zero);
            }
            let mut sum = Vector3::zeros();
            let mut rotation = None;
            for q in &carried {
                let flange =
                    base_model.frames(q).map_err(Error::kinematics)?.last().copied().unwrap_or_else(SE3::identity);
                let local = flange.inverse() * in_base.forward(q, tool).map_err(Error::kinematics)?;
                sum += local.translation();
                rotation.get_or_insert(local.rotation());
            }
            placed.push(SE3::new(rotation.unwrap_or_else(lie::SO3::identity), sum / carried.len() as f64));
        }
        base_model.set_tools(placed);
        let gravity = robot.dynamics.as_ref().map_or(loadsim::FLOOR_GRAVITY_M_PER_S2, |d| d.gravity_m_per_s2);
        Ok(Self { base_model, gravity_m_per_s2: gravity })
    }

    /// The gravity vector in the base frame, m/s².
    pub fn gravity(&self) -> Vector3 {
        Vector3::from(self.gravity_m_per_s2)
    }

    /// The gravity-torque regressor `Y(q)` (`loadsim::gravity_regressor`) row by row, with the
    /// payload's gravity torque appended to each row: `n × (4n + 1)`. Joint `j`'s gravity torque
    /// is `Y_j(q) π + τ_payload,j` with `π` the links' unknown mass moments.
    pub fn regressors(&self, row: &Measurement, tool: usize) -> Result<Vec<Vec<f64>>, Error> {
        self.regressors_with(&row.q, tool, row.payload_kg)
    }

    /// [`LoadFrame::regressors`] at joint values `q` with a payload of `payload_kg` at tool `tool`
    /// (a payload held at the end of a term's span, `crate::PayloadSpan`).
    pub fn regressors_with(&self, q: &[f64], tool: usize, payload_kg: f64) -> Result<Vec<Vec<f64>>, Error> {
        let g = self.gravity();
        let y = loadsim::gravity_regressor(&self.base_model, q, &g).map_err(Error::load)?;
        let payload = loadsim::payload_gravity_torque(&self.base_model, q, tool, &Payload::at_tool(payload_kg), &g)
            .map_err(Error::load)?;
        Ok((0..y.nrows())
            .map(|j| (0..y.ncols()).map(|c| y[(j, c)]).chain(std::iter::once(payload[j])).collect())
            .collect())
    }
}
