//! Drift: the robot's placement in the tracker frame moves at a constant twist rate, `exp(t ξ̂) T`
//! (`loadsim::TimeDriftModel`): six parameters, `(v, ω)`.

use super::{Regressor, check_column_varies, rms_scales};
use crate::check::{Cursor, EffectFault};
use crate::term::{EffectTerm, NewEffect};
use crate::{Argument, CandidateContext, CandidateModel, EffectContext, EffectSpec, IdentifiedEffect};
use crate::{BeyondSpan, Direction};
use errors::Error;
use crate::ErrorKind;
use measurements::{BoundSet, Measurement};
use serde::{Deserialize, Serialize};

/// Linear drift of the placement with `t_s`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimeDriftTerm {
    /// The time at which the geometry holds (the training rows' mean), s.
    pub reference_s: f64,
    /// `Δt` is divided by this (its RMS on the training poses), s; six equal entries.
    pub scale: Vec<f64>,
    /// The twist per unit of the scaled `Δt`, `(v, ω)`: metres and radians.
    pub theta: Vec<f64>,
    /// `[min, max]` of `t_s` on the training rows widened by `EffectOptions::hold_beyond_span` of
    /// its width at either end, s: outside it the drift falls back to zero (the geometry's own
    /// placement), so that a term fitted within one session is never carried on as a straight
    /// line into another. Absent in older model files: applied as fitted, everywhere.
    #[serde(default)]
    pub fitted_span: Option<[f64; 2]>,
    /// Beyond `fitted_span`: zero (the default, and what files written before the choice mean)
    /// or held at the value at its nearer end, chosen by the fit by leaving one session out at a
    /// time where the training rows hold several.
    #[serde(default = "crate::beyond_span::zero", skip_serializing_if = "crate::beyond_span::is_zero")]
    pub beyond_span: BeyondSpan,
}

impl TimeDriftTerm {
    /// A drift linear in `t_s`, scaled on the training rows, applied up to `hold_beyond_span` of
    /// their time span beyond either end.
    pub fn new(rows: &[Measurement], hold_beyond_span: f64) -> Result<Self, Error> {
        let times: Vec<f64> = rows
            .iter()
            .map(|r| {
                r.t_s.ok_or_else(|| Error::new(ErrorKind::EffectNeedsColumn {
                    line: r.line,
                    effect: "time_drift",
                    column: "t_s",
                }))
            })
            .collect::<Result<_, _>>()?;
        check_column_varies(&times, rows, "time_drift", "t_s")?;
        let reference_s = times.iter().sum::<f64>() / times.len().max(1) as f64;
        let raw: Vec<Vec<f64>> = times.iter().map(|t| vec![t - reference_s; 6]).collect();
        Ok(Self {
            reference_s,
            scale: rms_scales(&raw),
            theta: vec![0.0; 6],
            fitted_span: super::span_of(&times, hold_beyond_span),
            beyond_span: BeyondSpan::Zero,
        })
    }
}

impl Regressor for TimeDriftTerm {
    fn directions(&self) -> Vec<Direction> {
        (0..6).map(Direction::Component).collect()
    }

    fn features(&self, row: &Measurement, _tool: usize) -> Result<Vec<f64>, Error> {
        let t = row.t_s.ok_or_else(|| Error::new(ErrorKind::EffectNeedsColumn {
            line: row.line,
            effect: "time_drift",
            column: "t_s",
        }))?;
        // Past the span (and its margin) the drift falls back to the placement the geometry holds
        // (a later session starts from a placement of its own, which no line from this one knows),
        // or, where the sessions of the training data said so, is held at the end's placement.
        let at = |t: f64| self.scale.iter().map(|s| (t - self.reference_s) / s).collect();
        Ok(self.beyond_span.features(t, self.fitted_span, self.scale.len(), at))
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

impl EffectTerm for TimeDriftTerm {
    fn label(&self) -> String {
        "time_drift".into()
    }

    fn joints(&self) -> Vec<usize> {
        Vec::new()
    }

    fn check(&self, cursor: &Cursor<'_>, _n: usize, _tools: usize) -> Result<(), EffectFault> {
        cursor.finite("reference_s", &[self.reference_s], false)?;
        cursor.count("scale", self.scale.len(), 6)?;
        cursor.count("theta", self.theta.len(), 6)?;
        cursor.finite("scale", &self.scale, true)
    }

    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize)) {
        add("reference_s", 1);
        add("scale", 1);
    }

    fn beyond_span(&self) -> Option<BeyondSpan> {
        Some(self.beyond_span)
    }

    fn set_beyond_span(&mut self, rule: BeyondSpan) {
        self.beyond_span = rule;
    }

    fn coverage_weight(&self, row: &Measurement) -> f64 {
        self.beyond_span.coverage(row.t_s, self.fitted_span)
    }
}

impl NewEffect for TimeDriftTerm {
    const ARGUMENTS: &'static [Argument] = &[];

    fn build(_spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        TimeDriftTerm::new(data.rows(), context.hold_beyond_span)
    }

