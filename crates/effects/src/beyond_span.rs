//! What a term driven by time or temperature (`time_drift`, `thermal`) is beyond the span of
//! `t_s` / `temp_c` it was fitted on: held at its value at the span's nearer end, or
//! fallen back to zero (the geometry's own placement and size). A term driven by the payload's
//! load has a third rule, extended as fitted (`payload_span.rs`). Each kind keeps the rule it had
//! before the choice was made by data (drift: zero; growth: held), which is what a model file
//! without the field means; the fit chooses between them by leaving one measuring session out at
//! a time where its training rows hold several (`pipeline`'s session choice).

use serde::{Deserialize, Serialize};

/// Beyond the fitted span: held at the end's value, or zero.
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
}

impl BeyondSpan {
    /// The other of hold and zero (the sessions' two rules; extend's is hold).
    pub fn other(self) -> Self {
        match self {
            BeyondSpan::Hold => BeyondSpan::Zero,
            BeyondSpan::Zero | BeyondSpan::Extend => BeyondSpan::Hold,
        }
    }

    /// The SPEC-style name (`hold`, `zero`, `extend`).
    pub fn name(self) -> &'static str {
        match self {
            BeyondSpan::Hold => "hold",
            BeyondSpan::Zero => "zero",
            BeyondSpan::Extend => "extend",
        }
    }

    /// In words, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            BeyondSpan::Hold => "held at the span's end",
            BeyondSpan::Zero => "zero (the geometry alone)",
            BeyondSpan::Extend => "extended as fitted (linear in its input)",
        }
    }

    /// The features of `value` (`t_s` or `temp_c`) under this rule for a term fitted on `span`
    /// (`None`: older files, applied as fitted everywhere): `at(value)` inside the span, `at` of
    /// the nearer end beyond it (hold), zeros of `width` (zero), or `at(value)` (extend).
    pub(crate) fn features(
        self,
        value: f64,
        span: Option<[f64; 2]>,
        width: usize,
        at: impl Fn(f64) -> Vec<f64>,
    ) -> Vec<f64> {
        match span {
            Some([low, high]) if !(low..=high).contains(&value) => match self {
                BeyondSpan::Hold => at(value.clamp(low, high)),
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
