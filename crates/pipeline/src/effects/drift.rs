//! Drift: the robot's placement in the tracker frame moves at a constant twist rate, `exp(t ξ̂) T`
//! (`loadsim::BaseDrift`, `loadsim::drift_regressor`): six parameters, `(v, ω)`.

use super::{Regressor, check_column_varies, rms_scales};
use crate::effects::Direction;
use crate::{Error, Measurement};
use serde::{Deserialize, Serialize};

/// Linear drift of the placement with `t_s`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimeDrift {
    /// The time at which the geometry holds (the training rows' mean), s.
    pub reference_s: f64,
    /// `Δt` is divided by this (its RMS on the training poses), s; six equal entries.
    pub scale: Vec<f64>,
    /// The twist per unit of the scaled `Δt`, `(v, ω)`: metres and radians.
    pub theta: Vec<f64>,
}

impl TimeDrift {
    pub(crate) fn new(rows: &[Measurement]) -> Result<Self, Error> {
        let times: Vec<f64> = rows
            .iter()
            .map(|r| r.t_s.ok_or(Error::EffectNeedsColumn { line: r.line, effect: "time_drift", column: "t_s" }))
            .collect::<Result<_, _>>()?;
        check_column_varies(&times, rows, "time_drift", "t_s")?;
        let reference_s = times.iter().sum::<f64>() / times.len().max(1) as f64;
        let raw: Vec<Vec<f64>> = times.iter().map(|t| vec![t - reference_s; 6]).collect();
        Ok(Self { reference_s, scale: rms_scales(&raw), theta: vec![0.0; 6] })
    }
}

impl Regressor for TimeDrift {
    fn directions(&self) -> Vec<Direction> {
        (0..6).map(Direction::Component).collect()
    }

    fn features(&self, row: &Measurement, _tool: usize) -> Result<Vec<f64>, Error> {
        let t = row.t_s.ok_or(Error::EffectNeedsColumn { line: row.line, effect: "time_drift", column: "t_s" })?;
        Ok(self.scale.iter().map(|s| (t - self.reference_s) / s).collect())
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        ["v_x", "v_y", "v_z", "w_x", "w_y", "w_z"].iter().map(|c| format!("drift {c}")).collect()
    }
}
