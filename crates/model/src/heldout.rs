//! The fit's own estimate of the model's held-out error, kept in the model file so
//! that `calib register` can judge a registration's residual without being told it. Files
//! written before it was kept have none (`register` then asks for `--heldout-mm`).

use serde::{Deserialize, Serialize};

/// How the fit estimated the error on poses it was not fitted on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeldoutSource {
    /// The exact GP's closed-form leave-one-out prediction on every training row (the
    /// hyperparameters and the geometry as fitted on all rows).
    GpLeaveOneOut,
    /// The same with each repeated configuration left out whole ([`crate::RepeatGroups`]), where
    /// rows repeat one: a row left out alone keeps its twin.
    GpLeaveGroupOut,
    /// The training error corrected for the identifiable parameters `p` (the effects' among them)
    /// among the residual rows
    /// `r`: `× √((r + p) / (r − p))`, the ratio of the expected held-out and training mean squares
    /// of linear least squares (`σ²(1 + p/r)` against `σ²(1 − p/r)`). A configuration measured
    /// more than once counts once in `r`: the error a model leaves is a function of the
    /// configuration, so a repeat adds no independent residual.
    DegreesOfFreedom,
}

impl std::fmt::Display for HeldoutSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::GpLeaveOneOut => "the GP's leave-one-out error",
            Self::GpLeaveGroupOut => "the GP's leave-one-out error, repeated configurations left out whole",
            Self::DegreesOfFreedom => "the training error corrected for the fitted parameters",
        })
    }
}

/// The fit's estimate of the model's mean position error on poses like the training poses but
/// not among them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeldoutEstimate {
    /// Mean position error, mm.
    pub mean_position_error_mm: f64,
    /// How it was estimated.
    pub source: HeldoutSource,
}

impl HeldoutEstimate {
    /// `mean_mm` when it is a usable error (finite, positive): `None` says unknown.
    pub fn new(mean_mm: f64, source: HeldoutSource) -> Option<Self> {
        (mean_mm.is_finite() && mean_mm > 0.0).then_some(Self { mean_position_error_mm: mean_mm, source })
    }

    /// The degrees-of-freedom corrected training error ([`HeldoutSource::DegreesOfFreedom`]);
    /// `None` where the parameters leave no residual rows. `distinct` of the `rows` measurements
    /// behind the `residual_rows` are distinct configurations: the residual rows count in that
    /// proportion.
    pub fn degrees_of_freedom(
        training_mean_mm: f64,
        residual_rows: usize,
        parameters: usize,
        (distinct, rows): (usize, usize),
    ) -> Option<Self> {
        let share = if rows == 0 { 1.0 } else { distinct.min(rows) as f64 / rows as f64 };
        let (r, p) = (residual_rows as f64 * share, parameters as f64);
        if r <= p {
            return None;
        }
        Self::new(training_mean_mm * ((r + p) / (r - p)).sqrt(), HeldoutSource::DegreesOfFreedom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_correction_grows_with_the_parameters_and_refuses_none_left() {
        let few = HeldoutEstimate::degrees_of_freedom(1.0, 100, 10, (50, 50)).unwrap();
        let many = HeldoutEstimate::degrees_of_freedom(1.0, 100, 50, (50, 50)).unwrap();
        assert!((few.mean_position_error_mm - (110.0f64 / 90.0).sqrt()).abs() < 1e-12);
        assert!(many.mean_position_error_mm > few.mean_position_error_mm);
        assert!(HeldoutEstimate::degrees_of_freedom(1.0, 30, 30, (15, 15)).is_none());
        // Half the rows repeats of the other half: 50 independent residual rows, not 100.
        let twins = HeldoutEstimate::degrees_of_freedom(1.0, 100, 10, (25, 50)).unwrap();
        assert!((twins.mean_position_error_mm - (60.0f64 / 40.0).sqrt()).abs() < 1e-12);
        assert!(HeldoutEstimate::degrees_of_freedom(1.0, 100, 50, (25, 50)).is_none());
        assert!(HeldoutEstimate::new(f64::NAN, HeldoutSource::GpLeaveOneOut).is_none());
        assert!(HeldoutEstimate::new(0.0, HeldoutSource::GpLeaveOneOut).is_none());
    }
}
