//! Thermal growth: every link but the base placement grows by `α ΔT` with the temperature
//! (`loadsim::ThermalModel`, one coefficient for the whole arm, `loadsim::thermal_regressor`).

use super::{Regressor, check_column_varies, rms_scales};
use crate::check::{Cursor, EffectFault};
use crate::term::{EffectTerm, NewEffect};
use crate::{Argument, CandidateContext, CandidateModel, EffectContext, EffectSpec, IdentifiedEffect};
use crate::{BeyondSpan, Direction};
use errors::Error;
use crate::ErrorKind;
use measurements::{BoundSet, Measurement};
use serde::{Deserialize, Serialize};

/// Thermal growth of the arm with `temp_c`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThermalTerm {
    /// The temperature at which the geometry holds (the training rows' mean), °C.
    pub reference_c: f64,
    /// `ΔT` is divided by this (its RMS on the training poses), K.
    pub scale: Vec<f64>,
    /// The strain per unit of the scaled `ΔT`.
    pub theta: Vec<f64>,
    /// `[min, max]` of `temp_c` on the training rows widened by `EffectOptions::hold_beyond_span`
    /// of its width at either end, °C: outside it the temperature is held at the nearer end, so that a term fitted within one session is never carried on as a straight
    /// line. Absent in older model files: applied as fitted, everywhere.
    #[serde(default)]
    pub fitted_span: Option<[f64; 2]>,
    /// Beyond `fitted_span`: held at the nearer end's temperature (the default, and what files
    /// written before the choice mean) or zero, chosen by the fit by leaving one session out at a
    /// time where the training rows hold several.
    #[serde(default = "crate::beyond_span::hold", skip_serializing_if = "crate::beyond_span::is_hold")]
    pub beyond_span: BeyondSpan,
}

impl ThermalTerm {
    /// A growth linear in `temp_c`, scaled on the training rows, held beyond `hold_beyond_span` of
    /// their temperature span past either end.
    pub fn new(rows: &[Measurement], hold_beyond_span: f64) -> Result<Self, Error> {
        let temps: Vec<f64> = rows
            .iter()
            .map(|r| {
                r.temp_c.ok_or_else(|| Error::new(ErrorKind::EffectNeedsColumn {
                    line: r.line,
                    effect: "thermal",
                    column: "temp_c",
                }))
            })
            .collect::<Result<_, _>>()?;
        check_column_varies(&temps, rows, "thermal", "temp_c")?;
        let reference_c = temps.iter().sum::<f64>() / temps.len().max(1) as f64;
        let raw: Vec<Vec<f64>> = temps.iter().map(|t| vec![t - reference_c]).collect();
        Ok(Self {
            reference_c,
            scale: rms_scales(&raw),
            theta: vec![0.0],
            fitted_span: super::span_of(&temps, hold_beyond_span),
            beyond_span: BeyondSpan::Hold,
        })
    }
}

impl Regressor for ThermalTerm {
    fn directions(&self) -> Vec<Direction> {
        vec![Direction::LinkGrowth]
    }

    fn features(&self, row: &Measurement, _tool: usize) -> Result<Vec<f64>, Error> {
        let t = row.temp_c.ok_or_else(|| Error::new(ErrorKind::EffectNeedsColumn {
            line: row.line,
            effect: "thermal",
            column: "temp_c",
        }))?;
        let at = |t: f64| vec![(t - self.reference_c) / self.scale[0]];
        Ok(self.beyond_span.features(t, self.fitted_span, 1, at))
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

impl EffectTerm for ThermalTerm {
    fn label(&self) -> String {
        "thermal".into()
    }

    fn joints(&self) -> Vec<usize> {
        Vec::new()
    }

    fn check(&self, cursor: &Cursor<'_>, _n: usize, _tools: usize) -> Result<(), EffectFault> {
        cursor.finite("reference_c", &[self.reference_c], false)?;
        cursor.count("scale", self.scale.len(), 1)?;
        cursor.count("theta", self.theta.len(), 1)?;
        cursor.finite("scale", &self.scale, true)
    }

    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize)) {
        add("reference_c", 1);
        add("scale", 1);
    }

    fn beyond_span(&self) -> Option<BeyondSpan> {
        Some(self.beyond_span)
    }

    fn set_beyond_span(&mut self, rule: BeyondSpan) {
        self.beyond_span = rule;
    }

    fn coverage_weight(&self, row: &Measurement) -> f64 {
        self.beyond_span.coverage(row.temp_c, self.fitted_span)
    }
}

impl NewEffect for ThermalTerm {
    const ARGUMENTS: &'static [Argument] = &[];

    fn build(_spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        ThermalTerm::new(data.rows(), context.hold_beyond_span)
    }

    /// One expansion coefficient for the whole arm (every link but the tracker-to-base placement
    /// grows by `α ΔT`), where every row has `temp_c` and it spans more than
    /// `CandidateOptions::thermal_min_span_k`.
    fn global_candidates(context: &CandidateContext<'_>) -> Result<Vec<CandidateModel>, Error> {
        let Some(temps) = context.data.rows().iter().map(|r| r.temp_c).collect::<Option<Vec<f64>>>() else {
            return Ok(Vec::new());
        };
        let (low, high) = temps.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| (a.min(t), b.max(t)));
        if high - low <= context.options.thermal_min_span_k {
            return Ok(Vec::new());
        }
        let thermal = ThermalTerm::new(context.data.rows(), crate::HOLD_BEYOND_SPAN)?;
        Ok(vec![CandidateModel::plain(IdentifiedEffect::Thermal(thermal), 0)])
    }
}
