//! Thermal growth: every link but the base placement grows by `α ΔT` with the temperature
//! (`loadsim::ThermalGrowth`, one coefficient for the whole arm, `loadsim::thermal_regressor`).

use super::{Regressor, check_column_varies, rms_scales};
use crate::effects::Direction;
use crate::{Error, Measurement};
use serde::{Deserialize, Serialize};

/// Thermal growth of the arm with `temp_c`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Thermal {
    /// The temperature at which the geometry holds (the training rows' mean), °C.
    pub reference_c: f64,
    /// `ΔT` is divided by this (its RMS on the training poses), K.
    pub scale: Vec<f64>,
    /// The strain per unit of the scaled `ΔT`.
    pub theta: Vec<f64>,
}

impl Thermal {
    pub(crate) fn new(rows: &[Measurement]) -> Result<Self, Error> {
        let temps: Vec<f64> = rows
            .iter()
            .map(|r| r.temp_c.ok_or(Error::EffectNeedsColumn { line: r.line, effect: "thermal", column: "temp_c" }))
            .collect::<Result<_, _>>()?;
        check_column_varies(&temps, rows, "thermal", "temp_c")?;
        let reference_c = temps.iter().sum::<f64>() / temps.len().max(1) as f64;
        let raw: Vec<Vec<f64>> = temps.iter().map(|t| vec![t - reference_c]).collect();
        Ok(Self { reference_c, scale: rms_scales(&raw), theta: vec![0.0] })
    }
}

impl Regressor for Thermal {
    fn directions(&self) -> Vec<Direction> {
        vec![Direction::LinkGrowth]
    }

    fn features(&self, row: &Measurement, _tool: usize) -> Result<Vec<f64>, Error> {
        let t = row.temp_c.ok_or(Error::EffectNeedsColumn { line: row.line, effect: "thermal", column: "temp_c" })?;
        Ok(vec![(t - self.reference_c) / self.scale[0]])
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        vec!["link strain".into()]
    }
}