    /// Where every row has `t_s` and some row lies more than `CandidateOptions::drift_min_offset_s`
    /// from their mean.
    fn global_candidates(context: &CandidateContext<'_>) -> Result<Vec<CandidateModel>, Error> {
        let Some(times) = context.data.rows().iter().map(|r| r.t_s).collect::<Option<Vec<f64>>>() else {
            return Ok(Vec::new());
        };
        let mean = times.iter().sum::<f64>() / context.data.rows().len() as f64;
        if !times.iter().any(|t| (t - mean).abs() > context.options.drift_min_offset_s) {
            return Ok(Vec::new());
        }
        let drift = TimeDriftTerm::new(context.data.rows(), crate::HOLD_BEYOND_SPAN)?;
        Ok(vec![CandidateModel::plain(IdentifiedEffect::TimeDrift(drift), 0)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ThermalTerm;

    fn row(t_s: f64, temp_c: f64) -> Measurement {
        Measurement { temp_c: Some(temp_c), t_s: Some(t_s), ..Measurement::at(vec![0.0], lie::Vector3::zeros()) }
    }

    /// A drift fitted over one 73-minute session must not run on as a straight line eight
    /// days later. Outside the fitted span the time and the temperature are held at its ends.
    #[test]
    fn a_drift_and_a_thermal_growth_are_held_at_the_ends_of_the_span_they_were_fitted_on() {
        let session: Vec<Measurement> = (0..50).map(|i| row(f64::from(i) * 88.0, 20.0 + f64::from(i) * 0.05)).collect();
        let drift = TimeDriftTerm::new(&session, 0.0).unwrap();
        let thermal = ThermalTerm::new(&session, 0.0).unwrap();
        assert_eq!(drift.fitted_span, Some([0.0, 49.0 * 88.0]));
        let end = session.last().unwrap();
        let week_later = row(8.0 * 86_400.0, 9.0);
        assert_eq!(drift.features(&week_later, 0).unwrap(), vec![0.0; 6]);
        assert_ne!(drift.features(end, 0).unwrap(), vec![0.0; 6]);
        assert_eq!(thermal.features(&week_later, 0).unwrap(), thermal.features(&session[0], 0).unwrap());
        // Inside the span nothing changes.
        let inside = row(1000.0, 21.0);
        let raw = (1000.0 - drift.reference_s) / drift.scale[0];
        assert_eq!(drift.features(&inside, 0).unwrap()[0], raw);
        // With a margin of one span, half a span past the end is still the line; two spans past
        // it, nothing.
        let margin = TimeDriftTerm::new(&session, 1.0).unwrap();
        let width = 49.0 * 88.0;
        let at = |t: f64| margin.features(&row(t, 20.0), 0).unwrap()[0];
        assert_eq!(at(1.5 * width), (1.5 * width - margin.reference_s) / margin.scale[0]);
        assert_eq!(at(3.0 * width), 0.0);
        // A model file written before the span was recorded applies the line as it did.
        let old = TimeDriftTerm { fitted_span: None, ..drift.clone() };
        assert!(old.features(&week_later, 0).unwrap()[0] > 100.0);
    }

    /// The other rule of each, as the session choice may set it, and the model file: the default
    /// rule is not written, so that a file without the field (older, or of one session) means it.
    #[test]
    fn a_drift_may_be_held_and_a_growth_zeroed_beyond_the_span_and_the_default_rule_is_not_written() {
        let session: Vec<Measurement> = (0..50).map(|i| row(f64::from(i) * 88.0, 20.0 + f64::from(i) * 0.05)).collect();
        let mut drift = TimeDriftTerm::new(&session, 0.0).unwrap();
        let mut thermal = ThermalTerm::new(&session, 0.0).unwrap();
        let week_later = row(8.0 * 86_400.0, 9.0);
        let (end, first) = (session.last().unwrap(), &session[0]);
        let drift_text = ron::to_string(&drift).unwrap();
        let thermal_text = ron::to_string(&thermal).unwrap();
        assert!(!drift_text.contains("beyond_span") && !thermal_text.contains("beyond_span"), "{drift_text}");
        drift.beyond_span = BeyondSpan::Hold;
        thermal.beyond_span = BeyondSpan::Zero;
        assert_eq!(drift.features(&week_later, 0).unwrap(), drift.features(end, 0).unwrap());
        assert_eq!(thermal.features(&week_later, 0).unwrap(), vec![0.0]);
        assert_ne!(thermal.features(first, 0).unwrap(), vec![0.0], "inside the span the growth is applied");
        let text = ron::to_string(&drift).unwrap();
        assert!(text.contains("beyond_span:hold"), "{text}");
        assert_eq!(ron::from_str::<TimeDriftTerm>(&text).unwrap(), drift);
        assert_eq!(ron::from_str::<TimeDriftTerm>(&drift_text).unwrap().beyond_span, BeyondSpan::Zero);
        assert_eq!(ron::from_str::<ThermalTerm>(&thermal_text).unwrap().beyond_span, BeyondSpan::Hold);
    }
}
