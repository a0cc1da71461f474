//! What every effect implements: [`EffectTerm`] (what a fitted effect says about itself: its
//! label, its joints, its checks on reading a model file, where it applies) and [`NewEffect`] (how
//! it is made: the arguments of its `--effects` item, from an item for the fit, as candidates for
//! the diagnosis). [`crate::IdentifiedEffect`] is generated from the one list of kinds
//! (`loadsim::effect_kinds!`) and delegates every arm to these traits, so an effect is one file.

use crate::check::{Cursor, EffectFault};
use crate::{Argument, Direction, EffectContext, EffectSpec, IdentifiedEffect, LoadFrame, Regressor};
use errors::Error;
use measurements::{BoundSet, Measurement};
use robot::RobotDescription;
use serde::{Deserialize, Serialize};

/// What the diagnosis builds its candidates from.
#[derive(Debug, Clone, Copy)]
pub struct CandidateContext<'a> {
    /// The robot description.
    pub robot: &'a RobotDescription,
    /// The measurements, bound to the model the diagnosis fits (each row's model tool).
    pub data: &'a BoundSet<'a>,
    /// The nominal arm in the base frame, where gravity is known, with the calibrated tools.
    pub load: &'a LoadFrame,
    /// The robot's mass model, or [`crate::stand_in_dynamics`].
    pub dynamics: &'a loadsim::RobotDynamics,
    /// Whether every row has measured joint torques.
    pub measured: bool,
    /// 0-based joints that move.
    pub moving: &'a [usize],
    /// The highest order a Fourier series may take.
    pub longest_order: u32,
    /// When an input is too constant for an effect driven by it.
    pub options: CandidateOptions,
}

/// When the diagnosis offers the effects driven by the row's temperature and time: an input that
/// barely varies cannot identify a coefficient on it. Validated once, by the diagnosis's options
/// (`DiagnoseOptions::validate`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CandidateOptions {
    /// Thermal growth is a candidate only where every row has `temp_c` and it spans more than this,
    /// K. 0.2 K, not fitted to any data set: over 0.2 K steel (11.5e-6 /K) grows a 2 m arm by
    /// 4.6 µm, under the tracker's 5 µm line-of-sight noise (`loadsim::TrackerNoiseModel`), so a smaller
    /// span identifies noise.
    pub thermal_min_span_k: f64,
    /// Drift is a candidate only where every row has `t_s` and some row lies more than this from
    /// their mean, s. 1 s, not fitted to any data set: a robot takes seconds to reach and settle at
    /// a pose, so rows all within a second of their mean are one moment (a constant or rounded
    /// stamp), not a session that drifts.
    pub drift_min_offset_s: f64,
}

impl Default for CandidateOptions {
    fn default() -> Self {
        Self { thermal_min_span_k: 0.2, drift_min_offset_s: 1.0 }
    }
}

/// A candidate an effect offers the diagnosis: the effect with its parameters at zero.
#[derive(Debug, Clone)]
pub struct CandidateModel {
    /// The effect as the fit would model it.
    pub effect: IdentifiedEffect,
    /// Its place among one joint's candidates (the selection gives ties to the earlier one).
    pub order: u8,
    /// A Fourier series: the diagnosis gives it the series prior and lets it take any of its orders.
    pub series: bool,
    /// Offered only where its columns are not zero on every row (a torque sign that never changes).
    pub only_if_nonzero: bool,
}

impl CandidateModel {
    /// A candidate with the default prior, offered whenever it has columns.
    pub fn plain(effect: IdentifiedEffect, order: u8) -> Self {
        Self { effect, order, series: false, only_if_nonzero: false }
    }
}

/// What a fitted effect says about itself. Implemented by the type of every identified kind.
pub(crate) trait EffectTerm: Regressor + std::fmt::Debug + Send + Sync {
    /// A name for reports: the SPEC item where there is one (`gear_periodic:1:24`), with what
    /// drives it.
    fn label(&self) -> String;

    /// The 1-based joints the effect acts on (empty for effects of no joint).
    fn joints(&self) -> Vec<usize>;

    /// Checks the effect as read from a model file with `n` joints and `tools` tools: every index
    /// within the robot, every count consistent, every value finite (`theta`'s values are checked
    /// for every effect by `check_effects`).
    fn check(&self, cursor: &Cursor<'_>, n: usize, tools: usize) -> Result<(), EffectFault>;

    /// Counts the fields the effect writes into a model file (`add(field, occurrences)`), `theta`
    /// excepted, so that a fault of the next effect is placed at its own occurrence.
    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize));

    /// How fully the effect applies at `row`: 1 where it was fitted, fading to 0 where it is not
    /// trusted.
    fn coverage_weight(&self, _row: &Measurement) -> f64 {
        1.0
    }

    /// What the effect leaves uncorrected at `row`: a standard deviation along a direction, if any.
    fn uncovered(&self, _row: &Measurement) -> Option<(Direction, f64)> {
        None
    }

    /// Whether the effect can report [`EffectTerm::uncovered`].
    fn has_sigma(&self) -> bool {
        false
    }

    /// Each parameter's prior standard deviation relative to the effects' common one.
    fn prior_scale(&self) -> Vec<f64> {
        vec![1.0; self.theta().len()]
    }

    /// What the effect is beyond the span of its input (`t_s`, `temp_c`); `None` for an effect
    /// of no such input.
    fn beyond_span(&self) -> Option<crate::BeyondSpan> {
        None
    }

    /// Sets [`EffectTerm::beyond_span`]; nothing for an effect of no such input.
    fn set_beyond_span(&mut self, _rule: crate::BeyondSpan) {}

    /// The payloads the effect was fitted on and its rule beyond them; `None` for an effect not
    /// driven by the payload's load, or read from a file written before the span was recorded.
    fn payload_span(&self) -> Option<&crate::PayloadSpan> {
        None
    }

    /// Sets the rule of [`EffectTerm::payload_span`]; nothing where there is none.
    fn set_beyond_payload(&mut self, _rule: crate::BeyondSpan) {}

    /// Records what the effect keeps of its training rows once its parameters are fitted (a
    /// series' RMS, for [`EffectTerm::uncovered`]); nothing by default.
    fn after_fit(&mut self, _rows: &[Measurement]) {}
}

/// How an effect is made. Implemented by the type of every identified kind.
pub(crate) trait NewEffect: EffectTerm + Sized {
    /// The arguments of its `--effects` item, in order.
    const ARGUMENTS: &'static [Argument];

    /// The effect an `--effects` item names, its features scaled on the rows of `data`, its
    /// parameters at zero. Its joint, if any, is within the robot.
    fn build(spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error>;

    /// The diagnosis's candidates of this kind on 0-based joint `joint`.
    fn joint_candidates(_context: &CandidateContext<'_>, _joint: usize) -> Result<Vec<CandidateModel>, Error> {
        Ok(Vec::new())
    }

    /// The diagnosis's candidates of this kind that concern no one joint.
    fn global_candidates(_context: &CandidateContext<'_>) -> Result<Vec<CandidateModel>, Error> {
        Ok(Vec::new())
    }
}
