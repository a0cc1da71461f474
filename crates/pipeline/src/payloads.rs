//! The payload groups of the training rows, and what a term driven by the payload's load
//! (`joint_compliance`, `link_deflection`) is beyond the payloads it was fitted on: held
//! at the lightest or heaviest ([`BeyondSpan::Hold`], the kinds' own rule), zero, or extended as
//! fitted ([`BeyondSpan::Extend`], linear in the load). Chosen by leaving out the lightest and the
//! heaviest payload group in turn, each then beyond the span of the rest, exactly as a heavier
//! payload than any trained is beyond the model's: where the arm bends linearly under its load
//! the extension predicts them, where it does not (a joint that stiffens, a brake that slips, a
//! term that has absorbed something else) the hold or zero does. Extension is never a default:
//! only the left-out payloads can earn it.

use crate::fit_options::FitOptions;
use crate::rule_choice::{Decision, FoldFailure, Target, held_out_errors, one_standard_error};
use effects::{BeyondSpan, EffectSpec, IdentifiedEffect};
use errors::Error;
use measurements::{Measurement, MeasurementSet};
use model::CalibratedModel;
use serde::Serialize;

/// The rows of each distinct `payload_kg` (row indices), lightest first.
pub fn payload_groups(rows: &[Measurement]) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    order.sort_by(|&a, &b| rows[a].payload_kg.total_cmp(&rows[b].payload_kg));
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in order {
        match groups.last_mut() {
            Some(group) if rows[group[0]].payload_kg == rows[i].payload_kg => group.push(i),
            _ => groups.push(vec![i]),
        }
    }
    groups
}

/// The rule of one effect beyond its payloads, and why (`calib fit --json`'s `beyond_payload`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PayloadChoice {
    /// The effect's label.
    pub effect: String,
    /// The rule the model keeps.
    pub rule: BeyondSpan,
    /// The payloads it was fitted on, `[lightest, heaviest]`, kg.
    pub span_kg: [f64; 2],
    /// The distinct payloads of the training rows.
    pub payloads: usize,
    /// Mean position error of the left-out payloads' rows under each rule, mm (absent where
    /// nothing was left out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heldout_mm: Option<PayloadErrors>,
    /// Why.
    pub reason: String,
}

/// The left-out payloads' mean position error under each rule.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PayloadErrors {
    /// Held at the span's end, mm.
    pub hold: f64,
    /// Zero beyond the span, mm.
    pub zero: f64,
    /// Extended as fitted, mm.
    pub extend: f64,
}

impl std::fmt::Display for PayloadChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [low, high] = self.span_kg;
        write!(
            f,
            "beyond the payloads it was fitted on ({low} to {high} kg), {} is {}: {}",
            self.effect,
            self.rule.describe(),
            self.reason
        )
    }
}

/// The rules tried, the kinds' own first.
const RULES: [BeyondSpan; 3] = [BeyondSpan::Hold, BeyondSpan::Zero, BeyondSpan::Extend];

/// Chooses the rule beyond the payload span for every effect of `effects` that has one (fitted
/// with the items `specs` on `data`) and sets it: with `effects.payloads.min_groups` payloads or
/// more, the lightest and then the heaviest group left out, the rest fitted (`poe` with the same
/// items, as the session choice's folds) and the left-out rows predicted under each rule, the
/// other effects kept as fitted. The hold stays unless the better of zero and extend is lower by
/// more than one standard error of the rows' paired differences
/// (`rule_choice::one_standard_error`).
///
/// `fit` fits a fold (`crate::fit` with `poe`, passed in so that this module does not import the
/// fit that calls it).
pub(crate) fn choose(
    data: &MeasurementSet,
    specs: &[EffectSpec],
    effects: &mut [IdentifiedEffect],
    options: &FitOptions,
    fit: impl Fn(&MeasurementSet, &FitOptions) -> Result<CalibratedModel, Error>,
) -> Result<Vec<PayloadChoice>, Error> {
    let targets: Vec<usize> = (0..effects.len()).filter(|&k| effects[k].payload_span().is_some()).collect();
    if targets.is_empty() {
        return Ok(Vec::new());
    }
    let settings = options.effects.payloads;
    let groups = payload_groups(&data.rows);
    let keep = |effects: &[IdentifiedEffect], reason: String| own_rules(effects, &targets, groups.len(), reason);
    if !settings.choose {
        return Ok(keep(effects, "its own rule (effects.payloads.choose is false)".into()));
    }
    if groups.len() < settings.min_groups {
        let reason = format!(
            "{} distinct payload(s), fewer than {} (effects.payloads.min_groups): nothing to leave out, its own rule",
            groups.len(),
            settings.min_groups
        );
        return Ok(keep(effects, reason));
    }
    let folds = [groups[0].clone(), groups[groups.len() - 1].clone()];
    if let Some(reason) = tool_of_its_own(data, &folds) {
        return Ok(keep(effects, reason));
    }
    let fold_options = crate::rule_choice::fold_options(options, specs);
    let trials: Vec<Target> = targets.iter().map(|&k| Target { effect: k, rules: RULES.to_vec() }).collect();
    let errors = match held_out_errors(data, &folds, &fold_options, &trials, IdentifiedEffect::set_beyond_payload, fit)
    {
        Ok(errors) => errors,
        Err(FoldFailure::Fit(e)) => {
            return Ok(keep(effects, format!("the fit without a payload failed ({e}): its own rule")));
        }
        Err(FoldFailure::Predict(e)) => {
            return Ok(keep(effects, format!("a left-out payload was not predicted ({e}): its own rule")));
        }
    };
    let (lightest, heaviest) = (data.rows[folds[0][0]].payload_kg, data.rows[folds[1][0]].payload_kg);
    let mut out = Vec::with_capacity(targets.len());
    for (trial, errors) in trials.iter().zip(&errors) {
        let k = trial.effect;
        let decision = one_standard_error(&trial.rules, errors);
        let heldout = PayloadErrors { hold: decision.means[0], zero: decision.means[1], extend: decision.means[2] };
        let reason = chosen_reason(&decision, &heldout, groups.len(), (lightest, heaviest));
        effects[k].set_beyond_payload(decision.chosen);
        out.push(PayloadChoice {
            effect: effects[k].label(),
            rule: decision.chosen,
            span_kg: effects[k].payload_span().map_or([0.0; 2], |s| s.kg),
            payloads: groups.len(),
            heldout_mm: Some(heldout),
            reason,
        });
    }
    Ok(out)
}

