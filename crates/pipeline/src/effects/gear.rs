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
    /// The joint's smallest and largest angle on the training poses, rad: the series is known
    /// only there (a series of order 48 fitted on a 130° arc says nothing of the rest of the
    /// circle), and `eval`, `predict` and `compensate` warn about rows outside it. Absent in model
    /// files written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted_range: Option<[f64; 2]>,
    /// Open intervals inside `fitted_range` with no training angle that are wider than half the
    /// series' shortest period (`π / h_max`, the sampling theorem's spacing): the series is not
    /// determined there either, and rows inside them are warned about like rows outside.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fitted_gaps: Vec<[f64; 2]>,
}

impl GearPeriodic {
    pub(crate) fn new(joint: usize, orders: Vec<u32>, rows: &[Measurement]) -> Result<Self, Error> {
        let angles = rows.iter().filter_map(|row| row.q.get(joint).copied());
        let fitted_range = angles.fold(None, |range: Option<[f64; 2]>, q| {
            Some(range.map_or([q, q], |[low, high]| [low.min(q), high.max(q)]))
        });
        let mut sorted: Vec<f64> = rows.iter().filter_map(|row| row.q.get(joint).copied()).collect();
        sorted.sort_by(f64::total_cmp);
        let spacing = std::f64::consts::PI / f64::from(orders.iter().copied().max().unwrap_or(1).max(1));
        let fitted_gaps = sorted.windows(2).filter(|w| w[1] - w[0] > spacing).map(|w| [w[0], w[1]]).collect();
        let mut model = Self { joint, orders, scale: Vec::new(), theta: Vec::new(), fitted_range, fitted_gaps };
        let width = 2 * model.orders.len();
        model.scale = vec![1.0; width];
        let raw: Vec<Vec<f64>> = rows.iter().map(|row| model.features(row, 0)).collect::<Result<_, _>>()?;
        model.scale = rms_scales(&raw);
        model.theta = vec![0.0; width];
        Ok(model)
    }
}

impl GearPeriodic {
    /// Whether the series was fitted on poses near the angle `q` (inside the fitted range and
    /// outside its gaps); true for model files that do not record the range.
    pub fn covers(&self, q: f64) -> bool {
        let Some([low, high]) = self.fitted_range else { return true };
        (low..=high).contains(&q) && !self.fitted_gaps.iter().any(|&[a, b]| a < q && q < b)
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
