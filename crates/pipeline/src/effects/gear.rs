//! Gear (or encoder) periodic error: a smooth periodic function of one joint's own angle, as a
//! Fourier series `δq_j = Σ_h a_h cos(h q_j) + b_h sin(h q_j)` (`loadsim::periodic_joint_regressor`)
//! of any order.

use super::{Regressor, rms_scales};
use crate::effects::Direction;
use crate::{Error, Measurement};
use serde::{Deserialize, Serialize};

/// A periodic error of one joint in its own angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GearPeriodic {
    /// 0-based joint.
    pub joint: usize,
    /// The harmonic orders, each with a cosine then a sine parameter.
    pub orders: Vec<u32>,
    /// Each feature is divided by this (its RMS on the training poses; 1 where it vanishes).
    pub scale: Vec<f64>,
    /// The coefficients, rad per unit of the scaled feature: `cos(h₁q), sin(h₁q), cos(h₂q), …`.
    pub theta: Vec<f64>,
}

impl GearPeriodic {
    pub(crate) fn new(joint: usize, orders: Vec<u32>, rows: &[Measurement]) -> Result<Self, Error> {
        let mut model = Self { joint, orders, scale: Vec::new(), theta: Vec::new() };
        let width = 2 * model.orders.len();
        model.scale = vec![1.0; width];
        let raw: Vec<Vec<f64>> = rows.iter().map(|row| model.features(row, 0)).collect::<Result<_, _>>()?;
        model.scale = rms_scales(&raw);
        model.theta = vec![0.0; width];
        Ok(model)
    }
}

impl Regressor for GearPeriodic {
    fn directions(&self) -> Vec<Direction> {
        vec![Direction::Joint(self.joint); 2 * self.orders.len()]
    }

    fn features(&self, row: &Measurement, _tool: usize) -> Result<Vec<f64>, Error> {
        let q = *row.q.get(self.joint).ok_or(Error::EffectJoint { joint: self.joint + 1, joint_count: row.q.len() })?;
        Ok(self
            .orders
            .iter()
            .flat_map(|&h| loadsim::periodic_joint_regressor(q, f64::from(h)))
            .zip(&self.scale)
            .map(|(v, s)| v / s)
            .collect())
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        let j = self.joint + 1;
        self.orders.iter().flat_map(|h| [format!("cos({h} q{j})"), format!("sin({h} q{j})")]).collect()
    }
}
