//! What a term driven by time or temperature (`time_drift`, `thermal`) is beyond the span of
//! `t_s` / `temp_c` it was fitted on: held at its value at the span's nearer end, or
//! fallen back to zero (the geometry's own placement and size). A term driven by the payload's
//! load has a third rule, extended as fitted (`payload_span.rs`). Any of them may instead be
//! dropped: beyond the span the whole model falls back to the geometry fitted alone and its GP
//! (the model's `fallback_kinematics`, what the same fit without effects gives), the rule that
//! cannot make a later day worse than the plain fit. Each kind keeps the rule it had before the
//! choice was made by data (drift: zero; growth: held), which is what a model file without the
//! field means; the fit chooses among them by leaving one measuring session out at a time where
//! its training rows hold several, and drops a drift that no second session can judge
//! (`pipeline`'s session choice).

use serde::{Deserialize, Serialize};

/// Beyond the fitted span: held at the end's value, zero, extended, or dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BeyondSpan {
    /// The value at the nearer end of the span (its input clamped into it).
    Hold,
    /// Nothing: the geometry alone.
    Zero,
    /// As fitted, a straight line in the input past the span: a payload term's rule where leaving
    /// out the lightest and the heaviest payload showed it predicts them best (linear elasticity),
    /// never a default. The sessions never choose it for a drift or a growth.
    Extend,
    /// Dropped: the term held at the span's end (so that nothing jumps where the blend is
    /// partial), and the model's coverage of the row zero, so that the row is predicted by the
    /// geometry fitted alone and its GP, as the same fit without effects would predict it. Where
    /// the model keeps no such geometry (files written before it was kept) this is a hold.
    Drop,
}

impl BeyondSpan {
    /// The other of hold and zero (the sessions' two rules; extend's and drop's is hold).
    pub fn other(self) -> Self {
        match self {
            BeyondSpan::Hold => BeyondSpan::Zero,
            BeyondSpan::Zero | BeyondSpan::Extend | BeyondSpan::Drop => BeyondSpan::Hold,
        }
    }

    /// The SPEC-style name (`hold`, `zero`, `extend`, `drop`).
    pub fn name(self) -> &'static str {
        match self {
            BeyondSpan::Hold => "hold",
            BeyondSpan::Zero => "zero",
            BeyondSpan::Extend => "extend",
            BeyondSpan::Drop => "drop",
        }
    }

    /// In words, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            BeyondSpan::Hold => "held at the span's end",
            BeyondSpan::Zero => "zero (the geometry alone)",
            BeyondSpan::Extend => "extended as fitted (linear in its input)",
            BeyondSpan::Drop => "dropped (the model falls back to the geometry fitted alone and its GP)",
        }
    }

    /// How fully the model applies at `value` for a term fitted on `span` under this rule
    /// (`EffectTerm::coverage_weight`): 0 beyond the span where the term is dropped, 1 otherwise.
    pub(crate) fn coverage(self, value: Option<f64>, span: Option<[f64; 2]>) -> f64 {
        match (self, value, span) {
            (BeyondSpan::Drop, Some(value), Some([low, high])) if !(low..=high).contains(&value) => 0.0,
            _ => 1.0,
        }
    }

    /// The features of `value` (`t_s` or `temp_c`) under this rule for a term fitted on `span`
    /// (`None`: older files, applied as fitted everywhere): `at(value)` inside the span, `at` of
    /// the nearer end beyond it (hold, drop), zeros of `width` (zero), or `at(value)` (extend).
    pub(crate) fn features(
        self,
        value: f64,
        span: Option<[f64; 2]>,
        width: usize,
        at: impl Fn(f64) -> Vec<f64>,
    ) -> Vec<f64> {
        match span {
            Some([low, high]) if !(low..=high).contains(&value) => match self {
                BeyondSpan::Hold | BeyondSpan::Drop => at(value.clamp(low, high)),
                BeyondSpan::Zero => vec![0.0; width],
                BeyondSpan::Extend => at(value),
            },
            _ => at(value),
        }
    }
}

#[allow(clippy::trivially_copy_pass_by_ref)] // serde's `skip_serializing_if` passes a reference
pub(crate) fn is_zero(rule: &BeyondSpan) -> bool {
    *rule == BeyondSpan::Zero
}

#[allow(clippy::trivially_copy_pass_by_ref)] // serde's `skip_serializing_if` passes a reference
pub(crate) fn is_hold(rule: &BeyondSpan) -> bool {
    *rule == BeyondSpan::Hold
}

pub(crate) fn zero() -> BeyondSpan {
    BeyondSpan::Zero
}

pub(crate) fn hold() -> BeyondSpan {
    BeyondSpan::Hold
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dropped_term_is_held_and_uncovered_beyond_its_span_only() {
        let span = Some([10.0, 20.0]);
        let at = |v: f64| vec![v];
        for (value, features, coverage) in [(15.0, 15.0, 1.0), (25.0, 20.0, 0.0), (5.0, 10.0, 0.0)] {
            assert_eq!(BeyondSpan::Drop.features(value, span, 1, at), vec![features]);
            assert_eq!(BeyondSpan::Drop.coverage(Some(value), span), coverage);
        }
        // Every other rule covers every row, and a term without a span or a row without the
        // input is covered.
        for rule in [BeyondSpan::Hold, BeyondSpan::Zero, BeyondSpan::Extend] {
            assert_eq!(rule.coverage(Some(25.0), span), 1.0);
        }
        assert_eq!(BeyondSpan::Drop.coverage(Some(25.0), None), 1.0);
        assert_eq!(BeyondSpan::Drop.coverage(None, span), 1.0);
        assert_eq!(BeyondSpan::Drop.name(), "drop");
    }
}
