//! Measuring sessions in the training rows, and what a term driven by time or temperature
//! (`time_drift`, `thermal`) is beyond the span it was fitted on, chosen by leaving one session out
//! at a time: held at its value at the span's end ([`BeyondSpan::Hold`]), fallen back
//! to the geometry it was fitted with ([`BeyondSpan::Zero`]), or dropped, the whole model fallen
//! back to the geometry fitted alone and its GP ([`BeyondSpan::Drop`]). A robot re-measured days
//! later starts from a placement of its own: whether the end of the last session or the
//! geometry's average placement is nearer to it is a property of the cell (a foundation that
//! settles one way, or a tracker re-sighted anywhere), which only other sessions of the same cell
//! can tell. With one session nothing can: a drift is then dropped, the one rule that cannot make
//! another day worse than the fit without it (every later day is beyond a drift's span), and a
//! growth keeps its hold (a day at a temperature inside the span is inside it).

use crate::fit_options::FitOptions;
use crate::rule_choice::{Decision, FoldFailure, Target, held_out_errors, one_standard_error};
use effects::{BeyondSpan, EffectSpec, IdentifiedEffect};
use errors::Error;
use measurements::{Measurement, MeasurementSet};
use model::CalibratedModel;
use serde::Serialize;

/// The sessions of `rows` (row indices, each session in time order, sessions in time order):
/// rows split where the gap in `t_s` exceeds `gap_ratio` times the median positive gap. Empty
/// where a row has no `t_s`; one session where no gap is that long.
pub fn sessions(rows: &[Measurement], gap_ratio: f64) -> Vec<Vec<usize>> {
    let Some(times) = rows.iter().map(|r| r.t_s).collect::<Option<Vec<f64>>>() else { return Vec::new() };
    let mut order: Vec<usize> = (0..rows.len()).collect();
    order.sort_by(|&a, &b| times[a].total_cmp(&times[b]));
    let gaps: Vec<f64> = order.windows(2).map(|w| times[w[1]] - times[w[0]]).collect();
    let mut positive: Vec<f64> = gaps.iter().copied().filter(|&g| g > 0.0).collect();
    positive.sort_by(f64::total_cmp);
    let limit = positive.get(positive.len() / 2).map_or(f64::INFINITY, |median| gap_ratio * median);
    let mut out: Vec<Vec<usize>> = Vec::new();
    let mut current: Vec<usize> = Vec::new();
    for (k, &row) in order.iter().enumerate() {
        if k > 0 && gaps[k - 1] > limit {
            out.push(std::mem::take(&mut current));
        }
        current.push(row);
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// The rule of one effect beyond its span, and why (`calib fit --json`'s `beyond_span`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpanChoice {
    /// The effect's label (`time_drift`, `thermal`).
    pub effect: String,
    /// The rule the model keeps.
    pub rule: BeyondSpan,
    /// The sessions found in the training rows (0 where a row has no `t_s`).
    pub sessions: usize,
    /// Mean position error of the left-out sessions' rows, held and zero beyond the span, mm
    /// (absent where nothing was left out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heldout_mm: Option<SpanErrors>,
    /// Why.
    pub reason: String,
}

/// The left-out sessions' mean position error under each rule.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpanErrors {
    /// Held at the span's end, mm.
    pub hold: f64,
    /// Zero beyond the span, mm.
    pub zero: f64,
    /// Dropped beyond the span (the geometry fitted alone), mm.
    pub drop: f64,
}

impl std::fmt::Display for SpanChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "beyond its fitted span, {} is {}: {}", self.effect, self.rule.describe(), self.reason)
    }
}