/// Each target effect with the rule it has, and why it was not chosen.
fn own_rules(effects: &[IdentifiedEffect], targets: &[usize], payloads: usize, reason: String) -> Vec<PayloadChoice> {
    targets
        .iter()
        .map(|&k| PayloadChoice {
            effect: effects[k].label(),
            rule: effects[k].beyond_payload().unwrap_or(BeyondSpan::Hold),
            span_kg: effects[k].payload_span().map_or([0.0; 2], |s| s.kg),
            payloads,
            heldout_mm: None,
            reason: reason.clone(),
        })
        .collect()
}

/// Why the rules cannot be chosen when a left-out group was measured with a tool of its own (a
/// probe remounted per payload run): then nothing that knows its tool is left to predict it.
fn tool_of_its_own(data: &MeasurementSet, folds: &[Vec<usize>; 2]) -> Option<String> {
    for fold in folds {
        let inside: std::collections::BTreeSet<usize> = fold.iter().copied().collect();
        let others: std::collections::BTreeSet<usize> =
            (0..data.rows.len()).filter(|i| !inside.contains(i)).map(|i| data.rows[i].tool).collect();
        if let Some(&i) = fold.iter().find(|&&i| !others.contains(&data.rows[i].tool)) {
            let row = &data.rows[i];
            return Some(format!(
                "the rows of payload {} kg carry a tool no other payload's rows carry (line {}): left out, nothing \
                 predicts them; its own rule",
                row.payload_kg, row.line
            ));
        }
    }
    None
}

/// Why `decision` chose its rule: the left-out payloads' errors under each rule and the
/// standard error that decided.
fn chosen_reason(
    decision: &Decision,
    heldout: &PayloadErrors,
    payloads: usize,
    (lightest, heaviest): (f64, f64),
) -> String {
    let standard_error = decision.standard_error;
    format!(
        "{} payloads, the lightest ({lightest} kg) and the heaviest ({heaviest} kg) left out in turn: {:.4} mm \
         held, {:.4} mm zero, {:.4} mm extended ({} rows; {})",
        payloads,
        heldout.hold,
        heldout.zero,
        heldout.extend,
        decision.rows,
        if decision.switched {
            format!(
                "{} lower than held by more than one standard error, {standard_error:.4} mm",
                decision.chosen.name()
            )
        } else {
            format!("held, no other rule lower by more than one standard error, {standard_error:.4} mm")
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PayloadOptions;

    #[test]
    fn rows_group_by_their_payload_lightest_first() {
        let rows: Vec<Measurement> = [5.0, 1.0, 5.0, 2.5, 1.0]
            .iter()
            .map(|&payload_kg| Measurement { payload_kg, ..Measurement::at(vec![0.0], lie::Vector3::zeros()) })
            .collect();
        assert_eq!(payload_groups(&rows), vec![vec![1, 4], vec![3], vec![0, 2]]);
        assert!(payload_groups(&[]).is_empty());
    }

    #[test]
    fn the_fewest_payload_groups_are_validated() {
        assert!(PayloadOptions::default().validate().is_ok());
        for n in [0, 1] {
            assert_eq!(
                PayloadOptions { min_groups: n, ..PayloadOptions::default() }.validate().unwrap_err().field,
                "min_groups"
            );
        }
    }
}
