//! What a term driven by the payload's gravity load (`joint_compliance`, `link_deflection`) is
//! beyond the payloads it was fitted on: held at the lightest or heaviest trained
//! payload ([`BeyondSpan::Hold`], the default), fallen back to zero (the geometry alone), or
//! extended as fitted ([`BeyondSpan::Extend`], a straight line in the load; what a model file
//! written before the span was recorded does everywhere). The fit keeps the hold unless leaving
//! out the lightest and the heaviest payload in turn says another rule predicts them better
//! (`pipeline`'s payload choice).
//!
//! A term driven by measured joint torques (`tauN_nm`, [`crate::ComplianceTorque::Measured`]) has
//! no payload in its features: the torque is its input. Beyond the payload span, holding it means
//! each joint's torque clamped into the span of that joint's torque on the training rows (the
//! nearest load the term has seen on that joint), zero means no deflection, and extend the torque
//! as measured. Inside the payload span the measured torque is used as it is, so that a model's
//! predictions on the payloads it was fitted on do not change.

use crate::BeyondSpan;
use measurements::Measurement;
use serde::{Deserialize, Serialize};

/// The payloads (and, for measured torques, each joint's torque) a term was fitted on, and its
/// rule beyond them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PayloadSpan {
    /// `[lightest, heaviest]` payload of the training rows, kg.
    pub kg: [f64; 2],
    /// Each joint's measured torque `[min, max]` on the training rows, N·m (a prismatic joint's
    /// force, N); empty for a term whose features do not read the measured torques.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_nm: Vec<[f64; 2]>,
    /// Beyond `kg`: held (the default, not written), zero or extended; chosen by the fit.
    #[serde(default = "crate::beyond_span::hold", skip_serializing_if = "crate::beyond_span::is_hold")]
    pub beyond: BeyondSpan,
}

impl PayloadSpan {
    /// The span of the payloads of `rows` (and of their measured torques where `torques`), held
    /// beyond it; `None` for no rows.
    pub fn of(rows: &[Measurement], torques: bool) -> Option<Self> {
        let payloads: Vec<f64> = rows.iter().map(|r| r.payload_kg).collect();
        let kg = crate::span_of(&payloads, 0.0)?;
        let torque_nm = if torques {
            let joints = rows.iter().filter_map(|r| r.torques_nm.as_ref().map(Vec::len)).min().unwrap_or(0);
            (0..joints)
                .filter_map(|j| {
                    let values: Vec<f64> = rows.iter().filter_map(|r| r.torques_nm.as_ref().map(|t| t[j])).collect();
                    crate::span_of(&values, 0.0)
                })
                .collect()
        } else {
            Vec::new()
        };
        Some(Self { kg, torque_nm, beyond: BeyondSpan::Hold })
    }

    /// The rule at a row of payload `payload_kg`: `None` inside the span (the term as fitted),
    /// the rule beyond it.
    pub fn rule_at(&self, payload_kg: f64) -> Option<BeyondSpan> {
        let [low, high] = self.kg;
        (!(low..=high).contains(&payload_kg)).then_some(self.beyond)
    }

    /// How fully the model applies at a row of payload `payload_kg`
    /// (`EffectTerm::coverage_weight`): 0 beyond the span where the term is dropped.
    pub fn coverage(&self, payload_kg: f64) -> f64 {
        self.beyond.coverage(Some(payload_kg), Some(self.kg))
    }

    /// The payload the features are computed with under `rule` ([`PayloadSpan::rule_at`]): the
    /// nearer end of the span for a hold, the row's own otherwise.
    pub fn payload(&self, rule: Option<BeyondSpan>, payload_kg: f64) -> f64 {
        match rule {
            Some(BeyondSpan::Hold | BeyondSpan::Drop) => payload_kg.clamp(self.kg[0], self.kg[1]),
            _ => payload_kg,
        }
    }

    /// Joint `joint`'s measured torque under `rule`: clamped into its training span for a hold
    /// (as measured where no span was recorded for it).
    pub fn torque(&self, rule: Option<BeyondSpan>, joint: usize, torque_nm: f64) -> f64 {
        match (rule, self.torque_nm.get(joint)) {
            (Some(BeyondSpan::Hold | BeyondSpan::Drop), Some(&[low, high])) => torque_nm.clamp(low, high),
            _ => torque_nm,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(payload_kg: f64, torques: [f64; 2]) -> Measurement {
        Measurement {
            payload_kg,
            torques_nm: Some(torques.to_vec()),
            ..Measurement::at(vec![0.0, 0.0], lie::Vector3::zeros())
        }
    }

    #[test]
    fn a_payload_beyond_the_span_is_clamped_for_a_hold_and_kept_otherwise() {
        let rows = [row(1.0, [10.0, -4.0]), row(5.0, [30.0, 2.0]), row(2.5, [-5.0, 0.0])];
        let mut span = PayloadSpan::of(&rows, true).unwrap();
        assert_eq!(span.kg, [1.0, 5.0]);
        assert_eq!(span.torque_nm, vec![[-5.0, 30.0], [-4.0, 2.0]]);
        assert_eq!(span.rule_at(3.0), None);
        assert_eq!(span.rule_at(5.0), None);
        let beyond = span.rule_at(7.5);
        assert_eq!(beyond, Some(BeyondSpan::Hold));
        assert_eq!(span.rule_at(0.0), Some(BeyondSpan::Hold));
        assert_eq!((span.payload(beyond, 7.5), span.payload(beyond, 0.0)), (5.0, 1.0));
        assert_eq!((span.torque(beyond, 0, 45.0), span.torque(beyond, 1, -9.0)), (30.0, -4.0));
        // Inside the span, and beyond it under the other rules, the row's own values.
        assert_eq!((span.payload(None, 3.0), span.torque(None, 0, 45.0)), (3.0, 45.0));
        for rule in [BeyondSpan::Zero, BeyondSpan::Extend] {
            span.beyond = rule;
            let at = span.rule_at(7.5);
            assert_eq!((at, span.payload(at, 7.5), span.torque(at, 0, 45.0)), (Some(rule), 7.5, 45.0));
        }
        assert!(PayloadSpan::of(&rows, false).unwrap().torque_nm.is_empty());
        assert_eq!(PayloadSpan::of(&[], false), None);
    }
}