/// Chooses the rule beyond the span for every effect of `effects` that has one (fitted with the
/// items `specs` on `data`) and sets it: with several sessions, each left out in turn, the rest
/// fitted (`poe` with the same items; no prior strength chosen, and no sessions or payloads chosen
/// inside a fold), and the left-out rows predicted under each of hold, zero and drop, the others'
/// kept as fitted. The kind's own rule stays unless the best other's mean error is lower by more
/// than one standard error of the rows' paired differences (`rule_choice::one_standard_error`).
/// With one session, or none known, a drift is dropped and a growth keeps its hold
/// ([`undecided_rule`]); with the choice switched off each keeps the rule it has.
///
/// `fit` fits a fold (`crate::fit` with `poe`, passed in so that this module does not import the
/// fit that calls it).
pub(crate) fn choose(
    data: &MeasurementSet,
    specs: &[EffectSpec],
    effects: &mut [IdentifiedEffect],
    options: &FitOptions,
    fit: impl Fn(&MeasurementSet, &FitOptions) -> Result<CalibratedModel, Error>,
) -> Result<Vec<SpanChoice>, Error> {
    let targets: Vec<usize> = (0..effects.len()).filter(|&k| effects[k].beyond_span().is_some()).collect();
    if targets.is_empty() {
        return Ok(Vec::new());
    }
    let settings = options.effects.sessions;
    let found = sessions(&data.rows, settings.gap_ratio);
    let keep = |effects: &[IdentifiedEffect], reason: String| own_rules(effects, &targets, found.len(), reason);
    if !settings.choose {
        return Ok(keep(effects, "its own rule (effects.sessions.choose is false)".into()));
    }
    if found.len() < 2 {
        let why = if found.is_empty() {
            "sessions unknown (a row has no t_s)".to_owned()
        } else {
            format!("one session (no gap in t_s longer than {} times the median spacing)", settings.gap_ratio)
        };
        return Ok(undecided(effects, &targets, found.len(), &why));
    }
    let fold_options = crate::rule_choice::fold_options(options, specs);
    // Per target, the left-out rows' errors under the kind's own rule and under the other.
    let trials: Vec<Target> = targets
        .iter()
        .map(|&k| {
            let rule = effects[k].beyond_span().unwrap_or(BeyondSpan::Zero);
            let others = RULES.into_iter().filter(|&r| r != rule);
            Target { effect: k, rules: std::iter::once(rule).chain(others).collect() }
        })
        .collect();
    let errors = match held_out_errors(data, &found, &fold_options, &trials, IdentifiedEffect::set_beyond_span, fit) {
        Ok(errors) => errors,
        Err(FoldFailure::Fit(e)) => {
            return Ok(keep(effects, format!("the fit without a session failed ({e}): its own rule")));
        }
        Err(FoldFailure::Predict(e)) => {
            return Ok(keep(effects, format!("a left-out session was not predicted ({e}): its own rule")));
        }
    };
    let mut out = Vec::with_capacity(targets.len());
    for (trial, errors) in trials.iter().zip(&errors) {
        let k = trial.effect;
        let rule = trial.rules[0];
        let decision = one_standard_error(&trial.rules, errors);
        let mean_of =
            |wanted: BeyondSpan| trial.rules.iter().position(|&r| r == wanted).map_or(f64::NAN, |i| decision.means[i]);
        let errors = SpanErrors {
            hold: mean_of(BeyondSpan::Hold),
            zero: mean_of(BeyondSpan::Zero),
            drop: mean_of(BeyondSpan::Drop),
        };
        let reason = chosen_reason(&decision, rule, &errors, found.len());
        effects[k].set_beyond_span(decision.chosen);
        out.push(SpanChoice {
            effect: effects[k].label(),
            rule: decision.chosen,
            sessions: found.len(),
            heldout_mm: Some(errors),
            reason,
        });
    }
    Ok(out)
}

/// The rules the sessions choose among for a drift or a growth (extend is a payload term's).
const RULES: [BeyondSpan; 3] = [BeyondSpan::Hold, BeyondSpan::Zero, BeyondSpan::Drop];

/// The rule of an effect that no left-out session can judge: a drift dropped (another day is
/// always beyond its span, and the drop makes it the fit without effects there, so never worse
/// than it), a growth its own (held: a day at a temperature inside its span is predicted as
/// fitted, one beyond it at the nearer end).
pub(crate) fn undecided_rule(effect: &IdentifiedEffect) -> BeyondSpan {
    match effect {
        IdentifiedEffect::TimeDrift(_) => BeyondSpan::Drop,
        _ => effect.beyond_span().unwrap_or(BeyondSpan::Zero),
    }
}

/// Each target effect set to its [`undecided_rule`], and why: `why` nothing could decide it.
fn undecided(effects: &mut [IdentifiedEffect], targets: &[usize], sessions: usize, why: &str) -> Vec<SpanChoice> {
    targets
        .iter()
        .map(|&k| {
            let rule = undecided_rule(&effects[k]);
            effects[k].set_beyond_span(rule);
            let reason = match rule {
                BeyondSpan::Drop => format!(
                    "{why}: nothing to leave out, so nothing could decide the rule; dropped, the one rule that \
                     cannot make a day beyond the span worse than the fit without effects"
                ),
                _ => format!("{why}: nothing to leave out, so nothing could decide the rule; its own rule"),
            };
            SpanChoice { effect: effects[k].label(), rule, sessions, heldout_mm: None, reason }
        })
        .collect()
}

/// Each target effect with the rule it has, and why it was not chosen.
fn own_rules(effects: &[IdentifiedEffect], targets: &[usize], sessions: usize, reason: String) -> Vec<SpanChoice> {
    targets
        .iter()
        .map(|&k| SpanChoice {
            effect: effects[k].label(),
            rule: effects[k].beyond_span().unwrap_or(BeyondSpan::Zero),
            sessions,
            heldout_mm: None,
            reason: reason.clone(),
        })
        .collect()
}

/// Why `decision` chose its rule over the kind's own `rule`: the left-out sessions' errors under
/// either rule and the standard error that decided.
fn chosen_reason(decision: &Decision, rule: BeyondSpan, errors: &SpanErrors, sessions: usize) -> String {
    let standard_error = decision.standard_error;
    format!(
        "{} sessions, each left out in turn: {:.4} mm held, {:.4} mm zero, {:.4} mm dropped beyond the span ({} rows; {})",
        sessions,
        errors.hold,
        errors.zero,
        errors.drop,
        decision.rows,
        if decision.switched {
            format!("{} lower by more than one standard error, {standard_error:.4} mm", decision.chosen.name())
        } else {
            format!("{} kept, the other not lower by more than one standard error, {standard_error:.4} mm", rule.name())
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SessionOptions;

    fn at(times: &[f64]) -> Vec<Measurement> {
        times
            .iter()
            .map(|&t| Measurement { t_s: Some(t), ..Measurement::at(vec![0.0], lie::Vector3::zeros()) })
            .collect()
    }

    #[test]
    fn rows_split_into_sessions_at_gaps_far_longer_than_their_spacing() {
        // Two sessions of 30 s spacing with a 5-minute pause inside the first, a day apart, given
        // out of time order.
        let mut times: Vec<f64> = (0..20).map(|i| f64::from(i) * 30.0).collect();
        times.extend((0..10).map(|i| 900.0 + f64::from(i) * 30.0));
        times.extend((0..15).map(|i| 86_400.0 + f64::from(i) * 30.0));
        times.reverse();
        let found = sessions(&at(&times), SessionOptions::default().gap_ratio);
        assert_eq!(found.iter().map(Vec::len).collect::<Vec<_>>(), vec![30, 15]);
        assert!(found[1].iter().all(|&i| times[i] >= 86_400.0));
        // One session, a row without a time, and a constant time stamp.
        assert_eq!(sessions(&at(&[0.0, 30.0, 60.0]), 20.0).len(), 1);
        let mut rows = at(&[0.0, 30.0]);
        rows[1].t_s = None;
        assert!(sessions(&rows, 20.0).is_empty());
        assert_eq!(sessions(&at(&[5.0, 5.0, 5.0]), 20.0).len(), 1);
    }

    #[test]
    fn the_gap_ratio_is_validated() {
        assert!(SessionOptions::default().validate().is_ok());
        for ratio in [1.0, 0.5, f64::NAN, f64::INFINITY] {
            assert_eq!(
                SessionOptions { gap_ratio: ratio, ..SessionOptions::default() }.validate().unwrap_err().field,
                "gap_ratio"
            );
        }
    }
}
